"""Follower spring and inertia: the contact force over the cycle, lift-off, the cam's driving torque.

At a constant cam speed ω the follower needs the generalised force (per metre of lift s)

    Q = m·ω²·a + F₀ + c·s + F            translating: m kg, spring c N/m, preload F₀ N, load F N
    Q = (J·ω²·a/l + M₀ + c·s/l + M)/l    oscillating: J kg·m² about the pivot, c N·m/rad, M₀, M N·m

and the cam supplies it through the contact normal n̂ at the follower's driven point X:
N = Q/(n̂·∂X/∂s) (frictionless contact). N ≤ 0 means the follower leaves the cam. The cam's driving
torque follows from power, T·ω = Q·ṡ, so T = Q·v (N·m, positive when the cam's shaft drives).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .geometry import CamGeometry

__all__ = ["CamForces", "cam_forces"]


@dataclass(frozen=True)
class CamForces:
    """Forces over the cycle (arrays (N,) at the geometry's angles).

    Attributes
    ----------
    generalised : Q, N per metre of lift
    contact : N, the normal contact force, N
    torque : T, the cam's driving torque, N·m
    lift_off : where N ≤ 0 (bool array)
    """

    generalised: np.ndarray
    contact: np.ndarray
    torque: np.ndarray
    lift_off: np.ndarray


def cam_forces(geometry: CamGeometry, spec) -> CamForces:
    """Contact force and driving torque over the cycle.

    Parameters
    ----------
    geometry : CamGeometry
    spec : DynamicsSpec
        cam speed, follower inertia, spring rate, preload, constant load.

    Returns
    -------
    CamForces
    """
    g, f = geometry, geometry.follower
    w2 = spec.speed ** 2
    if f.motion == "translating":
        q = spec.mass * w2 * g.a + spec.preload + spec.spring_rate * g.s + spec.force
    else:
        l = f.arm
        q = (spec.mass * w2 * g.a / l + spec.preload + spec.spring_rate * g.s / l + spec.force) / l
    lever = np.sum(g.normal * g.lever, axis=-1)
    contact = q / lever
    return CamForces(q, contact, q * g.v, contact <= 0)
