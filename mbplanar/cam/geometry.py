"""Exact cam geometry: pitch curve by inversion, working profile as the true envelope, pressure angle,
radii of curvature, undercut.

Inversion: the cam is held still and the follower's stand is turned by −σφ (σ = `rotation`). A point X
of the fixed frame becomes R(−σφ)·X in the cam's frame, and its derivative with respect to φ is
R(−σφ)·(X′ − σ·J·X) (J: a turn by +90°).

- Roller or knife: the pitch curve c(φ) is the inverted pitch point. The roller's envelope is
  W = c − r·n, n the unit normal of c pointing away from the cam (for σ = +1 the curve runs clockwise:
  n = σ·J·c′/|c′|). Its radius of curvature ρ_p = −σ|c′|³/(c′ × c″) is positive where the pitch curve is
  convex; the profile's is ρ_w = ρ_p − r; W′ = c′(1 − r/ρ_p). Where ρ_p ≤ r on a convex stretch the
  envelope folds back (undercut): the roller cannot follow the law there.
- Flat face: the face's line is a family X·ν(α) = p in the cam's frame (α decreases by σφ); the envelope
  is X = p·ν + (dp/dα)·J·ν with radius of curvature ρ = p + d²p/dα², which must stay positive.

The pressure angle is the angle between the force the cam exerts (along the contact normal, away from the
cam) and the direction in which the follower's point moves on the rise (∂X/∂s: the pitch point for a
roller or a knife, the contact point for a flat face), signed positive in the cam's sense of rotation.
For the oscillating roller follower this is the seed's θ = atan((v + a_w cos(φ₂₀ + ψ) − l)/(a_w sin(φ₂₀ + ψ))).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from .followers import Follower, face_line, lift_direction, pitch_point

__all__ = ["CamGeometry", "cam_geometry", "rotate"]


def rotate(x: np.ndarray, angle) -> np.ndarray:
    """Points x (N, 2) turned counter-clockwise by `angle` (N,) or a scalar."""
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([c * x[..., 0] - s * x[..., 1], s * x[..., 0] + c * x[..., 1]], axis=-1)


def _perp(v):
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def _cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _dot(a, b):
    return np.sum(a * b, axis=-1)


@dataclass(frozen=True)
class CamGeometry:
    """The cam at cam angles `phi` (N,); points in the cam's frame unless named `_fixed`.

    Attributes
    ----------
    follower : Follower
        The follower it drives.
    phi : (N,) ndarray
        Cam angle, rad.
    s, v, a : (N,) ndarray
        Lift (m), its analogues ds/dφ (m/rad), d²s/dφ² (m/rad²).
    pitch : (N, 2) ndarray or None
        The pitch curve (roller centre / knife tip), m; None for a flat face.
    profile : (N, 2) ndarray
        The working profile (the contact points), m.
    profile_d1 : (N, 2) ndarray
        dW/dφ, m/rad.
    normal : (N, 2) ndarray
        Unit contact normal, away from the cam.
    contact_fixed : (N, 2) ndarray
        The contact point in the fixed frame, m.
    pressure : (N,) ndarray
        Pressure angle, rad (sign: see the module).
    rho_pitch : (N,) ndarray or None
        Radius of curvature of the pitch curve (+ convex), m; None for a flat face.
    rho_profile : (N,) ndarray
        Radius of curvature of the working profile (+ convex), m.
    lever : (N, 2) ndarray
        ∂X/∂s of the follower's driven point (pitch point or contact), fixed frame.

    Examples
    --------
    A roller's profile lies one roller radius inside its pitch curve:

    >>> import numpy as np
    >>> from mbplanar.cam import Follower, cam_geometry, make_law, program
    >>> cyc, dwell = make_law("cycloidal"), make_law("dwell")
    >>> p = program([("rise", cyc, np.pi / 2, 0.02), ("dwell", dwell, np.pi / 2, None),
    ...              ("return", cyc, np.pi / 2, 0.02), ("dwell", dwell, np.pi / 2, None)])
    >>> phi = p.grid(360)
    >>> g = cam_geometry(Follower("translating", "roller", base_radius=0.04, roller=0.01), phi, *p.evaluate(phi)[:3])
    >>> np.allclose(np.hypot(*(g.pitch - g.profile).T), 0.01, rtol=0, atol=1e-15), g.profile.shape
    (True, (360, 2))
    """

    follower: Follower
    phi: np.ndarray
    s: np.ndarray
    v: np.ndarray
    a: np.ndarray
    pitch: np.ndarray | None
    profile: np.ndarray
    profile_d1: np.ndarray
    normal: np.ndarray
    contact_fixed: np.ndarray
    pressure: np.ndarray
    rho_pitch: np.ndarray | None
    rho_profile: np.ndarray
    lever: np.ndarray

    @property
    def rho_min(self) -> float:
        """Smallest convex radius of curvature of the pitch curve (roller, knife) or profile (flat), m."""
        rho = self.rho_pitch if self.rho_pitch is not None else self.rho_profile
        convex = rho[rho > 0]
        return float(convex.min()) if convex.size else float("inf")

    @property
    def undercut(self) -> bool:
        """True where the profile folds (roller ≥ ρ_min of the pitch curve, or a flat face's ρ ≤ 0)."""
        return bool(np.any(self.rho_profile <= 0) if self.rho_pitch is None
                    else self.follower.roller >= self.rho_min)


def cam_geometry(follower: Follower, phi, s, v, a) -> CamGeometry:
    """The cam that drives a follower through a lift s(φ): profile, pressure angle, curvature.

    Parameters
    ----------
    follower : Follower
        The follower (SI).
    phi : (N,) array_like
        Cam angles, rad.
    s, v, a : (N,) array_like
        Lift (m) and its analogues ds/dφ (m/rad), d²s/dφ² (m/rad²).

    Returns
    -------
    CamGeometry
        The pitch curve and profile in the cam's frame, the pressure angle and radii of curvature.

    Raises
    ------
    ValueError
        Arrays of different lengths (numpy's broadcasting error).

    Examples
    --------
    A cycloidal rise of 20 mm over 90°: at 45°, s = h/2 and ds/dφ = 2h/β; a knife-edge at r0 = 40 mm
    on the cam's axis has tan(pressure angle) = (ds/dφ)/(r0 + s):

    >>> import numpy as np
    >>> from mbplanar.cam import Follower, cam_geometry, make_law, program
    >>> cyc, dwell = make_law("cycloidal"), make_law("dwell")
    >>> p = program([("rise", cyc, np.pi / 2, 0.02), ("dwell", dwell, np.pi / 2, None),
    ...              ("return", cyc, np.pi / 2, 0.02), ("dwell", dwell, np.pi / 2, None)])
    >>> phi = np.radians([45.0])
    >>> s, v, a, j = p.evaluate(phi)
    >>> g = cam_geometry(Follower("translating", "knife", base_radius=0.04), phi, s, v, a)
    >>> round(float(g.pressure[0]), 9), round(float(np.arctan(2 * 0.02 / (np.pi / 2) / 0.05)), 9)
    (0.471056578, 0.471056578)
    """
    phi, s, v, a = (np.asarray(x, float) for x in (phi, s, v, a))
    sigma = follower.rotation
    turn = -sigma * phi
    if follower.contact == "flat":
        return _flat(follower, phi, s, v, a, turn)
    b = pitch_point(follower, s, v, a)
    c = rotate(b.b, turn)
    c1 = rotate(b.d1 - sigma * _perp(b.b), turn)
    c2 = rotate(b.d2 - 2 * sigma * _perp(b.d1) - b.b, turn)
    speed = np.linalg.norm(c1, axis=-1)
    if np.any(speed <= 1e-12 * (1 + np.linalg.norm(c, axis=-1))):
        k = int(np.argmin(speed))
        raise ModelError(f"the follower's pitch point stands still on the cam at cam angle "
                         f"{np.degrees(phi[k]):.6g}°: no profile can drive it there")
    normal_c = sigma * _perp(c1) / speed[:, None]
    with np.errstate(divide="ignore"):
        rho_p = -sigma * speed ** 3 / _cross(c1, c2)      # ±inf on a straight stretch
    r = follower.roller
    profile = c - r * normal_c
    profile_d1 = c1 * (1 - r / rho_p)[:, None]
    normal = rotate(normal_c, -turn)
    lever = lift_direction(follower, b.b)
    return CamGeometry(follower, phi, s, v, a, c, profile, profile_d1, normal,
                       rotate(profile, -turn), _pressure(sigma, lever, normal), rho_p, rho_p - r, lever)


def _flat(follower, phi, s, v, a, turn):
    sigma = follower.rotation
    line = face_line(follower, s, v, a)
    alpha = line.alpha + turn
    w1, w2 = line.alpha_d1 - sigma, line.alpha_d2
    if np.any(-sigma * w1 < 1e-9):                      # the face's normal must keep turning against the cam
        k = int(np.argmin(-sigma * w1))
        raise ModelError(f"the flat face turns with the cam at cam angle {np.degrees(phi[k]):.6g}° "
                         f"(dψ/dφ = {line.alpha_d1[k]:.6g}): no flat-faced cam can drive this motion")
    dp = line.p_d1 / w1
    d2p = (line.p_d2 * w1 - line.p_d1 * w2) / w1 ** 3
    nu = np.stack([np.cos(alpha), np.sin(alpha)], -1)
    profile = line.p[:, None] * nu + dp[:, None] * _perp(nu)
    rho = line.p + d2p
    profile_d1 = (rho * w1)[:, None] * _perp(nu)
    normal = rotate(nu, -turn)
    contact = rotate(profile, -turn)
    lever = lift_direction(follower, contact)
    return CamGeometry(follower, phi, s, v, a, None, profile, profile_d1, normal, contact,
                       _pressure(sigma, lever, normal), None, rho, lever)


def _pressure(sigma, lever, normal):
    """Signed angle from the follower point's direction of rise to the contact normal."""
    return sigma * np.arctan2(_cross(lever, normal), _dot(lever, normal))
