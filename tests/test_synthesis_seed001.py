"""Seed 001's guiding-mechanism synthesis: round trip of forms (a), (b), (c), and the reported Δ1, Δ2
against an independent dense analysis of the written model."""

import math

import numpy as np
import pytest

import mbplanar
from mbplanar.errors import ModelError
from mbplanar.synthesis.guiding import (SEED001_CHAIN, Candidates, WalkingTarget, chain_angles,
                                        chebyshev_nodes, foot_paths, form_a, form_b, form_c)
from mbplanar.synthesis.seed001 import synthesise_seed001

CHAIN = SEED001_CHAIN
# a guiding crank-slider of our choice on the seed's chain: line angle 10°, 0.1 above the crank pivot
THETA, L, GAMMA = math.radians(10.0), 1.0, math.radians(20.0)
RHO = float(np.array([-math.sin(THETA), math.cos(THETA)]) @ np.array(CHAIN.pivot)) + 0.1
K, D = math.tan(THETA), RHO / math.cos(THETA)


def _reference_path(phi1):
    """Foot path of the reference design by mbplanar's analysis of a hand-built model."""
    a = np.array(CHAIN.pivot)
    b = a + CHAIN.a * np.array([1.0, 0.0])                    # crank at 0
    u, n = np.array([math.cos(THETA), math.sin(THETA)]), np.array([-math.sin(THETA), math.cos(THETA)])
    h = n @ b - RHO
    c = b - h * n + math.sqrt(L * L - h * h) * u
    psi = math.atan2(*(c - b)[::-1]) + GAMMA
    e = b + CHAIN.b * np.array([math.cos(psi), math.sin(psi)])
    m = mbplanar.Mechanism("ref")
    for name in "123":
        m.add_link(name)
    m.add_joint("A", "R", "0", "1", at=a)
    m.add_joint("B", "R", "1", "2", at=b)
    m.add_joint("C", "R", "2", "3", at=c)
    m.add_joint("Cp", "P", "0", "3", at=c, guide=math.degrees(THETA))
    m.add_point("E", "2", at=e)
    m.add_input("A")
    motion = mbplanar.analyse(mbplanar.Engine(m), phi1)
    return motion.xy[:, motion.point("E")]


def _modes(nodes, phi1):
    """The chain's assembly mode at each node: the root of (5) that gives the node's crank angle."""
    out = []
    for i, p in enumerate(phi1):
        for mode in (1, -1):
            got, _ = chain_angles(CHAIN, nodes[i:i + 1], mode)
            if abs(math.remainder(got[0] - p, 2 * math.pi)) < 1e-9:
                out.append(mode)
                break
    return out


PHI = np.radians([0.0, 90.0, 180.0, 270.0])


def test_round_trip_form_b_recovers_l_gamma_k_d():
    nodes = _reference_path(PHI[:3])
    cand = form_b(CHAIN, nodes, [THETA], _modes(nodes, PHI[:3]))
    assert cand.l[0] == pytest.approx(L, abs=1e-9)
    assert cand.gamma[0] == pytest.approx(GAMMA, abs=1e-9)
    assert cand.k[0] == pytest.approx(K, abs=1e-9)
    assert cand.d[0] == pytest.approx(D, abs=1e-9)


def test_round_trip_form_c_recovers_all_four():
    nodes = _reference_path(PHI)
    cand = form_c(CHAIN, nodes, _modes(nodes, PHI))
    hit = np.flatnonzero(np.abs(cand.l - L) < 1e-6)
    assert len(hit) == 1
    i = hit[0]
    assert (cand.l[i], cand.gamma[i], cand.k[i], cand.d[i]) == pytest.approx((L, GAMMA, K, D), abs=1e-9)


def test_round_trip_form_a_finds_the_line_at_the_true_gamma():
    nodes = _reference_path(PHI[:3])
    cand = form_a(CHAIN, nodes, [GAMMA], _modes(nodes, PHI[:3]))
    i = int(np.argmin(np.abs(cand.theta - THETA)))
    assert (cand.l[i], cand.k[i], cand.d[i]) == pytest.approx((L, K, D), abs=1e-9)


