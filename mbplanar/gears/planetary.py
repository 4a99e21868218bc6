"""Planetary (2K-H) trains by tooth numbers: the course books' schemes, every admissible set of tooth
numbers for a ratio, ranked by overall size; Willis' formula; the train's velocities.

Schemes (gear 1 the central gear on the input or output shaft, the planet a block of one row (A) or two
rows z₂, z₃ turning on the carrier H, the last central gear fixed to the frame; one module for the train,
no profile shift):

======  =====================================================  ========================  =====================
scheme  meshes                                                 ratio                     coaxiality
======  =====================================================  ========================  =====================
A       sun 1 – planet 2 (external), planet 2 – ring 3 (int.)  u_1H = 1 + z₃/z₁          z₃ = z₁ + 2z₂
B       sun 1 – planet 2 (ext.), planet 3 – ring 4 (int.)      u_1H = 1 + z₂z₄/(z₁z₃)    z₁ + z₂ = z₄ − z₃
C       sun 1 – planet 2 (ext.), planet 3 – gear 4 (ext.)      u_H1 = 1/(1 − z₂z₄/(z₁z₃))  z₁ + z₂ = z₃ + z₄
D       ring 1 – planet 2 (int.), planet 3 – ring 4 (int.)     u_H1 = 1/(1 − z₂z₄/(z₁z₃))  z₁ − z₂ = z₄ − z₃
======  =====================================================  ========================  =====================

The ratio asked for is input speed over output speed: schemes A and B are driven by gear 1 and give
out on the carrier (u_1H), schemes C and D are driven by the carrier and give out on gear 1 (u_H1, large).
Willis' formula: with the carrier held, gear 1 turns u^H_14 = ∓z₂z₄/(z₁z₃) times as fast as gear 4
(− for one external mesh, + for none or two), and u_1H = 1 − u^H_14.

Conditions (each counted in `PlanetarySearch.rejected`):

- ratio: |u − R| ≤ tolerance·|R|;
- coaxiality: the table's equation (both meshes share the carrier's centre distance);
- assembly of k equally spaced planets: u_1H z₁ z₃ / (k · gcd(z₂, z₃)) is a whole number (single row:
  (z₁ + z₃)/k; turning the carrier by 2π/k must turn gear 1 by a whole number of the angular steps that
  an identical planet block can be fitted at);
- neighbourhood: 2a_w sin(π/k) > d_a of the planet's larger row (SDP/SI eq. 13-9);
- no undercut: every external gear has z ≥ `min_teeth` (by default the smallest z without undercut at
  x = 0, 18 for the standard rack);
- every mesh meets the checks of `gear_pair` at x = 0 (contact ratio ≥ 1.2, no interference; internal
  meshes with the ring's tip cut back where the standard one would meet the planet below its involute
  (`gear_pair(..., ring_tip="cut")`), its tip outside its base circle, no trochoid interference).

    >>> from mbplanar.gears import planetary_trains
    >>> s = planetary_trains(4.0, "A", planets=4, min_teeth=16, tolerance=0.0, max_teeth=60)
    >>> [t.teeth for t in s.trains][:3]
    [(16, 16, 48), (17, 17, 51), (18, 18, 54)]
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from .pair import MARGIN_TOLERANCE, MIN_CONTACT, MIN_TIP, margins, mesh, validate_module
from .rack import Rack

__all__ = ["Scheme", "SCHEMES", "Train", "PlanetarySearch", "planetary_trains", "willis", "train_speeds"]


@dataclass(frozen=True)
class Scheme:
    """A 2K-H scheme: its meshes ("external"/"internal" for gear 1 – planet row 2, planet row 3 – gear 4),
    whether the planet has two rows, which shaft is driven."""

    name: str
    title: str
    first: str                  # mesh of gear 1 with the planet's row 2
    second: str                 # mesh of the planet's row 3 with the fixed gear 4
    two_rows: bool
    driven_by_carrier: bool

    @property
    def sign(self) -> int:
        """The sign of u^H_14: −1 with exactly one external mesh."""
        return -1 if (self.first == "external") != (self.second == "external") else 1


SCHEMES = {
    "A": Scheme("A", "single row: sun, planets, ring (fixed); sun in, carrier out", "external", "internal",
                False, False),
    "B": Scheme("B", "two rows: sun – planet, planet – ring (fixed); sun in, carrier out", "external", "internal",
                True, False),
    "C": Scheme("C", "two rows, two external meshes: sun – planet, planet – gear (fixed); carrier in, sun out",
                "external", "external", True, True),
    "D": Scheme("D", "two rows, two internal meshes: ring – planet, planet – ring (fixed); carrier in, ring out",
                "internal", "internal", True, True),
}


@dataclass(frozen=True)
class Train:
    """One admissible set of tooth numbers.

    Attributes
    ----------
    scheme : the scheme's letter
    teeth : (z₁, z₂, z₃) for A, (z₁, z₂, z₃, z₄) otherwise (z₂, z₃ the planet's rows; gear 4 fixed)
    planets : k
    ratio : input speed / output speed
    error : (ratio − asked)/asked
    willis : u^H_14 (A: u^H_13), gear 1 relative to the fixed gear with the carrier held
    module : m (m)
    centre_distance : a_w of the planets' axes (m)
    diameter : overall diameter (m): the largest circle any gear reaches (a ring: its root circle)
    neighbour_gap : 2a_w sin(π/k) − d_a of the planet's larger row (m), > 0

    Examples
    --------
    >>> from mbplanar.gears import planetary_trains
    >>> t = planetary_trains(7.0, "A", planets=3).trains[0]
    >>> t.teeth, round(t.ratio, 6), round(1 - t.willis, 6)
    ((18, 45, 108), 7.0, 7.0)
    """

    scheme: str
    teeth: tuple
    planets: int
    ratio: float
    error: float
    willis: float
    module: float
    centre_distance: float
    diameter: float
    neighbour_gap: float


@dataclass(frozen=True)
class PlanetarySearch:
    """The admissible trains for a ratio, best (smallest) first.

    Attributes
    ----------
    target : the ratio asked for
    schemes : the schemes searched
    planets : k
    tolerance : relative
    teeth_range : (min_teeth, max_teeth)
    trains : tuple of Train, ranked by overall diameter, then by ratio error, then by the teeth's sum
    rejected : dict condition → how many sets with the ratio within tolerance it rejected (a set is
               counted under the first condition it fails)
    success : at least one train
    message

    Examples
    --------
    >>> from mbplanar.gears import planetary_trains
    >>> s = planetary_trains(4.0, "A", planets=3, tolerance=0.0, max_teeth=60)
    >>> [t.teeth for t in s.trains], s.rejected["assembly"]
    ([(18, 18, 54)], 2)
    """

    target: float
    schemes: tuple
    planets: int
    tolerance: float
    teeth_range: tuple
    trains: tuple
    rejected: dict
    success: bool
    message: str


def willis(scheme: str, teeth) -> float:
    """Willis's ratio u^H_14 of a 2K-H scheme: gear 1's speed over gear 4's, both relative to the carrier.

    u^H_14 = ± z₂·z₄/(z₁·z₃), negative where the two meshes turn the speed once (one external, one
    internal mesh); for a single-row scheme (A) z₂ = z₃ is the planet and u^H_13 = −z₃/z₁. With gear 4
    fixed, the carrier drive gives 1 − u^H_14.

    Parameters
    ----------
    scheme : {"A", "B", "C", "D"}
        The scheme (`SCHEMES`).
    teeth : sequence of int
        (z₁, z₂, z₄) for a single-row scheme, (z₁, z₂, z₃, z₄) for two rows.

    Returns
    -------
    float
        u^H_14.

    Raises
    ------
    KeyError
        An unknown scheme.
    IndexError
        Fewer tooth numbers than the scheme has gears.

    Examples
    --------
    >>> from mbplanar.gears import willis
    >>> willis("A", (16, 16, 48)), 1 - willis("A", (16, 16, 48))        # sun to carrier: 1 + z3/z1
    (-3.0, 4.0)
    >>> willis("B", (20, 40, 20, 80))                                   # −(40·80)/(20·20)
    -8.0
    """
    sch = SCHEMES[scheme]
    z = [float(v) for v in teeth]
    z1, z2, z3, z4 = (z[0], z[1], z[1], z[2]) if not sch.two_rows else z
    return sch.sign * z2 * z4 / (z1 * z3)


def _ratio(sch, u1h):
    """Input over output speed for the scheme's drive."""
    with np.errstate(divide="ignore"):
        return 1.0 / u1h if sch.driven_by_carrier else u1h


def _coaxial_sets(sch, lo, hi):
    """Chunks (z₁, z₂, z₃, z₄) of every set of tooth numbers in [lo, hi] meeting coaxiality (single row:
    z₃ = z₂), one chunk per z₁."""
    zs = np.arange(lo, hi + 1)
    for z1 in zs:
        if not sch.two_rows:
            z2 = zs
            z3 = z2
            z4 = z1 + 2 * z2
        else:
            z2, z3 = (a.ravel() for a in np.meshgrid(zs, zs))
            if sch.name == "B":
                z4 = z1 + z2 + z3
            elif sch.name == "C":
                z4 = z1 + z2 - z3
            else:
                z4 = z1 - z2 + z3
        z1v = np.full_like(z2, z1)
        keep = (z4 >= lo) & (z4 <= hi)
        if sch.name == "D":
            keep &= (z1v > z2) & (z4 > z3)
        yield z1v[keep], z2[keep], z3[keep], z4[keep]


def _mesh_ok(module, za, zb, kind, rack, min_tip, min_contact):
    """The checks of the meshes (za, zb) at x = 0 (internal: zb the ring, its tip cut back where needed),
    undercut aside (the teeth's lower limit sees to it)."""
    internal = kind == "internal"
    q = mesh(module, za, zb, 0.0, 0.0, rack, internal, "cut")
    ok = np.ones(np.shape(za), bool)
    for (name, _), v in margins(q, 0.0, 0.0, module, internal, min_tip, min_contact).items():
        if name != "undercut":
            ok &= np.broadcast_to(v, ok.shape) >= -MARGIN_TOLERANCE
    return ok


def _undercut_limit(rack):
    """The smallest tooth number without undercut at x = 0."""
    return math.ceil(2 * rack.flank_end / math.sin(rack.pressure_angle) ** 2 - 1e-9)


def planetary_trains(ratio: float, scheme: str | None = None, *, planets: int = 3, tolerance: float = 0.01,
                     module: float = 1e-3, min_teeth: int | None = None, max_teeth: int = 150,
                     rack: Rack | None = None, min_contact: float = MIN_CONTACT, limit: int | None = None
                     ) -> PlanetarySearch:
    """Every set of tooth numbers of a 2K-H train giving `ratio` within `tolerance`, meeting coaxiality,
    assembly of `planets` equally spaced planets, neighbourhood, no undercut and the meshes' checks,
    ranked by overall diameter.

    Parameters
    ----------
    ratio : float
        input speed / output speed (see the module's table for each scheme's drive).
    scheme : {"A", "B", "C", "D"}, optional
        one scheme, or None for all four.
    planets : int
        k ≥ 1.
    tolerance : float
        relative, ≥ 0.
    module : float
        m (m), for the sizes.
    min_teeth : int, optional
        the smallest tooth number of an external gear (default: the smallest without undercut, 18 for the
        standard rack; a smaller value allows undercut gears).
    max_teeth : int
        the largest tooth number of any gear (the rings included).
    rack : Rack, optional
    min_contact : float
        the meshes' smallest contact ratio.
    limit : int, optional
        keep only the best `limit` trains.

    Returns
    -------
    PlanetarySearch

    Raises
    ------
    ModelError
        a ratio of 0 or not finite, or one that no coaxial set of tooth numbers of the schemes searched
        reaches within the tolerance (the message gives the nearest ratio they reach); bad k, tolerance,
        module or teeth range.

    Examples
    --------
    >>> from mbplanar.gears import planetary_trains
    >>> s = planetary_trains(7.0, "A", planets=3)
    >>> t = s.trains[0]
    >>> t.teeth, round(t.ratio, 6), round(t.diameter * 1e3, 3)
    ((18, 45, 108), 7.0, 110.5)
    """
    rack = Rack() if rack is None else rack
    m = validate_module(module, "--module")
    if not (isinstance(ratio, (int, float)) and math.isfinite(ratio)) or ratio == 0:
        raise ModelError(f"--ratio must be a finite number other than 0, got {ratio!r}")
    if isinstance(planets, bool) or not isinstance(planets, (int, np.integer)) or planets < 1:
        raise ModelError(f"--planets must be a whole number ≥ 1, got {planets!r}")
    if not (math.isfinite(tolerance) and tolerance >= 0):
        raise ModelError(f"--tolerance must be ≥ 0, got {tolerance!r}")
    z_under = _undercut_limit(rack)
    lo = z_under if min_teeth is None else min_teeth
    if isinstance(lo, bool) or not isinstance(lo, (int, np.integer)) or lo < 1:
        raise ModelError(f"--min-teeth must be a whole number ≥ 1, got {min_teeth!r}")
    if isinstance(max_teeth, bool) or not isinstance(max_teeth, (int, np.integer)) or max_teeth < lo:
        raise ModelError(f"--max-teeth must be a whole number ≥ --min-teeth ({lo}), got {max_teeth!r}")
    if max_teeth > 400:
        raise ModelError(f"--max-teeth {max_teeth} is beyond the search's 400")
    names = tuple(SCHEMES) if scheme is None else (scheme,)
    for name in names:
        if name not in SCHEMES:
            raise ModelError(f"--scheme: unknown scheme {name!r} (one of {', '.join(SCHEMES)})")
    trains, rejected = [], {c: 0 for c in ("assembly", "neighbourhood", "undercut", "meshes")}
    nearest = (math.inf, None, None)                          # (|ratio − target|, scheme, ratio)
    for name in names:
        near = _search(SCHEMES[name], ratio, planets, tolerance, m, lo, max_teeth, rack, min_contact, trains,
                       rejected)
        if near[0] < nearest[0]:
            nearest = near
    if nearest[0] > tolerance * abs(ratio) * (1 + 1e-12):
        near = (f"; the nearest is {nearest[2]:.6g} (scheme {nearest[1]})" if nearest[1] else "")
        raise ModelError(f"--ratio {ratio:g}: no scheme reaches it within ±{tolerance:g} with {lo} ≤ z ≤ "
                         f"{max_teeth} (schemes {', '.join(names)}){near}")
    trains.sort(key=lambda t: (round(t.diameter / m, 9), abs(t.error), sum(t.teeth)))
    if limit is not None:
        trains = trains[:limit]
    k = planets
    if trains:
        message = f"{len(trains)} train(s) within ±{tolerance:g} of {ratio:g} with k = {k}"
    else:
        why = ", ".join(f"{c} {n}" for c, n in rejected.items() if n)
        message = (f"no set of tooth numbers gives {ratio:g} within ±{tolerance:g} with k = {k} planets and "
                   f"{lo} ≤ z ≤ {max_teeth}" + (f" (rejected by: {why})" if why else ""))
    return PlanetarySearch(float(ratio), names, k, float(tolerance), (lo, max_teeth), tuple(trains), rejected,
                           bool(trains), message)


def _search(sch, target, k, tol, m, lo, hi, rack, min_contact, out, rejected):
    """Append the scheme's admissible trains to `out`, count the rejections; return the nearest ratio any
    coaxial set reaches, as (|ratio − target|, scheme, ratio)."""
    ha = rack.addendum
    nearest = (math.inf, None, None)
    for z1, z2, z3, z4 in _coaxial_sets(sch, lo, hi):
        if not z1.size:
            continue
        u14 = sch.sign * z2 * z4 / (z1 * z3)
        u1h = 1 - u14
        r = _ratio(sch, u1h)
        dist = np.where(np.isfinite(r), np.abs(r - target), np.inf)
        j = int(np.argmin(dist))
        if dist[j] < nearest[0]:
            nearest = (float(dist[j]), sch.name, float(r[j]))
        within = dist <= tol * abs(target) * (1 + 1e-12)
        if not within.any():
            continue
        z1, z2, z3, z4, u1h, r, u14 = (a[within] for a in (z1, z2, z3, z4, u1h, r, u14))
        g = np.gcd(z2, z3)
        numerator = np.rint(u1h * z1 * z3).astype(np.int64)          # z₁z₃ ∓ z₂z₄, a whole number
        fail = {"assembly": numerator % (k * g) != 0}
        aw = z1 + z2 if sch.first == "external" else z1 - z2             # in modules (x = 0)
        fail["neighbourhood"] = ~(aw * math.sin(math.pi / k) > np.maximum(z2, z3) + 2 * ha) if k > 1 \
            else np.zeros(z1.shape, bool)
        external = [z2, z3] + ([z1] if sch.first == "external" else []) + ([z4] if sch.second == "external" else [])
        under = np.zeros(z1.shape, bool)
        for z in external:
            under |= z < lo
        fail["undercut"] = under
        ok1 = _mesh_ok(m, z1, z2, "external", rack, MIN_TIP, min_contact) if sch.first == "external" \
            else _mesh_ok(m, z2, z1, "internal", rack, MIN_TIP, min_contact)
        ok2 = _mesh_ok(m, z3, z4, sch.second, rack, MIN_TIP, min_contact)
        fail["meshes"] = ~(ok1 & ok2)
        bad = np.zeros(z1.shape, bool)
        for name in ("assembly", "neighbourhood", "undercut", "meshes"):
            rejected[name] += int(np.sum(fail[name] & ~bad))
            bad |= fail[name]
        for i in np.flatnonzero(~bad):
            teeth = (int(z1[i]), int(z2[i]), int(z4[i])) if not sch.two_rows else \
                (int(z1[i]), int(z2[i]), int(z3[i]), int(z4[i]))
            out.append(_train(sch, teeth, k, float(r[i]), target, float(u14[i]), m, rack))
    return nearest


def _train(sch, teeth, k, ratio, target, u14, m, rack):
    z1, z2, z3, z4 = (teeth[0], teeth[1], teeth[1], teeth[2]) if not sch.two_rows else teeth
    ha, c = rack.addendum, rack.clearance
    aw = m * ((z1 + z2) if sch.first == "external" else (z1 - z2)) / 2
    tip_planet = m * (max(z2, z3) + 2 * ha)
    reach = [aw + m * (z2 + 2 * ha) / 2, aw + m * (z3 + 2 * ha) / 2]
    for z, kind in ((z1, sch.first), (z4, sch.second)):
        reach.append(m * (z / 2 + ha + c) if kind == "internal" else m * (z / 2 + ha))
    gap = 2 * aw * math.sin(math.pi / k) - tip_planet if k > 1 else math.inf
    return Train(sch.name, teeth, k, ratio, (ratio - target) / target, u14, m, aw, 2 * max(reach), gap)


def train_speeds(train: Train, omega_in: float = 1.0) -> dict:
    """Angular velocities (rad/s) of gear 1, the planet, the carrier and the fixed gear for an input
    speed `omega_in`, from Willis' formula: ω₁ − ω_H = u^H_14 (ω₄ − ω_H) with ω₄ = 0, and the planet from
    its mesh with gear 1 relative to the carrier.

    Examples
    --------
    >>> from mbplanar.gears.planetary import Train, train_speeds
    >>> t = Train("A", (16, 16, 48), 4, 4.0, 0.0, -3.0, 1e-3, 16e-3, 50.5e-3, 1.0)
    >>> {k: round(v, 12) for k, v in train_speeds(t).items()}
    {'gear 1': 1.0, 'planet': -0.5, 'carrier': 0.25, 'fixed': 0.0}
    """
    sch = SCHEMES[train.scheme]
    u1h = 1 - train.willis
    if sch.driven_by_carrier:
        wh, w1 = omega_in, omega_in * u1h
    else:
        w1, wh = omega_in, omega_in / u1h
    z1, z2 = train.teeth[0], train.teeth[1]
    # gear 1 – planet relative to the carrier: z₁(ω₁ − ω_H) = ∓ z₂(ω₂ − ω_H)
    sign = -1.0 if sch.first == "external" else 1.0
    w2 = wh + sign * z1 * (w1 - wh) / z2
    return {"gear 1": w1, "planet": w2, "carrier": wh, "fixed": 0.0}
