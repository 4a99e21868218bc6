"""Path generation: targets from known coupler curves, results checked by mbplanar's own analysis;
reproducible with a seed, serial or on Dask; constraints honoured; timed targets; any model's
parameters; clear errors."""


import numpy as np
import pytest

import mbplanar
from mbplanar.errors import ModelError
from mbplanar.synthesis.constraints import PathConstraints, transmission_angles
from mbplanar.synthesis.path import synthesise_path
from mbplanar.synthesis.path_model import synthesise_model_path

_M = mbplanar.analyse(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), np.radians(np.arange(0, 360, 30.0)))
TARGETS = _M.xy[:, _M.point("M")]
SMALL = {"starts": 1, "shapes": 1024, "keep": 2}


@pytest.fixture(scope="module")
def result():
    return synthesise_path(TARGETS, seed=1, **SMALL)


def _analysed(result, phi):
    engine = mbplanar.Engine(mbplanar.parse_model(result.toml))
    return engine, mbplanar.analyse(engine, phi)


def test_errors_are_the_models_own(result):
    engine, m = _analysed(result, result.phi)
    at_nodes = np.hypot(*(m.xy[:, m.point("P")] - TARGETS).T)
    assert np.all(result.errors <= at_nodes + 1e-12)
    assert result.defects.ok and result.defects.full_turn
    assert mbplanar.check(engine).full_turn
    dense = mbplanar.analyse(engine, result.phi[0] + np.linspace(0, 2 * np.pi, 7201))
    p = dense.xy[:, dense.point("P")]
    nearest = np.min(np.hypot(p[:, None, 0] - TARGETS[:, 0], p[:, None, 1] - TARGETS[:, 1]), axis=0)
    assert np.all(result.errors <= nearest + 1e-12)           # nothing nearer on the analysed curve
    from scipy.optimize import minimize_scalar                # ... and the reported distance is the nearest
    fine = dense.phi[:, 0]
    for k, target in enumerate(TARGETS):
        i = int(np.argmin(np.hypot(*(p - target).T)))
        gap = lambda x: float(np.hypot(*(mbplanar.analyse(engine, [x]).xy[0, dense.point("P")] - target)))  # noqa: E731
        best = minimize_scalar(gap, bounds=(fine[max(i - 1, 0)], fine[min(i + 1, len(fine) - 1)]), method="bounded",
                               options={"xatol": 1e-10})
        assert result.errors[k] <= best.fun + 1e-11
        assert best.fun < 1e-6 or abs(result.errors[k] - best.fun) < 1e-11
    assert result.rms < 0.1 * np.ptp(TARGETS, axis=0).max()


def test_same_seed_same_design(result):
    again = synthesise_path(TARGETS, seed=1, **SMALL)
    np.testing.assert_array_equal(again.design, result.design)
    assert again.evaluations == result.evaluations


def test_dask_starts_equal_the_serial_run():
    pytest.importorskip("distributed")
    from mbplanar.study.cluster import close, local_client
    settings = {**SMALL, "starts": 2, "generations": 8}
    serial = synthesise_path(TARGETS, seed=3, **settings)
    client = local_client(2)
    try:
        spread = synthesise_path(TARGETS, seed=3, client=client, **settings)
    finally:
        close(client)
    np.testing.assert_array_equal(spread.design, serial.design)
    np.testing.assert_array_equal(spread.errors, serial.errors)
    assert spread.evaluations == serial.evaluations


