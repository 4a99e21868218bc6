"""Followers of a disc cam and where they stand for a given lift.

Frame (fixed, cam centre O at the origin): a translating follower moves along +y on the line x = `offset`;
an oscillating follower turns about the pivot P = (0, −a_w), its arm at the angle φ₂₀ + ψ measured
counter-clockwise from the line P→O (ψ = s/l: the program's displacement s is the arc at the arm's end).
The rise always moves the follower away from the cam (+y, or ψ increasing counter-clockwise); the cam
turns counter-clockwise (`rotation` = +1) or clockwise (−1). Any other layout is a rotation or a mirror
image of one of these.

For a roller or a knife edge the follower is described by its pitch point B (the roller's centre, the
knife's tip) and its derivatives with respect to the cam angle φ; for a flat face by the face's line,
as a unit normal at angle α (pointing away from the cam) and its distance p from O (a support function).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError

__all__ = ["Follower", "PitchPoint", "FaceLine", "pitch_point", "face_line", "lift_direction"]

MOTIONS = ("translating", "oscillating")
CONTACTS = ("knife", "roller", "flat")


@dataclass(frozen=True)
class Follower:
    """A follower's kind and size (SI: metres, radians).

    Attributes
    ----------
    motion : {"translating", "oscillating"}
        How the follower moves.
    contact : {"knife", "roller", "flat"}
        Its contact with the cam.
    rotation : int
        +1 (the cam turns counter-clockwise) or −1.
    base_radius : float
        Translating knife/roller: r₀, the distance O–B at s = 0; flat: the distance O–face at s = 0.
    offset : float
        Translating: x of the follower's line (the offset e).
    roller : float
        Roller radius (0 for a knife or a flat face).
    centre_distance : float
        Oscillating: a_w = |OP|.
    arm : float
        Oscillating: l = |PB|.
    arm_angle : float
        Oscillating: φ₂₀, the angle from P→O to the arm at s = 0 (rad).
    face_offset : float
        Oscillating flat face: the distance from P to the face (on the cam's side of the arm).

    Raises
    ------
    ModelError
        On construction, for an unknown motion, contact or rotation, or a size that cannot exist: a
        roller or base radius that is not positive, an offset not inside the base circle, an arm or
        centre distance that is not positive, an arm angle outside (0°, 180°), a flat face through
        the cam's centre.

    Examples
    --------
    >>> from mbplanar.cam import Follower
    >>> Follower("translating", "roller", base_radius=0.05, offset=0.008, roller=0.01).roller
    0.01
    >>> Follower("translating", "knife")
    Traceback (most recent call last):
    ...
    mbplanar.errors.ModelError: the base radius must be positive, got 0.0
    """

    motion: str
    contact: str
    rotation: int = 1
    base_radius: float = 0.0
    offset: float = 0.0
    roller: float = 0.0
    centre_distance: float = 0.0
    arm: float = 0.0
    arm_angle: float = 0.0
    face_offset: float = 0.0

    def __post_init__(self):
        if self.motion not in MOTIONS:
            raise ModelError(f"follower motion must be one of {', '.join(MOTIONS)}, got '{self.motion}'")
        if self.contact not in CONTACTS:
            raise ModelError(f"follower contact must be one of {', '.join(CONTACTS)}, got '{self.contact}'")
        if self.rotation not in (1, -1):
            raise ModelError(f"cam rotation must be +1 (ccw) or -1 (cw), got {self.rotation}")
        if self.roller < 0 or (self.contact == "roller" and self.roller <= 0):
            raise ModelError(f"the roller radius must be positive, got {self.roller}")
        if self.motion == "translating":
            if self.base_radius <= 0:
                raise ModelError(f"the base radius must be positive, got {self.base_radius}")
            if self.contact != "flat" and abs(self.offset) >= self.base_radius:
                raise ModelError(f"the offset {self.offset:g} m must be smaller than the base radius "
                                 f"{self.base_radius:g} m (the follower's line must cut the base circle)")
        else:
            if self.centre_distance <= 0 or self.arm <= 0:
                raise ModelError(f"the centre distance a_w and the arm l must be positive, got "
                                 f"a_w = {self.centre_distance}, l = {self.arm}")
            if self.contact == "flat" and self.prime_radius <= 0:
                raise ModelError(f"the flat face passes the cam centre: a_w·sin φ20 − face_offset = "
                                 f"{self.prime_radius:.6g} m must be positive")
            if not 0 < self.arm_angle < math.pi:
                raise ModelError(f"the arm angle φ20 must lie between 0° and 180°, got "
                                 f"{math.degrees(self.arm_angle):.6g}°")

    @property
    def prime_radius(self) -> float:
        """r₀: distance from O to the pitch point (roller centre) at s = 0; for a flat face, to the face."""
        if self.motion == "translating":
            return self.base_radius
        if self.contact == "flat":
            return self.centre_distance * math.sin(self.arm_angle) - self.face_offset
        a, l, g = self.centre_distance, self.arm, self.arm_angle
        return math.sqrt(a * a + l * l - 2 * a * l * math.cos(g))

    @property
    def pivot(self) -> np.ndarray:
        """P (oscillating) in the fixed frame."""
        return np.array([0.0, -self.centre_distance])

    def with_size(self, **changes) -> "Follower":
        """A copy with some sizes changed (sizing)."""
        from dataclasses import replace
        return replace(self, **changes)


@dataclass(frozen=True)
class PitchPoint:
    """B and its first two derivatives with respect to φ in the fixed frame; each (N, 2)."""

    b: np.ndarray
    d1: np.ndarray
    d2: np.ndarray


@dataclass(frozen=True)
class FaceLine:
    """The face's line X·ν(α) = p in the fixed frame: α, p and their first two derivatives; each (N,)."""

    alpha: np.ndarray
    alpha_d1: np.ndarray
    alpha_d2: np.ndarray
    p: np.ndarray
    p_d1: np.ndarray
    p_d2: np.ndarray


def _unit(angle):
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def _perp(v):
    """v turned by +90°."""
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def pitch_point(f: Follower, s, v, a) -> PitchPoint:
    """B(φ), B′, B″ for lift s, v = ds/dφ, a = d²s/dφ² (arrays (N,))."""
    s, v, a = (np.asarray(x, float) for x in (s, v, a))
    if f.motion == "translating":
        s0 = math.sqrt(f.base_radius ** 2 - f.offset ** 2)
        zero = np.zeros_like(s)
        return PitchPoint(np.stack([zero + f.offset, s0 + s], -1), np.stack([zero, v], -1),
                          np.stack([zero, a], -1))
    e = _unit(np.pi / 2 + f.arm_angle + s / f.arm)
    n = _perp(e)
    b = f.pivot + f.arm * e
    return PitchPoint(b, v[:, None] * n, a[:, None] * n - (v * v / f.arm)[:, None] * e)


def face_line(f: Follower, s, v, a) -> FaceLine:
    """The flat face's line for lift s, v, a (its normal points away from the cam)."""
    s, v, a = (np.asarray(x, float) for x in (s, v, a))
    if f.motion == "translating":
        zero = np.zeros_like(s)
        return FaceLine(zero + np.pi / 2, zero, zero, f.base_radius + s, v, a)
    l, g = f.arm, f.arm_angle + s / f.arm
    w, w1 = v / l, a / l
    p = f.centre_distance * np.sin(g) - f.face_offset
    p1 = f.centre_distance * np.cos(g) * w
    p2 = f.centre_distance * (np.cos(g) * w1 - np.sin(g) * w * w)
    return FaceLine(np.pi + g, w, w1, p, p1, p2)


def lift_direction(f: Follower, x: np.ndarray) -> np.ndarray:
    """∂X/∂s: how a follower point X (fixed frame, (N, 2)) moves per metre of lift s."""
    x = np.asarray(x, float)
    if f.motion == "translating":
        return np.broadcast_to(np.array([0.0, 1.0]), x.shape).copy()
    return _perp(x - f.pivot) / f.arm