def test_foot_paths_match_mbplanar():
    phi = np.radians(np.arange(0, 360, 15.0))
    cand = Candidates(np.array([THETA]), np.array([RHO]), np.array([L * math.cos(GAMMA)]),
                      np.array([L * math.sin(GAMMA)]), np.ones((1, 1)))
    e, ok = foot_paths(CHAIN, cand, np.array([1.0]), phi)
    assert ok.all()
    np.testing.assert_allclose(e[0], _reference_path(phi), atol=1e-12)


def test_chebyshev_nodes_are_the_cosine_nodes():
    x = chebyshev_nodes(3, 0.0, 1.0)
    np.testing.assert_allclose(x, 0.5 - 0.5 * np.cos(np.pi * np.array([1, 3, 5]) / 6), atol=1e-15)


TARGET = WalkingTarget(0.0, -2.6, 1.0, 0.2, -1)      # the documented D-shaped target


@pytest.fixture(scope="module")
def seed_result():
    return synthesise_seed001(TARGET)


def test_documented_target_interpolates_its_nodes(seed_result):
    r = seed_result
    assert r.defects.ok and r.defects.full_turn
    assert np.max(r.node_errors) < 1e-9
    assert r.delta1 < 0.005 and r.delta2 < 0.005


def test_reported_deltas_are_the_models_own(seed_result):
    """An independent sweep of the written model (read back from its text) gives Δ1 and Δ2: the dense
    maximum inside the support window, its ends located by brentq on mbplanar's x(φ), and the dense
    interior maxima refined by a bounded scalar search."""
    from scipy.optimize import brentq, minimize_scalar
    r = seed_result
    engine = mbplanar.Engine(mbplanar.parse_model(r.toml))

    def foot(phi):
        m = mbplanar.analyse(engine, np.atleast_1d(phi))
        return m.xy[:, m.point("E")]
    phi = np.linspace(0, 2 * np.pi, 20001)
    xy = foot(phi)
    assert len(xy) == len(phi)
    low = xy[:, 1] < -2.5
    inside = low & (xy[:, 0] >= 0.0) & (xy[:, 0] <= 1.0)
    values = list(np.abs(xy[inside, 1] + 2.6))
    for k in np.flatnonzero(low[:-1] & low[1:] & (inside[:-1] != inside[1:])):   # the window's ends
        edge = 0.0 if min(xy[k, 0], xy[k + 1, 0]) < 0.5 else 1.0
        at = brentq(lambda p: foot(p)[0, 0] - edge, phi[k], phi[k + 1], xtol=1e-15)
        values.append(abs(foot(at)[0, 1] + 2.6))
    k = int(np.argmax(np.where(inside, np.abs(xy[:, 1] + 2.6), -1)))
    if 0 < k < len(phi) - 1 and inside[k - 1] and inside[k + 1]:
        res = minimize_scalar(lambda p: -abs(foot(p)[0, 1] + 2.6), bounds=(phi[k - 1], phi[k + 1]),
                              method="bounded", options={"xatol": 1e-12})
        values.append(-res.fun)
    assert r.delta1 == pytest.approx(max(values), abs=1e-10)
    k = int(np.argmax(xy[:, 1]))
    res = minimize_scalar(lambda p: -foot(p)[0, 1], bounds=(phi[k - 1], phi[k + 1]), method="bounded",
                          options={"xatol": 1e-12})
    assert r.delta2 == pytest.approx(abs(-res.fun + 2.4), abs=1e-10)


def test_minimax_and_lsq_over_more_nodes():
    lsq = synthesise_seed001(TARGET, support_nodes=4, fit="lsq", theta_deg=(165.0, 180.0, 1.0))
    assert lsq.defects.ok and lsq.delta < 0.01


def test_out_of_reach_target_is_a_clear_error():
    with pytest.raises(ModelError, match="out of the chain's reach"):
        synthesise_seed001(WalkingTarget(10.0, 0.0, 1.0, 0.2))


def test_bad_options_are_clear_errors():
    with pytest.raises(ModelError, match="exactly at 3 nodes"):
        synthesise_seed001(TARGET, form="b", support_nodes=4, fit="exact")
    with pytest.raises(ModelError, match="form must be"):
        synthesise_seed001(TARGET, form="x")
    with pytest.raises(ModelError, match="at least 2"):
        synthesise_seed001(TARGET, support_nodes=1)


def test_the_same_input_gives_the_same_model(seed_result):
    """The method has no randomness: a second run writes the same model to the last digit."""
    assert synthesise_seed001(TARGET).toml == seed_result.toml
