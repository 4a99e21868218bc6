"""The involute function, its inverse and the spur pair: published worked examples (each value cited),
ISO 21771's formulas written out independently here, and properties against an independent evaluation
of the involute function (40-digit decimal arithmetic for the function itself; long double, numpy's 80-bit
float, with a bisection of its own for the pair's geometry)."""

from __future__ import annotations

import decimal
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mbplanar.errors import ModelError
from mbplanar.gears import Rack, arcinv, gear_pair, inv
from mbplanar.gears.pair import mesh, shift_sum_for

LD = np.longdouble
ALPHA = math.radians(20.0)


def inv_ld(a):
    """tan α − α in long double (64-bit mantissa): the reference evaluation, independent of `inv`."""
    a = LD(a)
    return np.tan(a) - a


def arcinv_ld(v):
    """α with tan α − α = v by 200 bisections in long double (independent of `arcinv`'s Newton)."""
    lo, hi = LD(0), LD(math.pi) / 2 - LD(1e-12)
    v = LD(v)
    for _ in range(200):
        mid = (lo + hi) / 2
        if np.tan(mid) - mid < v:
            lo = mid
        else:
            hi = mid
    return (lo + hi) / 2


def _tan_minus(a: decimal.Decimal) -> decimal.Decimal:
    """tan a − a to 40 digits, from the Taylor series of sin and cos in decimal arithmetic (precision set
    by the caller's context)."""
    sin = cos = decimal.Decimal(0)
    term, n = decimal.Decimal(1), 0                           # a^n / n!
    while abs(term) > decimal.Decimal(10) ** -60:
        if n % 4 == 0:
            cos += term
        elif n % 4 == 1:
            sin += term
        elif n % 4 == 2:
            cos -= term
        else:
            sin -= term
        n += 1
        term = term * a / n
    return sin / cos - a


def inv_exact(alpha: float) -> float:
    """The involute function of a float angle, correctly rounded (from 40 digits)."""
    with decimal.localcontext() as ctx:
        ctx.prec = 45
        return float(_tan_minus(decimal.Decimal(alpha)))


def arcinv_exact(v: float) -> float:
    """The root of tan α − α = v (a float v) to 40 digits: a bisection in long double to start, then
    Newton's method (slope tan²α) in decimal arithmetic; rounded to a float."""
    with decimal.localcontext() as ctx:
        ctx.prec = 45
        target, x = decimal.Decimal(v), decimal.Decimal(float(arcinv_ld(v)))
        for _ in range(5):
            t = _tan_minus(x) + x
            x -= (t - x - target) / (t * t)
        return float(x)


def near(value, printed, digits):
    """Equal to a printed value to half a unit of its last digit (`digits` decimals)."""
    return abs(value - printed) <= 0.5 * 10.0 ** -digits + 1e-12


# -- the involute function ----------------------------------------------------------------------------
@settings(max_examples=200, deadline=None)
@given(st.floats(1e-5, 1.5))
def test_inv_equals_a_40_digit_evaluation(alpha):
    """Within 4 units of the last place of the correctly rounded value."""
    ref = inv_exact(alpha)
    assert abs(inv(alpha) - ref) <= 4 * np.spacing(ref)


@settings(max_examples=200, deadline=None)
@given(st.floats(1e-12, 100.0))
def test_arcinv_solves_inv_alpha_to_1e_14(v):
    """The inverse solved to 1e-14 (relative) against the 40-digit root."""
    alpha = arcinv(v)
    ref = arcinv_exact(v)
    assert abs(alpha - ref) <= 1e-14 * ref


def test_arcinv_edges_and_arrays():
    assert arcinv(0.0) == 0.0
    assert math.isnan(arcinv(-1e-3)) and math.isnan(arcinv(float("nan")))
    v = np.array([[1e-8, 0.0149043838673], [0.5, 10.0]])
    a = arcinv(v)
    assert a.shape == (2, 2) and np.allclose(inv(a), v, rtol=1e-14, atol=0)
    assert abs(inv(ALPHA) - 0.014904383867336) < 1e-15     # inv 20°, any table of the involute function


