"""The block contour and the choice of shifts: the contour's admissible set is exactly where `gear_pair`
meets every check, and each criterion's point is what it says (checked against grids of its own)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mbplanar.errors import ModelError
from mbplanar.gears import block_contour, choose_shifts, gear_pair

M = 10e-3


def pair_at(x1, x2, teeth=(12, 30)):
    """The pair at (x1, x2), or None where the shifts give no mesh (inv α_w < 0)."""
    try:
        return gear_pair(M, teeth, (x1, x2))
    except ModelError:
        return None


@pytest.fixture(scope="module")
def contour():
    return block_contour(M, (12, 30), grid=81)


def test_contour_is_where_every_check_is_met(contour):
    """Every 7th grid point: admissible on the contour ⇔ `gear_pair` there meets every check."""
    for j in range(0, contour.x2.size, 7):
        for i in range(0, contour.x1.size, 7):
            p = pair_at(contour.x1[i], contour.x2[j])
            assert bool(contour.admissible[j, i]) == (p is not None and p.success), (contour.x1[i], contour.x2[j])


def test_contour_edges_are_the_textbook_lines(contour):
    """The undercut line of the 12-tooth pinion is the vertical x₁ = 1 − 12 sin²20°/2 (0.2981); every
    admissible point lies right of it; the contour exists and is bounded by the contact ratio above."""
    x_min = 1 - 12 * math.sin(math.radians(20)) ** 2 / 2
    cols = np.flatnonzero(contour.admissible.any(axis=0))
    assert contour.x1[cols[0]] >= x_min - 1e-12
    assert contour.x1[cols[0]] - x_min < np.diff(contour.x1)[0] + 1e-12
    assert contour.area > 0.1 and contour.admissible.mean() < 0.5
    top = contour.admissible[-1]                              # at the box's top edge: nothing admissible
    assert not top.any()


def test_balanced_choice_equalises_the_sliding_and_is_least_on_the_curve():
    c = choose_shifts(M, (12, 30), "balanced")
    g1, g2 = c.pair.gears
    assert c.success and abs(g1.root_sliding - g2.root_sliding) < 1e-9
    # along the balanced curve (each line of constant sum), no admissible point slides less
    for total in np.linspace(0.2, 1.4, 25):
        best = None
        x1s = np.linspace(-0.5, 1.5, 4001)
        pairs = [pair_at(x, total - x) for x in x1s[::40]]
        gaps = [np.nan if p is None else p.gears[0].root_sliding - p.gears[1].root_sliding for p in pairs]
        for k in range(len(gaps) - 1):
            if np.isfinite(gaps[k]) and np.isfinite(gaps[k + 1]) and gaps[k] * gaps[k + 1] <= 0:
                lo, hi = x1s[::40][k], x1s[::40][k + 1]
                for _ in range(60):
                    mid = (lo + hi) / 2
                    p = gear_pair(M, (12, 30), (mid, total - mid))
                    g = p.gears[0].root_sliding - p.gears[1].root_sliding
                    if (g > 0) == (gaps[k] > 0):
                        lo = mid
                    else:
                        hi = mid
                best = gear_pair(M, (12, 30), (lo, total - lo))
        if best is not None and best.success:
            assert best.gears[0].root_sliding <= g1.root_sliding + 1e-6


def test_contact_choice_is_the_largest_contact_ratio():
    c = choose_shifts(M, (12, 30), "contact")
    assert c.success
    rng = np.random.default_rng(3)
    for x1, x2 in rng.uniform([-0.5, -1.25], [0.8, 1.45], size=(400, 2)):
        p = pair_at(x1, x2)
        if p is not None and p.success:
            assert p.contact_ratio <= c.pair.contact_ratio + 1e-9


@settings(max_examples=20, deadline=None)
@given(st.floats(0.35, 1.0))
def test_sum_choice_holds_the_sum_and_balances(total):
    c = choose_shifts(M, (12, 30), "sum", shift_sum=total)
    assert abs(sum(c.shifts) - total) < 1e-12
    g1, g2 = c.pair.gears
    if "nearest" not in c.message:
        assert abs(g1.root_sliding - g2.root_sliding) < 1e-9
    assert c.pair.success


def test_fixed_centre_distance():
    """a_w = 215 mm for z = 12, 30, m = 10 (a = 210 mm): the chosen pair sits at exactly that distance."""
    for criterion in ("balanced", "contact", "sum"):
        c = choose_shifts(M, (12, 30), criterion, centre_distance=0.215)
        assert abs(c.pair.centre_distance - 0.215) < 1e-12 and c.success
        assert c.contour.shift_sum == c.shift_sum


def test_internal_pair_choice():
    c = choose_shifts(2e-3, (20, 62), "contact", internal=True)
    assert c.success and c.pair.internal
    c = choose_shifts(2e-3, (20, 62), "sum", internal=True, shift_sum=0.3)
    assert abs(c.shifts[1] - c.shifts[0] - 0.3) < 1e-12


@pytest.mark.parametrize("kwargs, match", [
    (dict(criterion="fancy"), "unknown criterion 'fancy'"),
    (dict(criterion="sum"), "needs --shift-sum or --centre-distance"),
    (dict(criterion="balanced", centre_distance=0.1), "cannot be taken"),
    (dict(criterion="sum", shift_sum=3.0), "no admissible shifts on the line x_Σ = 3"),
    (dict(criterion="balanced", shift_sum=0.5, centre_distance=0.215), "disagrees"),
])
def test_bad_requests(kwargs, match):
    with pytest.raises(ModelError, match=match):
        choose_shifts(M, (12, 30), **kwargs)