def test_constraints_are_honoured():
    c = PathConstraints(min_transmission_deg=35.0, max_ratio=4.0, pivots={"A0": [[-0.2, -0.2], [0.2, 0.2]]})
    r = synthesise_path(TARGETS, seed=0, constraints=c, starts=1, popsize=8, generations=30, keep=2)
    engine, m = _analysed(r, r.phi[0] + np.linspace(0, 2 * np.pi, 721))
    xy = {k: m.xy[:, m.point(k)] for k in ("A0", "A", "B", "B0")}
    mu = np.degrees(transmission_angles(xy["A"], xy["B"], xy["B0"]))
    assert mu.min() >= 35.0 - 1e-9 and abs(mu.min() - r.transmission_deg) < 0.05
    links = [np.hypot(*(xy[p] - xy[q])[0]) for p, q in (("A0", "A"), ("A", "B"), ("B", "B0"), ("B0", "A0"))]
    assert max(links) / min(links) <= 4.0 + 1e-12
    assert np.all(np.abs(xy["A0"][0]) <= 0.2 + 1e-12)
    assert r.defects.ok


def test_timed_targets_meet_their_crank_angles():
    phi = np.radians(np.arange(0, 360, 40.0))
    m0 = mbplanar.analyse(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), phi)
    targets = m0.xy[:, m0.point("M")]
    r = synthesise_path(targets, timing=phi + 1.0, seed=0, starts=1, popsize=8, generations=30, keep=2)
    assert r.timed
    np.testing.assert_allclose(np.mod(r.defects.sense * (r.phi - r.phi[0]), 2 * np.pi), phi, atol=1e-12)
    _, m = _analysed(r, r.phi)
    np.testing.assert_allclose(np.hypot(*(m.xy[:, m.point("P")] - targets).T), r.errors, atol=1e-12)
    assert r.rms < 0.2 * np.ptp(targets, axis=0).max()


def test_any_model_parameters_recover_a_known_design():
    template_values = {"m": 0.3, "h": 0.08}
    from mbplanar.study.run import load_template
    tpl = load_template("models/fourbar_design.toml")
    engine = mbplanar.Engine(mbplanar.parse_model(tpl.bind(template_values)))
    m = mbplanar.analyse(engine, engine.phi_drawn[0] + np.radians(np.arange(0, 360, 36.0)))
    targets = m.xy[:, m.point("M")]
    r = synthesise_model_path("models/fourbar_design.toml", "M", {"m": (0.0, 1.0), "h": (-0.1, 0.1)}, targets,
                              seed=0, starts=1, generations=10, popsize=6)
    assert abs(r.values["m"] - 0.3) < 1e-9 and abs(r.values["h"] - 0.08) < 1e-9
    assert r.max < 1e-9 and r.defects.ok
    again = mbplanar.Engine(mbplanar.parse_model(r.toml))   # the written model, with its new parameters
    back = mbplanar.analyse(again, r.phi)
    np.testing.assert_allclose(np.hypot(*(back.xy[:, back.point("M")] - targets).T), r.errors, atol=1e-12)


def test_open_partial_curve_without_a_full_turn():
    part = TARGETS[:6]                                     # half of the curve, an open run of targets
    r = synthesise_path(part, constraints=PathConstraints(full_turn=False), seed=0, starts=1, popsize=8,
                        generations=30, keep=2)
    assert r.defects.ok and r.defects.full_turn is None and not r.constraints.full_turn
    engine, m = _analysed(r, r.phi)
    np.testing.assert_allclose(np.hypot(*(m.xy[:, m.point("P")] - part).T) >= r.errors - 1e-12, True)
    span = np.linspace(r.phi[0], r.phi[0] + r.defects.sense * np.mod(r.defects.sense * (r.phi[-1] - r.phi[0]), 2 * np.pi), 200)
    swept = mbplanar.analyse(engine, span)                 # the arc from the first to the last target, one branch
    assert len(swept.phi) == len(span) and not swept.limits


def test_any_model_timed_targets():
    from mbplanar.study.run import load_template
    tpl = load_template("models/fourbar_design.toml")
    engine = mbplanar.Engine(mbplanar.parse_model(tpl.bind({"m": 0.3, "h": 0.08})))
    advance = np.radians(np.arange(0, 300, 50.0))
    m = mbplanar.analyse(engine, engine.phi_drawn[0] + 0.7 + advance)
    targets = m.xy[:, m.point("M")]
    r = synthesise_model_path(tpl, "M", {"m": (0.0, 1.0), "h": (-0.1, 0.1)}, targets, timing=advance + 5.0,
                              seed=1, starts=1, generations=12, popsize=6)
    assert r.timed and r.defects.ok
    np.testing.assert_allclose(r.phi - r.phi[0], advance, atol=1e-12)
    assert r.max < 1e-8 and abs(r.values["m"] - 0.3) < 1e-8