# -- published worked examples -------------------------------------------------------------------------
def test_khk_profile_shifted_pair():
    """KHK's worked example of a profile-shifted spur pair, as tabulated in "Profile Shifted External Spur
    Gears", http://bolsover.com/utilitiesforalibre/profile-shifted-external-spur-gears.html: m = 3 mm,
    α = 20°, z = 12, 24, x = 0.6, 0.36, working centre distance 56.500 mm: inv α = 0.014904,
    inv α_w = 0.034317, α_w = 26.0888°, y = 0.83333, d = 36.000, 72.000, d_b = 33.8289, 67.6579,
    d_w = 37.667, 75.333, h_a = 4.420, 3.700, h_f = 1.950, 2.670, h = 6.370, d_a = 44.840, 79.400,
    d_f = 32.100, 66.660, ε_α = 1.202. (The page's α_w and y follow from its a_w = 56.5 mm; the shifts
    0.6 + 0.36 give a_w = 56.4999 mm, which the rounded diameters do not see.)"""
    m = 3e-3
    p = gear_pair(m, (12, 24), (0.6, 0.36))
    assert near(inv(ALPHA), 0.014904, 6)
    g1, g2 = p.gears
    for value, printed, digits in ((g1.pitch_diameter, 36.000, 3), (g2.pitch_diameter, 72.000, 3),
                                   (g1.base_diameter, 33.8289, 4), (g2.base_diameter, 67.6579, 4),
                                   (g1.working_diameter, 37.667, 3), (g2.working_diameter, 75.333, 3),
                                   ((g1.tip_diameter - g1.pitch_diameter) / 2, 4.420, 3),
                                   ((g2.tip_diameter - g2.pitch_diameter) / 2, 3.700, 3),
                                   ((g1.pitch_diameter - g1.root_diameter) / 2, 1.950, 3),
                                   ((g2.pitch_diameter - g2.root_diameter) / 2, 2.670, 3),
                                   ((g1.tip_diameter - g1.root_diameter) / 2, 6.370, 3),
                                   (g1.tip_diameter, 44.840, 3), (g2.tip_diameter, 79.400, 3),
                                   (g1.root_diameter, 32.100, 3), (g2.root_diameter, 66.660, 3)):
        assert near(value * 1e3, printed, digits), (value * 1e3, printed)
    assert near(p.contact_ratio, 1.202, 3)
    assert p.success
    # the page's working centre distance 56.500 mm: its inv α_w, α_w and y
    rack = Rack()
    total = shift_sum_for(12, 24, 56.5e-3, m, rack)
    assert near(total, 0.960, 3)
    q = mesh(m, 12, 24, total / 2, total / 2, rack)
    assert near(float(q["inv_w"]), 0.034317, 6)
    assert near(math.degrees(float(q["alpha_w"])), 26.0888, 4)
    assert near(float(q["y"]), 0.83333, 5)
    assert abs(float(q["aw"]) - 56.5e-3) < 1e-15


@pytest.mark.parametrize("z1, x2, alpha_w, a, eps", [
    (49, 1.00, 61.0605, 0.971, 1.105), (48, 0.60, 46.0324, 1.354, 1.512), (47, 0.40, 37.4155, 1.775, 1.726),
    (46, 0.30, 32.4521, 2.227, 1.835), (45, 0.20, 28.2019, 2.666, 1.933), (44, 0.11, 24.5356, 3.099, 2.014),
    (43, 0.06, 22.3755, 3.557, 2.053), (42, 0.01, 20.3854, 4.010, 2.088)])
def test_sdp_internal_pairs_with_small_tooth_differences(z1, x2, alpha_w, a, eps):
    """SDP/SI, "Elements of Metric Gear Technology", §5.3, Table 5-4 (α = 20°, m = 1, an internal gear of
    z₂ = 50 with x₁ = 0 on the pinion; the shift listed is the internal gear's), page T-46,
    http://www.sdp-si.com/D785/HTML1/D785T043_4.html: working pressure angle, centre distance, contact
    ratio."""
    p = gear_pair(1e-3, (z1, 50), (0.0, x2), internal=True)
    assert near(p.working_pressure_angle_deg, alpha_w, 4)
    assert near(p.centre_distance * 1e3, a, 3)
    assert near(p.contact_ratio, eps, 3)
    assert p.gears[1].internal and not p.gears[0].internal


