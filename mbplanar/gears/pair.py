"""An involute spur gear pair with profile shift: geometry, path of contact and the quality checks.

Conventions (ISO 21771 and the course books): module m, tooth numbers z₁ (the pinion) and z₂, basic rack
`Rack` (α, h_a*, c*, ρ_f*), profile shift coefficients x₁, x₂. For an internal pair gear 2 is the ring
(internal teeth) and its shift follows KHK and GOST 19274: x₂ > 0 moves the ring's teeth away from its
axis (its tip circle grows, its teeth get thinner).

External pair: inv α_w = inv α + 2 tan α (x₁ + x₂)/(z₁ + z₂), a = m(z₁ + z₂)/2, a_w = a cos α/cos α_w,
y = (a_w − a)/m, Δy = x₁ + x₂ − y (the tips are shortened by Δy·m to keep the clearance c*·m),
d_a = d + 2m(h_a* + x − Δy), d_f = d − 2m(h_a* + c* − x).
Internal pair: inv α_w = inv α + 2 tan α (x₂ − x₁)/(z₂ − z₁), a = m(z₂ − z₁)/2, no tip shortening,
d_a2 = d₂ − 2m(h_a* − x₂), d_f2 = d₂ + 2m(h_a* + c* + x₂) (KHK's Table 5-1).

Along the line of action (N₁ and N₂ the tangent points on the base circles, L = N₁N₂ = a_w sin α_w) a
contact point is ρ₁ from N₁ and ρ₂ = L − ρ₁ from N₂ (internal: ρ₂ = L + ρ₁); ρ is the radius of curvature
of each involute there. The path runs from A (gear 2's tip) to E (gear 1's tip): ρ₁(E) = √(r_a1² − r_b1²),
ρ₂(A) = √(r_a2² − r_b2²); ε_α = AE/p_b with p_b = π m cos α. Specific sliding ζ₁ = 1 − ρ₂/(u ρ₁),
ζ₂ = 1 − u ρ₁/ρ₂ (u = z₂/z₁), most negative at the root end of each gear's active profile (ζ₁ at A,
ζ₂ at E).

Checks, each a `Check` with its margin (≥ 0: met):

- undercut: x ≥ x_min = h_fe* − z sin²α/2 (rack-cut gears);
- pointed tip: s_a ≥ `min_tip`·m (0.25 m by default), s_a = d_a(s/d + inv α − inv α_a);
- interference with the mate's root: the contact must start on the involute, at or above the point
  where the rack's straight flank ends, ρ_l = r sin α − (h_fe* − x)m/sin α, i.e. ρ₁(A) ≥ max(ρ_l1, 0)
  (and ρ₂(E) ≥ max(ρ_l2, 0) for an external gear 2);
- internal pairs: the ring's tip outside its base circle, and no trochoid interference (the pinion's tip
  leaving the ring's tooth space, KHK/SDP eq. 5-6);
- contact ratio ε_α ≥ `min_contact` (1.2 by default).

    >>> from mbplanar.gears import gear_pair
    >>> p = gear_pair(3e-3, (12, 24), (0.6, 0.36))
    >>> round(p.centre_distance * 1e3, 4), round(p.working_pressure_angle_deg, 4)
    (56.4999, 26.0886)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from .involute import arcinv, inv
from .rack import Rack

__all__ = ["Gear", "Check", "GearPair", "gear_pair", "mesh", "margins", "validate_teeth", "validate_module",
           "shift_sum_for", "MIN_TIP", "MIN_CONTACT", "MARGIN_TOLERANCE"]

MIN_TIP = 0.25          # s_a ≥ 0.25 m
MIN_CONTACT = 1.2       # ε_α ≥ 1.2
MARGIN_TOLERANCE = 1e-12    # a margin ≥ −1e-12 (in its unit) counts as met: rounding of a limit met exactly


@dataclass(frozen=True)
class Gear:
    """One gear of a pair (SI: metres, radians).

    Attributes
    ----------
    teeth, shift : z and x
    internal : True for the ring of an internal pair
    pitch_diameter, base_diameter, working_diameter, tip_diameter, root_diameter : d, d_b, d_w, d_a, d_f
    pitch_thickness, tip_thickness : s and s_a (arc lengths on those circles; the ring's: of its tooth)
    tip_pressure_angle : α_a = arccos(d_b/d_a)
    min_shift : x_min for no undercut (None for a ring)
    form_radius : radius where the rack's straight flank stops generating the involute, √(r_b² + ρ_l²)
                  (None for a ring; ρ_l < 0 means undercut, then r_b)
    active_diameter : where the active profile ends on the root side (the mate's tip meets it)
    root_sliding, tip_sliding : specific sliding at the root-side and tip ends of the active profile

    Examples
    --------
    >>> from mbplanar.gears import gear_pair
    >>> g = gear_pair(3e-3, (12, 24), (0.6, 0.36)).gears[0]
    >>> round(g.tip_diameter * 1e3, 3), round(g.min_shift, 4)
    (44.84, 0.2981)
    """

    teeth: int
    shift: float
    internal: bool
    pitch_diameter: float
    base_diameter: float
    working_diameter: float
    tip_diameter: float
    root_diameter: float
    pitch_thickness: float
    tip_thickness: float
    tip_pressure_angle: float
    min_shift: float | None
    form_radius: float | None
    active_diameter: float
    root_sliding: float
    tip_sliding: float


@dataclass(frozen=True)
class Check:
    """One quality check: `margin` ≥ 0 when it is met (in modules, radians or plain numbers, as `value`).

    Examples
    --------
    >>> from mbplanar.gears import gear_pair
    >>> c = gear_pair(10e-3, (12, 30), (0.0, 0.0)).checks[0]
    >>> c.name, c.gear, c.ok, round(c.limit, 4)
    ('undercut', 1, False, 0.2981)
    """

    name: str
    gear: int | None
    value: float
    limit: float
    margin: float
    ok: bool
    message: str


@dataclass(frozen=True)
class GearPair:
    """The geometry of a meshing pair and its checks (SI: metres, radians).

    Attributes
    ----------
    module, rack, internal
    ring_tip : "standard" or "cut" (internal pairs, see `mesh`)
    gears : (Gear, Gear)
    ratio : u = z₂/z₁
    working_pressure_angle, inv_working : α_w and inv α_w
    reference_centre_distance, centre_distance : a and a_w
    centre_factor : y = (a_w − a)/m
    tip_reduction : Δy (external pairs; 0 for internal)
    base_pitch : p_b = π m cos α
    line_of_action : L = N₁N₂ = a_w sin α_w
    path : (ρ₁(A), ρ₁(E)), the ends of the path of contact measured from N₁ along the line of action
    path_length : g_α = ρ₁(E) − ρ₁(A)
    contact_ratio : ε_α = g_α/p_b
    checks : tuple of `Check`
    success : every check met
    message : the failed checks, or "all checks met"

    Examples
    --------
    >>> from mbplanar.gears import gear_pair
    >>> p = gear_pair(3e-3, (12, 24), (0.6, 0.36))
    >>> round(p.contact_ratio, 3), p.success, [c.name for c in p.failed()]
    (1.202, True, [])
    """

    module: float
    rack: Rack
    internal: bool
    ring_tip: str
    gears: tuple
    ratio: float
    working_pressure_angle: float
    inv_working: float
    reference_centre_distance: float
    centre_distance: float
    centre_factor: float
    tip_reduction: float
    base_pitch: float
    line_of_action: float
    path: tuple
    path_length: float
    contact_ratio: float
    checks: tuple
    success: bool
    message: str

    @property
    def working_pressure_angle_deg(self) -> float:
        """α_w in degrees."""
        return math.degrees(self.working_pressure_angle)

    @property
    def shifts(self) -> tuple:
        """(x₁, x₂)."""
        return self.gears[0].shift, self.gears[1].shift

    def failed(self) -> tuple:
        """The checks not met."""
        return tuple(c for c in self.checks if not c.ok)


def validate_teeth(z1, z2, internal: bool = False, where: str = "--teeth") -> tuple[int, int]:
    """Tooth numbers as integers ≥ 1 (an internal pair: z₂ > z₁), or a `ModelError` naming the value."""
    out = []
    for k, z in enumerate((z1, z2), 1):
        if isinstance(z, bool) or not isinstance(z, (int, np.integer, float)) or not math.isfinite(z) \
                or z != int(z) or z < 1:
            raise ModelError(f"{where}: tooth number z{k} must be a whole number ≥ 1, got {z!r}")
        out.append(int(z))
    if internal and out[1] <= out[0]:
        raise ModelError(f"{where}: an internal gear needs more teeth than its pinion, got z1 = {out[0]}, "
                         f"z2 = {out[1]}")
    return out[0], out[1]


def validate_module(m, where: str = "--module") -> float:
    """The module as a float > 0, or a `ModelError` naming the value."""
    if isinstance(m, bool) or not isinstance(m, (int, float, np.floating)) or not math.isfinite(m) or m <= 0:
        raise ModelError(f"{where}: the module must be > 0, got {m!r}")
    return float(m)


def shift_sum_for(z1: int, z2: int, centre_distance: float, module: float, rack: Rack,
                  internal: bool = False) -> float:
    """x₁ + x₂ (internal: x₂ − x₁) that gives the working centre distance `centre_distance` (m).

    Raises
    ------
    ModelError
        a centre distance the pair cannot take (cos α_w > 1).
    """
    a = module * ((z2 - z1) if internal else (z1 + z2)) / 2
    c = a * math.cos(rack.pressure_angle) / centre_distance
    if not (math.isfinite(c) and 0 < c < 1):
        raise ModelError(f"--centre-distance: {centre_distance * 1e3:.6g} mm cannot be taken by z = {z1}, {z2}, "
                         f"m = {module * 1e3:g} mm (it needs a_w > a·cos α = {a * math.cos(rack.pressure_angle) * 1e3:.6g} mm)")
    aw = math.acos(c)
    return (inv(aw) - inv(rack.pressure_angle)) * ((z2 - z1) if internal else (z1 + z2)) / (2 * math.tan(rack.pressure_angle))


def mesh(module: float, z1: int, z2: int, x1, x2, rack: Rack = Rack(), internal: bool = False,
         ring_tip: str = "standard") -> dict:
    """Every quantity of the pair for arrays of shifts `x1`, `x2` (broadcast together), in SI units.

    Parameters
    ----------
    module : float
        m, metres.
    z1, z2 : int or array_like
        tooth numbers (an internal pair: z₂ > z₁, gear 2 the ring).
    x1, x2 : float or array_like
        profile shift coefficients (broadcast with the tooth numbers).
    rack : Rack
    internal : bool
    ring_tip : {"standard", "cut"}
        an internal pair's ring tip: d_a2 = d₂ − 2m(h_a* − x₂), or that cut back (enlarged) where needed
        so that the ring's tip meets the pinion on its involute, d_a2 ≥ 2√(r_b2² + (a_w sin α_w + ρ_l1)²).

    Returns
    -------
    dict of numpy.ndarray
        keys: inv_w, alpha_w, a, aw, y, dy, L, pb, and per gear k = 1, 2: d{k}, db{k}, dw{k}, da{k}, df{k},
        s{k}, sa{k}, alpha_a{k}, xmin{k}, rho_l{k}; the path: rho_A1, rho_E1, rho_A2, rho_E2, eps;
        sliding: zeta1_A, zeta1_E, zeta2_A, zeta2_E. NaN where the shifts give no mesh.

    Examples
    --------
    >>> from mbplanar.gears.pair import mesh
    >>> q = mesh(3e-3, 12, 24, 0.6, 0.36)
    >>> round(float(q["eps"]), 3)
    1.202
    """
    m, al = module, rack.pressure_angle
    z1, z2, x1, x2 = np.broadcast_arrays(np.asarray(z1, float), np.asarray(z2, float), np.asarray(x1, float),
                                         np.asarray(x2, float))
    ta, ca, sa = math.tan(al), math.cos(al), math.sin(al)
    ha, c, hfe = rack.addendum, rack.clearance, rack.flank_end
    q = {}
    if internal:
        q["inv_w"] = inv(al) + 2 * ta * (x2 - x1) / (z2 - z1)
        q["a"] = m * (z2 - z1) / 2
    else:
        q["inv_w"] = inv(al) + 2 * ta * (x1 + x2) / (z1 + z2)
        q["a"] = m * (z1 + z2) / 2
    q["alpha_w"] = arcinv(q["inv_w"])                       # NaN where inv α_w < 0
    aw = q["a"] * ca / np.cos(q["alpha_w"])
    q["aw"] = aw
    q["y"] = (aw - q["a"]) / m
    q["dy"] = np.zeros_like(aw) if internal else x1 + x2 - q["y"]
    q["L"] = aw * np.sin(q["alpha_w"])
    q["pb"] = math.pi * m * ca
    for k, z, x in ((1, z1, x1), (2, z2, x2)):
        d = m * z
        db = d * ca
        ring = internal and k == 2
        q[f"d{k}"], q[f"db{k}"] = d + 0 * x, db + 0 * x
        q[f"dw{k}"] = d * ca / np.cos(q["alpha_w"])
        if ring:
            da = d - 2 * m * (ha - x)
            if ring_tip == "cut":                               # contact to start on the pinion's involute
                da = np.maximum(da, 2 * np.hypot(db / 2, q["L"] + np.maximum(q["rho_l1"], 0.0)))
            df = d + 2 * m * (ha + c + x)
            s = m * (math.pi / 2 - 2 * x * ta)
        else:
            da = d + 2 * m * (ha + x - q["dy"])
            df = d - 2 * m * (ha + c - x)
            s = m * (math.pi / 2 + 2 * x * ta)
        with np.errstate(invalid="ignore"):
            alpha_a = np.arccos(np.clip(db / da, -1.0, 1.0))
            alpha_a = np.where(da >= db, alpha_a, np.nan)
        sign = -1.0 if ring else 1.0                            # a ring's tooth widens outwards
        q[f"da{k}"], q[f"df{k}"], q[f"s{k}"], q[f"alpha_a{k}"] = da, df, s, alpha_a
        q[f"sa{k}"] = da * (s / d + sign * (inv(al) - inv(alpha_a)))
        q[f"xmin{k}"] = np.full_like(x + z, np.nan) if ring else hfe - z * sa * sa / 2 + 0 * x
        q[f"rho_l{k}"] = np.full_like(x + z, np.nan) if ring else d / 2 * sa - (hfe - x) * m / sa
    with np.errstate(invalid="ignore"):
        q["rho_E1"] = np.sqrt(q["da1"] ** 2 - q["db1"] ** 2) / 2
        q["rho_A2"] = np.sqrt(q["da2"] ** 2 - q["db2"] ** 2) / 2
    if internal:
        q["rho_A1"] = q["rho_A2"] - q["L"]
        q["rho_E2"] = q["rho_E1"] + q["L"]
    else:
        q["rho_A1"] = q["L"] - q["rho_A2"]
        q["rho_E2"] = q["L"] - q["rho_E1"]
    q["eps"] = (q["rho_E1"] - q["rho_A1"]) / q["pb"]
    u = z2 / z1
    with np.errstate(divide="ignore", invalid="ignore"):
        for end in ("A", "E"):
            r1, r2 = q[f"rho_{end}1"], q[f"rho_{end}2"]
            q[f"zeta1_{end}"] = np.where(r1 > 0, 1 - r2 / (u * r1), -np.inf)
            q[f"zeta2_{end}"] = np.where(r2 > 0, 1 - u * r1 / r2, -np.inf)
    if internal:
        q["trochoid"] = _trochoid_margin(q, z1, z2)
    return q


def _trochoid_margin(q, z1, z2):
    """KHK/SDP eq. (5-6): θ₁ z₁/z₂ + inv α_w − inv α_a2 − θ₂ (rad); ≥ 0: the pinion's tip clears the ring's
    tooth as it leaves the mesh. Tip circles that do not cross cannot interfere (margin π)."""
    a, ra1, ra2 = q["aw"], q["da1"] / 2, q["da2"] / 2
    c1 = (ra2 ** 2 - ra1 ** 2 - a ** 2) / (2 * a * ra1)
    c2 = (a ** 2 + ra2 ** 2 - ra1 ** 2) / (2 * a * ra2)
    crossing = (np.abs(c1) <= 1) & (np.abs(c2) <= 1)
    with np.errstate(invalid="ignore"):
        th1 = np.arccos(np.clip(c1, -1, 1)) + inv(q["alpha_a1"]) - inv(q["alpha_w"])
        th2 = np.arccos(np.clip(c2, -1, 1))
        out = th1 * z1 / z2 + inv(q["alpha_w"]) - inv(q["alpha_a2"]) - th2
    return np.where(crossing, out, math.pi)


CHECKS = ("undercut", "pointed tip", "interference", "ring tip", "trochoid interference", "contact ratio")


def margins(q: dict, x1, x2, module: float, internal: bool, min_tip: float = MIN_TIP,
            min_contact: float = MIN_CONTACT) -> dict:
    """The checks' margins (≥ 0: met) from a `mesh` dict, as {(check, gear): array}; gear None for the
    pair. Undercut: x − x_min; pointed tip: (s_a − min_tip·m)/m; interference: (ρ − max(ρ_l, 0))/m at the
    root end of the active profile; ring tip: (r_a2 − r_b2)/m; trochoid interference: radians; contact
    ratio: ε_α − min_contact. NaN (no mesh) counts as not met.

    Examples
    --------
    >>> from mbplanar.gears.pair import mesh, margins
    >>> q = mesh(1e-3, 12, 30, 0.0, 0.0)
    >>> round(float(margins(q, 0.0, 0.0, 1e-3, False)[("undercut", 1)]), 4)   # x − x_min < 0: undercut
    -0.2981
    """
    m = module
    x1, x2 = np.broadcast_arrays(np.asarray(x1, float), np.asarray(x2, float))
    out = {("undercut", 1): x1 - q["xmin1"],
           ("pointed tip", 1): (q["sa1"] - min_tip * m) / m,
           ("interference", 1): (q["rho_A1"] - np.maximum(q["rho_l1"], 0.0)) / m}
    if internal:
        out[("pointed tip", 2)] = (q["sa2"] - min_tip * m) / m
        out[("ring tip", 2)] = (q["da2"] - q["db2"]) / (2 * m)
        out[("trochoid interference", 2)] = q["trochoid"]
    else:
        out[("undercut", 2)] = x2 - q["xmin2"]
        out[("pointed tip", 2)] = (q["sa2"] - min_tip * m) / m
        out[("interference", 2)] = (q["rho_E2"] - np.maximum(q["rho_l2"], 0.0)) / m
    out[("contact ratio", None)] = q["eps"] - min_contact
    return {k: np.where(np.isfinite(v), v, np.where(v == np.inf, v, -np.inf)) for k, v in out.items()}


def _finite_shift(x, name) -> float:
    if isinstance(x, bool) or not isinstance(x, (int, float, np.floating, np.integer)) or not math.isfinite(x):
        raise ModelError(f"shift {name} must be a finite number, got {x!r}")
    return float(x)


def gear_pair(module: float, teeth, shifts=(0.0, 0.0), *, internal: bool = False, rack: Rack | None = None,
              min_tip: float = MIN_TIP, min_contact: float = MIN_CONTACT, ring_tip: str = "standard") -> GearPair:
    """The geometry, path of contact, sliding and checks of a spur pair.

    Parameters
    ----------
    module : float
        m in metres.
    teeth : (int, int)
        z₁, z₂ (internal: z₂ > z₁, gear 2 the ring).
    shifts : (float, float)
        x₁, x₂.
    internal : bool
        gear 2 has internal teeth.
    rack : Rack, optional
        the basic rack (default: α = 20°, h_a* = 1, c* = 0.25).
    min_tip : float
        smallest tip thickness, in modules.
    min_contact : float
        smallest transverse contact ratio.
    ring_tip : {"standard", "cut"}
        an internal pair's ring tip (see `mesh`): "cut" enlarges its tip circle where the standard one
        would meet the pinion below its involute.

    Returns
    -------
    GearPair
        with `success` False and a `message` naming the failed checks when a check is not met.

    Raises
    ------
    ModelError
        m ≤ 0, a tooth number below 1, non-finite shifts, or shifts that give no mesh (inv α_w < 0).

    Examples
    --------
    >>> from mbplanar.gears import gear_pair
    >>> p = gear_pair(10e-3, (12, 30), (0.3, 0.0))
    >>> [round(g.tip_diameter * 1e3, 3) for g in p.gears], round(p.contact_ratio, 4)
    ([145.719, 319.719], 1.4146)
    >>> p.success
    True
    """
    rack = Rack() if rack is None else rack
    m = validate_module(module, "module")
    z1, z2 = validate_teeth(*teeth, internal=internal, where="teeth")
    x1, x2 = _finite_shift(shifts[0], "x1"), _finite_shift(shifts[1], "x2")
    if not (math.isfinite(min_tip) and min_tip >= 0):
        raise ModelError(f"the smallest tip thickness must be ≥ 0 (in modules), got {min_tip!r}")
    if not (math.isfinite(min_contact) and min_contact > 0):
        raise ModelError(f"the smallest contact ratio must be > 0, got {min_contact!r}")
    if ring_tip not in ("standard", "cut"):
        raise ModelError(f"--ring-tip must be 'standard' or 'cut', got {ring_tip!r}")
    q = {k: (float(v) if np.ndim(v) == 0 else v)
         for k, v in mesh(m, z1, z2, x1, x2, rack, internal, ring_tip).items()}
    if not math.isfinite(q["alpha_w"]):
        what = "x2 − x1" if internal else "x1 + x2"
        raise ModelError(f"shifts x1 = {x1:g}, x2 = {x2:g}: {what} is so negative that inv α_w = "
                         f"{q['inv_w']:.6g} < 0; the teeth cannot mesh")
    gears = []
    for k, z, x in ((1, z1, x1), (2, z2, x2)):
        ring = internal and k == 2
        rho_l = q[f"rho_l{k}"]
        if k == 1:
            active, root_zeta, tip_zeta = q["rho_A1"], q["zeta1_A"], q["zeta1_E"]
        else:
            active, root_zeta, tip_zeta = q["rho_E2"], q["zeta2_E"], q["zeta2_A"]
        rb = q[f"db{k}"] / 2
        gears.append(Gear(z, x, ring, q[f"d{k}"], q[f"db{k}"], q[f"dw{k}"], q[f"da{k}"], q[f"df{k}"],
                          q[f"s{k}"], q[f"sa{k}"], q[f"alpha_a{k}"], None if ring else q[f"xmin{k}"],
                          None if ring else math.hypot(rb, max(rho_l, 0.0)),
                          2 * math.hypot(rb, active) if math.isfinite(active) else math.nan,
                          root_zeta, tip_zeta))
    checks = tuple(_check(name, gear, float(margin), q, gears, m, min_tip, min_contact)
                   for (name, gear), margin in margins(q, x1, x2, m, internal, min_tip, min_contact).items())
    failed = [c.message for c in checks if not c.ok]
    return GearPair(m, rack, internal, ring_tip if internal else "standard", tuple(gears), z2 / z1, q["alpha_w"], q["inv_w"], q["a"], q["aw"], q["y"],
                    q["dy"], q["pb"], q["L"], (q["rho_A1"], q["rho_E1"]), q["rho_E1"] - q["rho_A1"], q["eps"],
                    checks, not failed, "; ".join(failed) if failed else "all checks met")


def _check(name, k, margin, q, gears, m, min_tip, min_contact) -> Check:
    ok = bool(margin >= -MARGIN_TOLERANCE)
    mm = lambda v: f"{v * 1e3:.4g} mm"                       # noqa: E731
    g = gears[k - 1] if k else None
    if name == "undercut":
        value, limit = g.shift, g.min_shift
        text = f"gear {k} (z = {g.teeth}) is undercut: x = {value:.4g} < x_min = {limit:.4g}"
    elif name == "pointed tip":
        value, limit = g.tip_thickness, min_tip * m
        text = (f"gear {k}'s tip is too thin: s_a = {mm(value)} < {min_tip:g}·m = {mm(limit)}"
                if math.isfinite(value) else f"gear {k}'s teeth are pointed below the tip circle")
    elif name == "interference":
        value = q["rho_A1"] if k == 1 else q["rho_E2"]
        limit = max(q[f"rho_l{k}"], 0.0)
        text = (f"interference: gear {3 - k}'s tip meets gear {k} at ρ = {mm(value)} from N{k}, below the "
                f"start of its involute (ρ = {mm(limit)})")
        if gears[1].internal and k == 1:
            text += " (--ring-tip cut enlarges the ring's tip circle to avoid it)"
    elif name == "ring tip":
        value, limit = g.tip_diameter / 2, g.base_diameter / 2
        text = (f"the ring's tip circle (d_a = {mm(2 * value)}) lies inside its base circle "
                f"(d_b = {mm(2 * limit)}): its teeth have no involute at the tip")
    elif name == "trochoid interference":
        value, limit = margin, 0.0
        text = (f"trochoid interference: the pinion's tip cuts the ring's teeth as it leaves the mesh "
                f"(margin {margin:.4g} rad)")
    else:
        value, limit = q["eps"], min_contact
        text = f"contact ratio ε_α = {value:.4g} < {limit:g}"
    return Check(name, k, float(value), float(limit), margin, ok, "" if ok else text)