@pytest.mark.parametrize("call, message", [
    (lambda: synthesise_path(TARGETS[:2]), "at least 3"),
    (lambda: synthesise_path(np.zeros((6, 2))), "rows 1-6 are all the one point"),
    (lambda: synthesise_path(np.r_[TARGETS[:2], [[np.nan, 0.1]], TARGETS[3:]]), "row 3"),
    (lambda: synthesise_path(TARGETS, timing=[0.0, 1.0]), "one finite input value per target"),
    (lambda: PathConstraints(min_transmission_deg=95.0), "min_transmission_deg"),
    (lambda: PathConstraints(max_ratio=0.5), "max_ratio"),
    (lambda: PathConstraints(pivots={"A0": [[1, 1], [0, 0]]}), "x_min < x_max"),
    (lambda: synthesise_model_path("models/fourbar_design.toml", "M", {"zz": (0, 1)}, TARGETS), "zz name no parameter"),
    (lambda: synthesise_model_path("models/fourbar_design.toml", "M", {"m": (1, 0)}, TARGETS), "lower < upper"),
    (lambda: synthesise_model_path("models/fourbar_design.toml", "Q", {"m": (0, 1)}, TARGETS), "no joint or point 'Q'"),
    (lambda: synthesise_model_path("models/fourbar_design.toml", "M", {"m": (0, 1)}, TARGETS,
                                   constraints=PathConstraints(pivots={"A": [[0, 0], [1, 1]]})), "not a fixed pivot"),
    (lambda: synthesise_model_path("models/fourbar_design.toml", "M", {"m": (0, 1)}, TARGETS,
                                   constraints=PathConstraints(min_transmission_deg=30)), "transmission_joints"),
])
def test_bad_input_is_a_clear_error(call, message):
    with pytest.raises(ModelError, match=message):
        call()


def test_infeasible_constraints_say_so():
    """Bounds no design can meet: the best design still comes back, with success False and a warning
    naming the bound missed and by how much."""
    c = PathConstraints(pivots={"A0": [[50.0, 50.0], [50.1, 50.1]], "B0": [[-50.1, -50.1], [-50.0, -50.0]]},
                        max_ratio=1.05)
    r = synthesise_path(TARGETS, constraints=c, starts=1, shapes=256, keep=1)
    assert not r.success and r.ratio > 1.05
    assert any("link ratio" in w and "exceeds the bound 1.05" in w for w in r.warnings)


# -- designer-grade results: never empty-handed, the defaults, reproducibility ---------------------------------
def _fourbar_targets(design, degrees):
    from mbplanar.synthesis.batch import fourbar_coupler_paths
    _, _, p, ok = fourbar_coupler_paths(np.array([design], float), np.radians(degrees))
    assert ok.all()
    return p[0]


def test_near_coincident_target_out_of_order_gets_a_design_and_the_warning():
    """A 13th target half a degree of crank behind the 5th, listed after it (as a careless digitisation
    gives): the design comes back, in order within the tolerance, with a warning naming targets 5 and 6
    and how far back 6 lies."""
    m = mbplanar.analyse(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), np.radians([119.5]))
    targets = np.insert(TARGETS, 5, m.xy[0, m.point("M")], axis=0)
    assert np.hypot(*(targets[5] - targets[4])) < 0.05 * np.hypot(*(targets[6] - targets[5]))
    r = synthesise_path(targets, **SMALL)
    assert r.success and r.defects.ok
    said = [w for w in r.warnings if "targets 5 and 6 are met out of order" in w]
    assert len(said) == 1 and "within the tolerance" in said[0]
    step = [s for s in r.order["steps_back"] if (s["from"], s["to"]) == (5, 6)]
    gap = float(np.hypot(*(targets[5] - targets[4])))
    assert len(step) == 1 and 0.5 * gap < step[0]["length"] < 2.0 * gap + 2 * r.max    # back by about their gap
    assert r.rms < 1e-3 * np.ptp(targets, axis=0).max()