def test_sdp_chordal_thickness_example_pitch_thickness():
    """SDP/SI, "Elements of Metric Gear Technology", Table 10-1 (T-81), transcribed at
    https://fdocuments.us/document/elements-of-metric-gear-technology-i-sdpsi-governing-equations-become-simple.html:
    m = 10, α = 20°, z = 12, x = +0.3: circular tooth thickness s = 17.8918 mm; addendum h_a = 13.000
    (a gear alone: no tip shortening, which its mate of x = −0.3 at the standard centre distance keeps)."""
    p = gear_pair(10e-3, (12, 30), (0.3, -0.3))
    g = p.gears[0]
    assert near(g.pitch_thickness * 1e3, 17.8918, 4)
    assert near((g.tip_diameter - g.pitch_diameter) / 2 * 1e3, 13.000, 3)
    assert abs(p.tip_reduction) < 1e-15 and abs(p.centre_distance - p.reference_centre_distance) < 1e-15


@pytest.mark.parametrize("teeth, m, shifts, internal, inv_w, alpha_w, a_w", [
    ((17, 96), 14.0, (0.2, 0.5), True, 0.01766871, 21.1251, 557.0887),
    ((30, 78), 16.0, (0.0, 0.05), False, 0.01524139, 20.1446, 864.7972)])
def test_centre_distance_spreadsheet(teeth, m, shifts, internal, inv_w, alpha_w, a_w):
    """"Centre distance of profile shifted gear calculation" (a spreadsheet of a gear shop),
    https://scribd.com/doc/92821234/Cent-r-Dist-Nce-of-Profile-Shifted-Gear-Calc: an internal pair
    (z = 17, 96, m = 14, x = 0.2, 0.5) and an external one (z = 30, 78, m = 16, x = 0, 0.05): inv α_w,
    α_w and the centre distance as printed."""
    p = gear_pair(m * 1e-3, teeth, shifts, internal=internal)
    assert near(p.inv_working, inv_w, 8)
    assert near(p.working_pressure_angle_deg, alpha_w, 4)
    assert near(p.centre_distance * 1e3, a_w, 4)


# -- ISO 21771 written out independently -----------------------------------------------------------------
def iso_21771_spur(m, z1, z2, x1, x2, alpha, ha=1.0, c=0.25):
    """ISO 21771:2007's geometry of an external spur pair (transverse = normal), in long double, with its
    own inverse involute (bisection): inv α_w = inv α + 2 tan α (x₁+x₂)/(z₁+z₂); a = m(z₁+z₂)/2;
    a_w = a cos α / cos α_w; d = zm; d_b = d cos α; d_w = 2a_w z/(z₁+z₂); k = (a_w − a)/m − (x₁+x₂) (tip
    alteration, here to keep the clearance c·m); d_a = d + 2m(h_a + x + k); d_f = d − 2m(h_a + c − x);
    ε_α = (√(d_a1² − d_b1²) + √(d_a2² − d_b2²) − 2a_w sin α_w)/(2π m cos α); s = m(π/2 + 2x tan α);
    s_a = d_a(s/d + inv α − inv α_a)."""
    m, alpha = LD(m), LD(alpha)
    inv_w = inv_ld(alpha) + 2 * np.tan(alpha) * LD(x1 + x2) / (z1 + z2)
    aw_angle = arcinv_ld(inv_w)
    a = m * (z1 + z2) / 2
    aw = a * np.cos(alpha) / np.cos(aw_angle)
    k = (aw - a) / m - LD(x1 + x2)
    out = {"inv_w": inv_w, "alpha_w": aw_angle, "aw": aw}
    for n, z, x in ((1, z1, LD(x1)), (2, z2, LD(x2))):
        d = z * m
        out[f"d{n}"], out[f"db{n}"] = d, d * np.cos(alpha)
        out[f"dw{n}"] = 2 * aw * z / (z1 + z2)
        out[f"da{n}"] = d + 2 * m * (LD(ha) + x + k)
        out[f"df{n}"] = d - 2 * m * (LD(ha) + LD(c) - x)
        s = m * (LD(math.pi) / 2 + 2 * x * np.tan(alpha))
        aa = np.arccos(out[f"db{n}"] / out[f"da{n}"])
        out[f"s{n}"] = s
        out[f"sa{n}"] = out[f"da{n}"] * (s / d + inv_ld(alpha) - inv_ld(aa))
    out["eps"] = ((np.sqrt(out["da1"] ** 2 - out["db1"] ** 2) + np.sqrt(out["da2"] ** 2 - out["db2"] ** 2)
                   - 2 * aw * np.sin(aw_angle)) / (2 * LD(math.pi) * m * np.cos(alpha)))
    return out


