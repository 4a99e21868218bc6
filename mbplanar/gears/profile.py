"""The exact tooth profile a rack cutter generates: involute flank, trochoid fillet (undercut included),
root and tip circles, for the whole gear; and a self-check of the generated outline.

Generation (envelope of the tool). The gear's pitch circle (r = mz/2) rolls on the rack's pitch line,
which lies x·m below the rack's datum line. At a roll φ, a point Q of the rack with normal n touches the
gear where that normal passes through the pitch point I (Willis' law of gearing): with the gear's tooth
axis along +y and the rack above it, φ = (Q_x − (Q_y − r) n_x/n_y)/r, and the gear's point is the rack
point moved back by rφ and turned by −φ. The rack's straight flank gives the involute, the round of its
tip (radius ρ_f*·m) the fillet, its tip line the root circle. Where the straight flank would reach below
the base circle (ρ_l < 0, i.e. x < x_min) the fillet cuts into the involute: the flank is the fillet up
to their intersection (found by Newton's method on the two generating parameters), then the involute.

An internal gear (the ring of a pair) cannot be cut by a rack: its involute flanks are drawn from the
analytic involute, and its root fillet as the arc of radius ρ_f*·m tangent to the flank and the root
circle (a shaper cutter's fillet depends on the cutter's tooth count).

Self-check (`ProfileCheck`): the outline is taken as data. (1) every sample of the generated involute lies
on the analytic involute of the base circle, r·|ψ_gen − ψ_inv(r)| ≤ 1e-9·m; (2) the tooth thickness at
the pitch circle, read off the outline (quintic splines through each flank's samples, every tooth of the
whole gear), equals m(π/2 ± 2x tan α) to 1e-9·m; (3) the profile is undercut exactly when x < x_min.

    >>> from mbplanar.gears import gear_pair, gear_profile
    >>> p = gear_pair(10e-3, (12, 30), (0.3, 0.0))
    >>> prof = gear_profile(p, 1)
    >>> prof.check.success, prof.undercut, prof.outline.shape[1]
    (True, False, 2)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from .involute import arcinv, inv

__all__ = ["Piece", "ProfileCheck", "GearProfile", "gear_profile", "SAMPLES", "CHECK_TOLERANCE"]

SAMPLES = 64                # samples of the involute and of the fillet, per flank
CHECK_TOLERANCE = 1e-9      # of the module


@dataclass(frozen=True)
class Piece:
    """One piece of the outline: a smooth curve through `points` ((N, 2), m), or a circular arc about
    `centre` of `radius` from `start` to `end` (radians, counter-clockwise from +x; `points` samples it).
    `part` says what it is: "root", "fillet", "involute", "tip"."""

    kind: str
    points: np.ndarray
    part: str
    centre: tuple = (0.0, 0.0)
    radius: float = 0.0
    start: float = 0.0
    end: float = 0.0


@dataclass(frozen=True)
class ProfileCheck:
    """The generated outline against the formulas.

    Attributes
    ----------
    involute_error : largest distance (m) of a generated involute sample from the analytic involute
                     (None for an internal gear, whose involute is drawn from the formula)
    thickness_error : largest |s_measured − s_formula| (m) at the pitch circle over every tooth
    undercut_agrees : the profile is undercut exactly when the shift is below x_min
    tolerance : CHECK_TOLERANCE·m
    success : all three within the tolerance
    """

    involute_error: float | None
    thickness_error: float
    undercut_agrees: bool
    tolerance: float
    success: bool


@dataclass(frozen=True)
class GearProfile:
    """The outline of a whole gear in its own frame (centre at the origin, tooth 0's axis along +y).

    Attributes
    ----------
    teeth, module, shift, internal
    flank : (fillet (F, 2), involute (N, 2)): the right flank of tooth 0 (x ≥ 0), the fillet from the
            root circle to where the involute starts, then the involute to the tip
    undercut : the fillet cuts into the involute
    form_radius : radius where the fillet meets the involute
    tip_radius, root_radius : the circles that bound the teeth (a pointed tooth ends below its tip circle)
    pointed : the two flanks of a tooth meet below the tip circle
    outline : (K, 2) closed outline of the whole gear, counter-clockwise (an internal gear: its toothed
              inner outline)
    pieces : tuple of Piece, the outline piece by piece (for DXF)
    check : ProfileCheck

    Examples
    --------
    >>> from mbplanar.gears import gear_pair, gear_profile
    >>> prof = gear_profile(gear_pair(10e-3, (12, 30), (0.6, 0.5)), 1)
    >>> [p.part for p in prof.pieces[:5]], prof.check.success
    (['root', 'fillet', 'involute', 'tip', 'involute'], True)
    """

    teeth: int
    module: float
    shift: float
    internal: bool
    flank: tuple
    undercut: bool
    form_radius: float
    tip_radius: float
    root_radius: float
    pointed: bool
    outline: np.ndarray
    pieces: tuple
    check: ProfileCheck


def _psi(points):
    """Polar angle from +y towards +x (clockwise), and radius."""
    return np.arctan2(points[..., 0], points[..., 1]), np.hypot(points[..., 0], points[..., 1])


def _turn(points, angle):
    """Points turned counter-clockwise by `angle` about the origin."""
    c, s = math.cos(angle), math.sin(angle)
    return points @ np.array([[c, s], [-s, c]])


def _at(r, psi):
    return np.stack([r * np.sin(psi), r * np.cos(psi)], axis=-1)


class _Rack:
    """The rack's generating maps for one gear, in the gear's frame: involute(ρ) and fillet(β)."""

    def __init__(self, module, teeth, shift, rack):
        m, al = module, rack.pressure_angle
        self.r = r = m * teeth / 2
        self.al = al
        self.rb = r * math.cos(al)
        self.yd = yd = r + shift * m                          # rack datum line
        self.yt = yt = yd - rack.tooth_depth() * m            # rack tip line: the root circle
        self.rho = rho = rack.tip_radius * m
        ty = yt + rho * (1 - math.sin(al))                    # where the straight flank ends
        tx = math.pi * m / 4 + (yd - ty) * math.tan(al)
        self.centre = (tx + rho * math.cos(al), yt + rho)     # centre of the tip round
        self.yn = r * math.cos(al) ** 2                       # height of N, where the line of action
        self.rho_l = (ty - self.yn) / math.sin(al)            # touches the base circle; ρ_l < 0: undercut
        self.m = m

    def _gear_point(self, qx, qy, nx, ny):
        r = self.r
        phi = (qx - (qy - r) * nx / ny) / r
        px, py = qx - r * phi, qy
        c, s = np.cos(phi), np.sin(phi)
        return np.stack([px * c + py * s, -px * s + py * c], axis=-1)

    def involute(self, rho_line):
        """Points generated by the straight flank, ρ from N along the line of action."""
        al = self.al
        y = self.yn + np.asarray(rho_line, float) * math.sin(al)
        x = math.pi * self.m / 4 + (self.yd - y) * math.tan(al)
        return self._gear_point(x, y, math.cos(al), math.sin(al))

    def fillet(self, beta):
        """Points generated by the tip round: β from π + α (its end on the flank) to 3π/2 (on the tip line)."""
        beta = np.asarray(beta, float)
        nx, ny = np.cos(beta), np.sin(beta)
        return self._gear_point(self.centre[0] + self.rho * nx, self.centre[1] + self.rho * ny, nx, ny)


def _intersection(gen, half_pitch_angle, inv_alpha):
    """(β, ρ) where the fillet crosses the involute (an undercut profile), the first crossing along the
    fillet from the root: on the fillet's samples above the base circle, the sign change of its polar
    angle minus the involute's at the same radius, then Brent's method in β. (Near the undercut limit the
    two curves cross almost tangentially, within 1e-9 of the module: a polyline test would miss it.)"""
    from scipy.optimize import brentq

    def gap(beta):
        psi, r = _psi(gen.fillet(beta))
        alpha_r = np.arccos(np.clip(gen.rb / r, -1.0, 1.0))
        return np.where(r >= gen.rb * (1 - 1e-15), psi - (half_pitch_angle + inv_alpha - inv(alpha_r)), np.nan)

    end = math.pi + gen.al
    betas = np.linspace(1.5 * math.pi, end, 4001)
    _, r = _psi(gen.fillet(betas))
    above = np.flatnonzero(r >= gen.rb)
    if not above.size:
        return None
    k = above[0]
    start = betas[0] if k == 0 else brentq(lambda b: float(_psi(gen.fillet(b))[1]) - gen.rb, betas[k - 1],
                                           betas[k], xtol=1e-16, rtol=1e-15)
    betas = np.linspace(start, end, 4001)                    # from where the fillet crosses the base circle
    h = gap(betas)
    change = np.flatnonzero(np.isfinite(h[:-1]) & np.isfinite(h[1:]) & (np.sign(h[:-1]) != np.sign(h[1:])))
    if not change.size:
        return None
    k = change[0]
    beta = brentq(lambda b: float(gap(b)), betas[k], betas[k + 1], xtol=1e-16, rtol=1e-15)
    _, r = _psi(gen.fillet(beta))
    return float(beta), math.sqrt(max(float(r) ** 2 - gen.rb ** 2, 0.0))


def _tip_end(rb, half_pitch_angle, ra, inv_alpha):
    """ρ along the line of action where an external tooth's flank ends: at the tip circle, or where the
    two flanks meet below it (a pointed tooth: ψ(r) = half_pitch_angle + inv α − inv α_r = 0)."""
    rho_a = math.sqrt(max(ra * ra - rb * rb, 0.0))
    rho_p = rb * math.tan(float(arcinv(half_pitch_angle + inv_alpha)))
    return (rho_p, True) if rho_p < rho_a else (rho_a, False)


def _arc(radius, psi_from, psi_to, part, centre=(0.0, 0.0), points=None):
    """A circular arc piece about `centre`, from polar angle ψ_from to ψ_to (clockwise from +y about the
    gear centre when centre is the origin)."""
    n = max(3, int(abs(psi_to - psi_from) / 0.02) + 2)
    psi = np.linspace(psi_from, psi_to, n)
    pts = _at(radius, psi) if points is None else points
    theta_from, theta_to = math.pi / 2 - psi_from, math.pi / 2 - psi_to
    return Piece("arc", pts, part, centre, radius, theta_from, theta_to)


def gear_profile(pair, gear: int, samples: int = SAMPLES) -> GearProfile:
    """The whole outline of gear `gear` (1 or 2) of `pair`, as the rack generates it (a ring: drawn).

    Parameters
    ----------
    pair : GearPair
        from `gear_pair` (its rack, module, tooth number, shift and tip diameter are used).
    gear : int
        1 or 2.
    samples : int
        samples of the involute and of the fillet on each flank (≥ 8).

    Returns
    -------
    GearProfile

    Raises
    ------
    ModelError
        a tooth without an involute between its form circle and its tip.

    Examples
    --------
    >>> from mbplanar.gears import gear_pair, gear_profile
    >>> prof = gear_profile(gear_pair(10e-3, (8, 30), (0.0, 0.0)), 1)   # 8 teeth, no shift: undercut
    >>> prof.undercut, prof.check.undercut_agrees, prof.check.success
    (True, True, True)
    """
    if gear not in (1, 2):
        raise ModelError(f"gear must be 1 or 2, got {gear!r}")
    if samples < 8:
        raise ModelError(f"samples must be at least 8, got {samples}")
    g, rack, m = pair.gears[gear - 1], pair.rack, pair.module
    if g.internal:
        return _ring_profile(g, rack, m, samples)
    return _external_profile(g, rack, m, samples)


def _external_profile(g, rack, m, samples):
    z, x = g.teeth, g.shift
    gen = _Rack(m, z, x, rack)
    ra, rb, rp = g.tip_diameter / 2, gen.rb, gen.r
    half = g.pitch_thickness / (2 * rp)                       # half-angle of the tooth at the pitch circle
    rho_end, pointed = _tip_end(rb, half, ra, inv(rack.pressure_angle))
    undercut = gen.rho_l < 0
    beta_end, rho_start = math.pi + gen.al, gen.rho_l
    if undercut:
        hit = _intersection(gen, half, inv(rack.pressure_angle))
        if hit is None:
            raise ModelError(f"gear with z = {z}, x = {x:g}: the fillet never meets the involute")
        beta_end, rho_start = hit
    if rho_end <= rho_start:
        raise ModelError(f"gear with z = {z}, x = {x:g}: no involute between its form circle "
                         f"(r = {math.hypot(rb, rho_start) * 1e3:.6g} mm) and its tip")
    fillet = gen.fillet(np.linspace(1.5 * math.pi, beta_end, samples))
    involute = gen.involute(np.linspace(rho_start, rho_end, samples))
    tip_r = math.hypot(rb, rho_end)
    pieces = _assemble(z, fillet, involute, gen.yt, pointed)
    check = _check_external(g, rack, m, pieces, gen, undercut, rp)
    return GearProfile(z, m, x, False, (fillet, involute), undercut, math.hypot(rb, rho_start), tip_r, gen.yt,
                       pointed, _outline(pieces), tuple(pieces), check)


def _assemble(z, fillet, involute, root_r, pointed):
    """The pieces of the whole outline, tooth after tooth, counter-clockwise (decreasing ψ)."""
    pitch = 2 * math.pi / z
    pieces = []
    psi_root, _ = _psi(fillet[0])
    psi_tip, tip_r = _psi(involute[-1])
    for k in range(z):
        turn = k * pitch                                      # tooth k's axis at ψ = −turn
        rot = lambda p, t=turn: _turn_psi(p, -t)              # noqa: E731
        pieces.append(_arc(root_r, pitch / 2 - turn, psi_root - turn, "root"))
        pieces.append(Piece("curve", rot(fillet), "fillet"))
        pieces.append(Piece("curve", rot(involute), "involute"))
        if not pointed:
            pieces.append(_arc(tip_r, psi_tip - turn, -psi_tip - turn, "tip"))
        mirrored = lambda p: p * np.array([-1.0, 1.0])        # noqa: E731
        pieces.append(Piece("curve", rot(mirrored(involute)[::-1]), "involute"))
        pieces.append(Piece("curve", rot(mirrored(fillet)[::-1]), "fillet"))
        pieces.append(_arc(root_r, -psi_root - turn, -pitch / 2 - turn, "root"))
    return pieces


def _turn_psi(points, dpsi):
    """Points turned by dψ (ψ clockwise from +y): counter-clockwise by −dψ."""
    return _turn(points, -dpsi)


def _outline(pieces):
    pts = [pieces[0].points]
    for p in pieces[1:]:
        pts.append(p.points[1:])
    out = np.vstack(pts)
    return out[:-1] if np.allclose(out[0], out[-1]) else out


def _flanks_of_each_tooth(pieces, z):
    """The (right, left) involute samples of every tooth, read off the outline's pieces and turned back
    into that tooth's own frame (its axis along +y)."""
    inv_pieces = [p.points for p in pieces if p.part == "involute"]
    pitch = 2 * math.pi / z
    return [(_turn_psi(inv_pieces[2 * k], k * pitch), _turn_psi(inv_pieces[2 * k + 1], k * pitch))
            for k in range(z)]


def _thickness_error(pieces, z, thickness_at, r_lo, r_hi, rp, rb):
    """Largest |thickness read off the outline − formula| over every tooth, at the pitch circle (or, if the
    involute does not reach it, at the middle of the involute): the polar angle of each flank's samples
    as a quintic spline in √(r² − r_b²) (in which an involute is smooth down to its base circle)."""
    from scipy.interpolate import make_interp_spline
    r_at = rp if r_lo < rp < r_hi else 0.5 * (r_lo + r_hi)
    worst = 0.0
    for right, left in _flanks_of_each_tooth(pieces, z):
        psi = []
        for pts in (right, left):
            a, r = _psi(pts)
            rho = np.sqrt(np.maximum(r * r - rb * rb, 0.0))
            order = np.argsort(rho)
            spline = make_interp_spline(rho[order], np.unwrap(a[order]), k=5)
            psi.append(float(spline(math.sqrt(r_at ** 2 - rb ** 2))))
        worst = max(worst, abs(r_at * (psi[0] - psi[1]) - thickness_at(r_at)))
    return worst


def _check_external(g, rack, m, pieces, gen, undercut, rp):
    al = rack.pressure_angle

    def half_angle(r):
        return g.pitch_thickness / (2 * rp) + inv(al) - inv(np.arccos(np.clip(gen.rb / r, -1, 1)))

    inv_err = 0.0
    for right, left in _flanks_of_each_tooth(pieces, g.teeth):
        for pts, sign in ((right, 1.0), (left, -1.0)):
            psi, r = _psi(pts)
            inv_err = max(inv_err, float(np.max(r * np.abs(psi - sign * half_angle(r)))))
    _, r_inv = _psi(pieces[2].points)
    err = _thickness_error(pieces, g.teeth, lambda r: 2 * r * half_angle(r), r_inv.min(), r_inv.max(), rp, gen.rb)
    agrees = undercut == (g.shift < g.min_shift)
    tol = CHECK_TOLERANCE * m
    return ProfileCheck(inv_err, err, bool(agrees), tol, bool(inv_err <= tol and err <= tol and agrees))


def _ring_profile(g, rack, m, samples):
    """The ring's outline: exact involute flanks from the tip circle outwards, an arc fillet of radius
    ρ_f*·m tangent to the flank and the root circle."""
    from scipy.optimize import brentq
    z, x = g.teeth, g.shift
    al = rack.pressure_angle
    rp, rb = m * z / 2, m * z * math.cos(al) / 2
    ra, rf = g.tip_diameter / 2, g.root_diameter / 2
    half = g.pitch_thickness / (2 * rp)                       # half-angle of the ring's tooth at the pitch
    if ra < rb:
        raise ModelError(f"ring with z = {z}, x = {x:g}: its tip circle lies inside its base circle")
    rho_tip = math.sqrt(ra * ra - rb * rb)
    rho_root = math.sqrt(rf * rf - rb * rb)

    def flank(rho):
        rho = np.asarray(rho, float)
        r = np.hypot(rb, rho)
        psi = half - inv(al) + inv(np.arctan2(rho, rb))
        return _at(r, psi)

    rho_t = rack.tip_radius * m

    def centre(rho):
        h = 1e-7 * m
        p = flank(rho)
        t = (flank(rho + h) - flank(rho - h)) / (2 * h)
        n = np.array([t[1], -t[0]]) / np.hypot(*t)
        psi = math.atan2(p[0], p[1])
        if n @ np.array([math.cos(psi), -math.sin(psi)]) < 0:   # towards the space (larger ψ)
            n = -n
        return p + rho_t * n

    def gap(rho):
        return np.hypot(*centre(rho)) - (rf - rho_t)

    if rho_t > 0 and gap(rho_tip) < 0 < gap(rho_root):
        rho_f = brentq(gap, rho_tip, rho_root, xtol=1e-15 * m)
        c = centre(rho_f)
        touch_root = c / np.hypot(*c) * rf
        p_f = flank(rho_f)
        a0 = math.atan2(p_f[1] - c[1], p_f[0] - c[0])
        a1 = math.atan2(touch_root[1] - c[1], touch_root[0] - c[0])
        sweep = (a1 - a0 + math.pi) % (2 * math.pi) - math.pi
        angles = a0 + np.linspace(0.0, sweep, max(8, samples // 4))
        fillet = np.stack([c[0] + rho_t * np.cos(angles), c[1] + rho_t * np.sin(angles)], -1)[::-1]
    else:
        rho_f = rho_root
        fillet = flank(np.array([rho_root, rho_root]))
        c, a0, a1 = (0.0, 0.0), 0.0, 0.0
    involute = flank(np.linspace(rho_f, rho_tip, samples))   # from the fillet inwards to the tip
    pieces = []
    pitch = 2 * math.pi / z
    psi_root, _ = _psi(fillet[0])
    psi_tip, _ = _psi(involute[-1])
    for k in range(z):
        turn = k * pitch
        rot = lambda p, t=turn: _turn_psi(p, -t)              # noqa: E731
        mirrored = lambda p: p * np.array([-1.0, 1.0])        # noqa: E731
        # ψ decreases counter-clockwise; the ring's tooth is centred on ψ = 0, its spaces at ±π/z
        pieces.append(_arc(rf, pitch / 2 - turn, psi_root - turn, "root"))
        pieces.append(Piece("curve", rot(fillet), "fillet"))
        pieces.append(Piece("curve", rot(involute), "involute"))
        pieces.append(_arc(ra, psi_tip - turn, -psi_tip - turn, "tip"))
        pieces.append(Piece("curve", rot(mirrored(involute)[::-1]), "involute"))
        pieces.append(Piece("curve", rot(mirrored(fillet)[::-1]), "fillet"))
        pieces.append(_arc(rf, -psi_root - turn, -pitch / 2 - turn, "root"))
    def thickness_at(r):
        return 2 * r * (half - inv(al) + inv(math.acos(rb / r)))

    err = _thickness_error(pieces, z, thickness_at, ra, math.hypot(rb, rho_f), rp, rb)
    tol = CHECK_TOLERANCE * m
    check = ProfileCheck(None, err, True, tol, bool(err <= tol))
    return GearProfile(z, m, x, True, (fillet, involute), False, float(np.hypot(rb, rho_f)), ra, rf, False,
                       _outline(pieces), tuple(pieces), check)