def test_defaults_hold_by_the_models_analysis_and_can_be_dropped():
    """Targets on the curve of a crank-rocker whose transmission angle falls to 14.36° (where the crank
    points at the rocker's pivot, cos μ = (1.2² + 0.7² − 0.55²)/(2·1.2·0.7)): by default the
    design keeps the crank turning fully, μ ≥ 30° and the link ratio ≤ 10 (mbplanar's analysis of the
    written model), and says what that cost; without the bounds the exact design is within reach."""
    design = [0.0, 0.0, 1.0, 0.0, 0.45, 1.2, 0.7, 0.6, 0.5, 1.0]
    from mbplanar.synthesis.path_screen import shape_bounds
    assert abs(shape_bounds([design])[0][0] - np.degrees(np.arccos(1.6275 / 1.68))) < 1e-12
    targets = _fourbar_targets(design, np.arange(0.0, 360.0, 36.0))
    r = synthesise_path(targets, **SMALL)
    assert r.constraints.min_transmission_deg == 30.0 and r.constraints.max_ratio == 10.0 and r.constraints.full_turn
    engine, m = _analysed(r, r.phi[0] + np.linspace(0, 2 * np.pi, 1441))
    assert mbplanar.check(engine).full_turn
    xy = {k: m.xy[:, m.point(k)] for k in ("A0", "A", "B", "B0")}
    assert np.degrees(transmission_angles(xy["A"], xy["B"], xy["B0"])).min() >= 30.0 - 1e-9
    links = [np.hypot(*(xy[p] - xy[q])[0]) for p, q in (("A0", "A"), ("A", "B"), ("B", "B0"), ("B0", "A0"))]
    assert max(links) / min(links) <= 10.0 + 1e-12
    t = r.tradeoff
    assert t["relaxed"] == ["min_transmission_deg", "max_ratio"] and t["with"]["rms"] == r.rms
    if t["without"] is not None:                       # the better design the bounds ruled out
        assert t["without"]["rms"] < r.rms and (t["without"]["transmission_deg"] < 30.0 or t["without"]["ratio"] > 10.0)
    free = synthesise_path(targets, constraints=PathConstraints(), **SMALL)
    assert free.tradeoff is None and free.rms <= r.rms + 1e-12 and free.rms < 1e-9


def test_same_seed_same_design_and_count_in_fresh_processes():
    """Two processes (one with four BLAS threads, one with one) give the same design, bit for bit, and
    the same evaluation count."""
    import subprocess
    import sys
    code = ("import numpy as np, mbplanar; from mbplanar.synthesis import synthesise_path; "
            "m = mbplanar.analyse(mbplanar.Engine(mbplanar.read_model('models/fourbar.toml')), "
            "np.radians(np.arange(0, 360, 30.0))); r = synthesise_path(m.xy[:, m.point('M')], seed=5, starts=1, "
            "shapes=512, keep=1); print(r.design.tobytes().hex(), r.evaluations)")
    outs = []
    for threads in ("4", "1"):
        env = {**__import__("os").environ, "OMP_NUM_THREADS": threads, "OPENBLAS_NUM_THREADS": threads}
        outs.append(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                                   check=True).stdout)
    assert outs[0] == outs[1] and outs[0].strip()


def test_a_budget_stops_the_search_with_the_best_so_far():
    r = synthesise_path(TARGETS, budget=0.01, seed=1)
    assert r.stopped and any("budget" in w for w in r.warnings)
    assert r.defects.full_turn and np.all(np.isfinite(r.errors))