@settings(max_examples=200, deadline=None)
@given(st.integers(8, 150), st.integers(8, 150), st.floats(-0.5, 1.0), st.floats(-0.5, 1.0),
       st.sampled_from([14.5, 20.0, 25.0]), st.floats(0.5, 20.0))
def test_pair_equals_iso_21771_evaluated_independently(z1, z2, x1, x2, alpha_deg, m_mm):
    """Diameters, thicknesses, α_w, a_w and ε_α against ISO 21771's formulas evaluated in long double with
    a bisection for the inverse involute: relative error ≤ 1e-13 (1e-11 for ε_α and s_a, differences of
    nearly equal terms); inv α_w solved to 1e-14."""
    alpha = math.radians(alpha_deg)
    if x1 + x2 < -0.4:
        return
    p = gear_pair(m_mm * 1e-3, (z1, z2), (x1, x2), rack=Rack(alpha))
    ref = iso_21771_spur(m_mm * 1e-3, z1, z2, x1, x2, alpha)
    assert abs((LD(p.working_pressure_angle) - ref["alpha_w"]) / ref["alpha_w"]) < 1e-14
    assert abs((inv_ld(p.working_pressure_angle) - ref["inv_w"]) / ref["inv_w"]) < 1e-14
    assert abs((LD(p.centre_distance) - ref["aw"]) / ref["aw"]) < 1e-13
    for n, g in enumerate(p.gears, 1):
        for name, key in (("pitch_diameter", "d"), ("base_diameter", "db"), ("working_diameter", "dw"),
                          ("tip_diameter", "da"), ("root_diameter", "df"), ("pitch_thickness", "s")):
            r = ref[f"{key}{n}"]
            assert abs((LD(getattr(g, name)) - r) / r) < 1e-13, (name, n)
        if ref[f"sa{n}"] > 1e-3 * p.module:
            assert abs((LD(g.tip_thickness) - ref[f"sa{n}"]) / ref[f"sa{n}"]) < 1e-11
    assert abs(LD(p.contact_ratio) - ref["eps"]) < 1e-11


# -- the checks -------------------------------------------------------------------------------------------
@settings(max_examples=100, deadline=None)
@given(st.integers(5, 40), st.floats(-0.8, 1.0))
def test_undercut_check_is_x_below_x_min(z, x):
    p = gear_pair(5e-3, (z, 60), (x, 0.0))
    check = next(c for c in p.checks if c.name == "undercut" and c.gear == 1)
    x_min = 1.0 - z * math.sin(ALPHA) ** 2 / 2               # h_a* − z sin²α/2 (h_fe* = h_a* by default)
    assert abs(p.gears[0].min_shift - x_min) < 1e-14
    assert check.ok == (x >= x_min - 1e-12)


def test_checks_fail_with_their_causes():
    m = 10e-3
    p = gear_pair(m, (12, 30), (0.0, 0.0))                  # the textbook's undercut pinion
    failed = {(c.name, c.gear) for c in p.failed()}
    assert ("undercut", 1) in failed and not p.success and "undercut" in p.message
    p = gear_pair(m, (12, 30), (1.2, 0.0))                  # a large shift: pointed tip
    assert ("pointed tip", 1) in {(c.name, c.gear) for c in p.failed()}
    assert p.gears[0].tip_thickness < 0.25 * m
    p = gear_pair(m, (20, 20), (1.0, 1.0))                  # both shifted far: short contact
    assert ("contact ratio", None) in {(c.name, c.gear) for c in p.failed()} and p.contact_ratio < 1.2
    p = gear_pair(m, (40, 40), (0.0, 0.0))
    assert p.success and p.message == "all checks met"


def test_interference_means_contact_below_the_involute():
    """The contact starts where gear 2's tip meets the line of action; gear 1's involute starts where the
    rack's straight flank stopped cutting: ρ_l = r sin α − (h_a* − x)m/sin α."""
    m = 1e-3
    for z1, x1 in ((14, 0.2), (18, 0.0), (25, -0.3)):
        p = gear_pair(m, (z1, 80), (x1, 0.0))
        rho_l = m * z1 / 2 * math.sin(ALPHA) - (1 - x1) * m / math.sin(ALPHA)
        check = next(c for c in p.checks if c.name == "interference" and c.gear == 1)
        assert abs(check.limit - max(rho_l, 0.0)) < 1e-15
        assert check.ok == (p.path[0] >= max(rho_l, 0.0) - 1e-15)


def test_ring_tip_cut_back_starts_the_contact_on_the_pinion_involute():
    """A standard internal gear (x = 0, h_a* = 1) meets a rack-cut pinion below its involute; cut back,
    its tip circle is the one through the pinion's form point, and the contact ratio is what remains."""
    std = gear_pair(1e-3, (20, 62), (0.0, 0.0), internal=True)
    cut = gear_pair(1e-3, (20, 62), (0.0, 0.0), internal=True, ring_tip="cut")
    assert not std.success and "interference" in std.message and "--ring-tip cut" in std.message
    assert cut.success and cut.gears[1].tip_diameter > std.gears[1].tip_diameter
    rho_l = 10e-3 * math.sin(ALPHA) - 1e-3 / math.sin(ALPHA)
    assert abs(cut.path[0] - rho_l) < 1e-15
    assert cut.contact_ratio < std.contact_ratio


def test_specific_sliding_from_the_velocities_of_the_contact_point():
    """ζ₁ = (v₁ − v₂)/v₁ with v the velocity of the contact point along each profile, v = ω ρ: at the path's
    ends, from the pair's own ρ and the speeds ω₂ = ω₁ z₁/z₂."""
    p = gear_pair(4e-3, (17, 41), (0.4, 0.1))
    w1, w2 = 1.0, 17 / 41
    L = p.line_of_action
    for rho1, zeta1, zeta2 in ((p.path[0], p.gears[0].root_sliding, p.gears[1].tip_sliding),
                               (p.path[1], p.gears[0].tip_sliding, p.gears[1].root_sliding)):
        v1, v2 = w1 * rho1, w2 * (L - rho1)
        assert abs(zeta1 - (v1 - v2) / v1) < 1e-13 and abs(zeta2 - (v2 - v1) / v2) < 1e-13


@pytest.mark.parametrize("call, match", [
    (lambda: gear_pair(0.0, (12, 30)), "module must be > 0, got 0.0"),
    (lambda: gear_pair(-1e-3, (12, 30)), "module must be > 0"),
    (lambda: gear_pair(1e-3, (0, 30)), "z1 must be a whole number ≥ 1, got 0"),
    (lambda: gear_pair(1e-3, (12, 30.5)), "z2 must be a whole number ≥ 1, got 30.5"),
    (lambda: gear_pair(1e-3, (30, 20), internal=True), "more teeth than its pinion"),
    (lambda: gear_pair(1e-3, (12, 30), (float("nan"), 0)), "x1 must be a finite number"),
    (lambda: gear_pair(1e-3, (12, 30), (-20, -20)), "cannot mesh"),
    (lambda: Rack(math.radians(50)), "pressure angle must be between"),
    (lambda: Rack(tip_radius=0.9), "tool tip radius coefficient must be between 0 and 0.47"),
])
def test_bad_values_are_named(call, match):
    with pytest.raises(ModelError, match=match):
        call()
