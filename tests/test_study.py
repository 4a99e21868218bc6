"""Design studies: design batches against the same designs solved one by one, limits and reasons per
design, loop closure over random four-bars and slider-cranks, seed 002's 30 variants, Dask."""

import csv
import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import mbplanar
from mbplanar.cli import main
from mbplanar.study import design_batch, run_study, solve_designs, with_dimensions
from mbplanar.study.variants import read_variants

SEED002 = "models/crank_slider_rocker.toml"
# the design batch's loops: numpy (the reference) and the compiled kernel (backends._numba_design)
BACKENDS = ["numpy", pytest.param("numba", marks=pytest.mark.skipif(
    __import__("importlib").util.find_spec("numba") is None, reason="numba not installed"))]
VARIANTS = "models/crank_slider_rocker_variants.csv"


def seed002_mechanism(l2, l3, l4, p2, p3, p4, l1=0.5):
    """Seed 002's mechanism from its formulas, by the Python API (not through parameters)."""
    m = mbplanar.Mechanism("seed002")
    for name in "12345":
        m.add_link(name)
    a = (l1, 0.0)
    c = (a[0] + l2 * math.cos(p2), a[1] + l2 * math.sin(p2))
    b = (c[0] + l3 * math.cos(p3), c[1] + l3 * math.sin(p3))
    d = (b[0] + l4 * math.cos(p4), b[1] + l4 * math.sin(p4))
    m.add_joint("O", "R", "0", "1", at=(0, 0))
    m.add_joint("A", "R", "1", "2", at=a)
    m.add_joint("C", "R", "2", "3", at=c)
    m.add_joint("C5", "R", "2", "5", at=c)
    m.add_joint("Cp", "P", "0", "5", at=c, guide=0.0)
    m.add_joint("B", "R", "3", "4", at=b)
    m.add_joint("D", "R", "4", "0", at=d)
    m.add_input("O", name="t", unit="rad")
    return m


def single_reach(engine):
    """Full turn, and the limits by direction, of a single-model engine (as `check` finds them)."""
    phi0 = float(engine.phi_drawn[0])
    up = mbplanar.analyse(engine, [phi0, phi0 + 2 * math.pi])
    if not up.limits:
        return True, {}
    down = mbplanar.analyse(engine, [phi0 - 2 * math.pi, phi0])
    return False, {lim.direction: lim for lim in up.limits + down.limits}


@pytest.fixture(scope="module")
def seed002_rows():
    rows = []
    for line in open(VARIANTS):
        if line[0].isdigit():
            rows.append([float(x) for x in line.split(",")])
    return rows


def test_seed002_study_lists_every_variant_with_its_turn_or_lock(capsys, seed002_rows):
    """All 30 variants of Table 2.1: full turn or the lock angles (to 1e-6°) and kinds, as each
    variant's own engine, built from the seed's formulas, finds them."""
    assert main(["study", SEED002, "--variants", VARIANTS, "--json", "--no-progress"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["counts"]["designs"] == 30 and len(doc["designs"]) == 30
    for row, design in zip(seed002_rows, doc["designs"]):
        assert design["name"] == str(int(row[0])) and design["assembles"]
        turns, limits = single_reach(mbplanar.Engine(seed002_mechanism(*row[1:])))
        assert design["full_turn"] is turns
        got = {lim["direction"]: lim for lim in design["limits"]}
        assert set(got) == set(limits)
        for direction, lim in limits.items():
            assert abs(got[direction]["phi_deg"] - math.degrees(lim.phi[0])) < 1e-6
            assert got[direction]["kind"] == lim.kind


@pytest.mark.parametrize("backend", BACKENDS)
def test_batch_equals_one_by_one(seed002_rows, backend):
    """Positions, link angles (and, away from motion limits, analogues) of a design batch against each
    design's own engine, to 1e-12; the same positions reached, the same limits."""
    variants = read_variants(VARIANTS, mbplanar.study.load_template(SEED002)).take(np.arange(0, 30, 6))
    batch = design_batch(SEED002, variants, backend=backend)
    phi = np.linspace(-math.pi, math.pi, 37)
    motion = batch.solve(phi)
    for d in range(len(variants)):
        row = seed002_rows[6 * d]
        engine = mbplanar.Engine(seed002_mechanism(*row[1:]))
        single = mbplanar.analyse(engine, phi)
        reached = np.isin(phi, single.phi[:, 0])
        assert np.array_equal(reached, motion.valid[d])
        cols = [single.point(p) for p in motion.points]
        assert np.abs(single.xy[:, cols] - motion.xy[d, reached]).max() < 1e-12
        assert np.abs(single.angle - motion.angle[d, reached]).max() < 1e-12
        far = np.ones(reached.sum(), bool)
        for lim in single.limits:
            far &= np.abs(single.phi[:, 0] - lim.phi[0]) > 0.05
        scale = 1 + np.abs(single.vq[far][:, cols])
        assert (np.abs(single.vq[far][:, cols] - motion.vq[d, reached][far]) / scale).max() < 1e-12
        mine = {lim.direction: lim for lim in motion.limits_of(d)}
        assert set(mine) == {lim.direction for lim in single.limits}
        for lim in single.limits:
            assert abs(mine[lim.direction].phi - lim.phi[0]) < 1e-12
            assert mine[lim.direction].kind == lim.kind


@pytest.mark.parametrize("backend", BACKENDS)
def test_locking_variant_is_reported_as_a_single_model_sweep(backend):
    """The seed's first data (l3 = 1.2, φ30 = 4.7, φ40 = 5.7), a row of parameters, locks where the
    model file crank_slider_rocker_locking.toml locks in a sweep: same φ, direction, links, kind."""
    phi = np.linspace(0, 2 * math.pi, 73)
    motion = design_batch(SEED002, {"phi30": [4.7], "phi40": [5.7]}, backend=backend).solve(phi)
    sweep = mbplanar.analyse(mbplanar.Engine(mbplanar.read_model("models/crank_slider_rocker_locking.toml")), phi)
    (lim,), (mine,) = sweep.limits, motion.limits_of(0)
    assert abs(mine.phi - lim.phi[0]) < 1e-13
    assert (mine.direction, mine.links, mine.joints, mine.kind) == (lim.direction, lim.links, lim.joints, lim.kind)
    assert abs(lim.phi[0] - 1.799912) < 1e-6  # REFERENCE.md: seed 002's first data lock at t = 1.799912
    assert np.array_equal(motion.valid[0], np.isin(phi, sweep.phi[:, 0]))


SKETCH = """
name = "sketch"
links = [{ name = "1", length = "a" }, { name = "2", length = "b" }, { name = "3", length = "c" }]
joints = [
  { name = "O", type = "R", links = ["0", "1"], at = [0.0, 0.0] },
  { name = "A", type = "R", links = ["1", "2"], at = [0.05, 0.0866] },
  { name = "B", type = "R", links = ["2", "3"], at = [0.33, 0.20] },
  { name = "C", type = "R", links = ["3", "0"], at = ["d", 0.0] },
]
[parameters]
a = 0.1
b = 0.3
c = 0.25
d = 0.3
[input]
joint = "O"
drawn_at = 60.0
"""


@pytest.mark.parametrize("backend", BACKENDS)
def test_every_invalid_design_gets_its_reason(tmp_path, backend):
    """Designs that cannot be assembled, are drawn singular, or have undefined coordinates are
    reported with a reason, and the batch goes on with the others."""
    model = tmp_path / "sketch.toml"
    model.write_text(SKETCH)
    # 0: fine; 1: too short to close; 2: the coupler and the rocker in line when drawn (B on the far
    # side: b + c = |AC|); 3: fine again
    ac = math.dist((0.05, 0.0866), (0.3, 0.0))
    motion = design_batch(model, {"b": [0.3, 0.01, ac - 0.1, 0.28], "c": [0.25, 0.01, 0.1, 0.26]},
                          backend=backend).solve(
        np.radians(np.arange(0, 360, 30.0)))
    assert motion.ok.tolist() == [True, False, False, True]
    assert "cannot be assembled" in motion.reasons[1]
    assert "singular" in motion.reasons[2] or "cannot be assembled" in motion.reasons[2]
    assert motion.reasons[0] is None and motion.valid[0].all() and motion.valid[3].all()
    assert np.isnan(motion.xy[1]).all() and not motion.valid[1].any()
    # a coupler of zero length leaves the coupler point M (on A→B) undefined
    bad = design_batch("models/fourbar_design.toml", {"b": [0.3, 0.0]}, backend=backend)
    got = bad.solve(np.radians([0.0, 90.0]))
    assert got.ok.tolist() == [True, False] and "undefined coordinates" in got.reasons[1]


SLIDER_CRANK = """
name = "slider_crank_design"
links = [{ name = "1" }, { name = "2" }, { name = "3" }]
joints = [
  { name = "O", type = "R", links = ["0", "1"], at = [0.0, 0.0] },
  { name = "A", type = "R", links = ["1", "2"], at = { from = "O", length = "r", angle = "t0" } },
  { name = "B", type = "R", links = ["2", "3"], at = { from = "A", length = "l", angle = "beta" } },
  { name = "Bp", type = "P", links = ["0", "3"], at = { from = "B", length = 0.0, angle = 0.0 }, guide = "g" },
]
[parameters]
r = 0.1
l = 0.3
t0 = 40.0
beta = -10.0
g = 0.0
[input]
joint = "O"
"""


def _closure(motion, names, pairs, lines=()):
    """Largest error of the distances between point pairs (drawn lengths) and of points on lines."""
    worst = 0.0
    for d in np.flatnonzero(motion.ok):
        v = motion.valid[d]
        xy = motion.xy[d, v]
        for p, q, length in pairs:
            dist = np.hypot(*(xy[:, names.index(p)] - xy[:, names.index(q)]).T)
            worst = max(worst, float(np.abs(dist - length[d]).max(initial=0.0)))
        for p, origin, u in lines:
            rel = xy[:, names.index(p)] - origin[d]
            worst = max(worst, float(np.abs(rel[:, 0] * u[d][1] - rel[:, 1] * u[d][0]).max(initial=0.0)))
    return worst


@pytest.mark.parametrize("backend", BACKENDS)
@settings(max_examples=3, deadline=None)
@given(seed=st.integers(0, 2 ** 31 - 1))
def test_loop_closure_over_random_four_bars(seed, backend):
    rng = np.random.default_rng(seed)
    D = 10
    vals = {"a": rng.uniform(0.02, 0.2, D), "b": rng.uniform(0.1, 0.4, D), "d": rng.uniform(0.1, 0.4, D),
            "theta0": rng.uniform(0, 360, D), "beta": rng.uniform(-180, 180, D)}
    batch = design_batch("models/fourbar_design.toml", vals, backend=backend)
    motion = batch.solve(np.radians(np.arange(0, 360, 20.0)), exact_limits=False)
    g = batch.geometry.at
    length = lambda p, q: np.hypot(*(g[p] - g[q]))  # noqa: E731
    names = motion.points
    err = _closure(motion, names, [("O", "A", length("O", "A")), ("A", "B", length("A", "B")),
                                   ("B", "C", length("B", "C")), ("C", "O", length("C", "O"))])
    assert err < 1e-12
    assert motion.ok.all() or all(r for r in np.array(motion.reasons, object)[~motion.ok])


@pytest.fixture(scope="module")
def slider_crank_model(tmp_path_factory):
    model = tmp_path_factory.mktemp("sc") / "slider_crank.toml"
    model.write_text(SLIDER_CRANK)
    return model


@pytest.mark.parametrize("backend", BACKENDS)
@settings(max_examples=3, deadline=None)
@given(seed=st.integers(0, 2 ** 31 - 1))
def test_loop_closure_over_random_slider_cranks(slider_crank_model, seed, backend):
    model = slider_crank_model
    rng = np.random.default_rng(seed)
    D = 10
    vals = {"r": rng.uniform(0.02, 0.2, D), "l": rng.uniform(0.1, 0.4, D), "t0": rng.uniform(0, 360, D),
            "beta": rng.uniform(-60, 60, D), "g": rng.uniform(-30, 30, D)}
    batch = design_batch(model, vals, backend=backend)
    motion = batch.solve(np.radians(np.arange(0, 360, 20.0)), exact_limits=False)
    g = batch.geometry
    names = motion.points
    err = _closure(motion, names, [("O", "A", np.hypot(*g.at["A"])), ("A", "B", np.hypot(*(g.at["A"] - g.at["B"])))],
                   [("B", g.at["Bp"].T, g.guide["Bp"].T)])
    assert err < 1e-12
    assert motion.valid[motion.ok].sum() > 0


def test_study_table_and_errors(tmp_path, capsys):
    out = tmp_path / "summary.csv"
    table = tmp_path / "v.csv"
    table.write_text("variant,l3,phi30,phi40\nA,1.2,1.9,3.5\nB,1.2,4.7,5.7\n")
    assert main(["study", SEED002, "--variants", str(table), "-o", str(out), "--no-progress"]) == 0
    rows = list(csv.DictReader(out.read_text().splitlines()))
    assert [(r["variant"], r["l1"], r["phi30"], r["assembles"], r["full_turn"]) for r in rows] == \
        [("A", "0.5", "1.9", "yes", "yes"), ("B", "0.5", "4.7", "yes", "no")]
    assert abs(float(rows[1]["limit_hi[deg]"]) - math.degrees(1.7999124165244385)) < 1e-9
    table.write_text("variant,l3,phi30\nA,1.2,x\n")
    assert main(["study", SEED002, "--variants", str(table), "--no-progress"]) == 2
    assert "line 2, column 'phi30'" in capsys.readouterr().err
    table.write_text("variant,l9\nA,1.2\n")
    assert main(["study", SEED002, "--variants", str(table), "--no-progress"]) == 2
    assert "l9" in capsys.readouterr().err


def test_with_dimensions_equals_a_new_engine():
    base = mbplanar.Engine(mbplanar.read_model(SEED002))
    variant = mbplanar.read_model("models/crank_slider_rocker_locking.toml")
    new = with_dimensions(base, variant)
    assert mbplanar.check(new).as_dict() == mbplanar.check(mbplanar.Engine(variant)).as_dict()
    again = base.with_dimensions(variant)  # the Engine method, the same function
    assert again.topology is base.topology and again.mech.joints["B"].at == new.mech.joints["B"].at
    phi = np.linspace(0.0, 1.5, 7)
    assert np.array_equal(mbplanar.analyse(again, phi).xy, mbplanar.analyse(mbplanar.Engine(variant), phi).xy)
    with pytest.raises(mbplanar.errors.ModelError, match="re-dimensioning keeps the structure"):
        base.with_dimensions(mbplanar.read_model("models/fourbar.toml"))


def test_dask_two_workers_equal_the_serial_run(tmp_path, capsys):
    """LocalClusters of two worker processes: `mbplanar study --workers 2` prints the serial run's JSON,
    and the design batch through a Client equals the serial one, bit for bit."""
    pytest.importorskip("distributed")
    from mbplanar.study.cluster import close, local_client

    table = tmp_path / "v.csv"
    table.write_text("".join(line for k, line in enumerate(open(VARIANTS)) if k < 3 or k in (6, 11)))
    args = ["study", SEED002, "--variants", str(table), "--json", "--no-progress", "--chunk", "1"]
    assert main(args) == 0
    serial = capsys.readouterr().out
    assert main(args + ["--workers", "2"]) == 0
    assert capsys.readouterr().out == serial
    assert len(json.loads(serial)["designs"]) == 2

    rows = read_variants(VARIANTS, mbplanar.study.load_template(SEED002)).take(np.array([3, 5, 6, 8]))
    phi = np.radians(np.arange(0, 360, 30.0))
    kin = solve_designs(SEED002, rows, phi, chunk=2)
    client = local_client(2)
    try:
        assert len(client.scheduler_info()["workers"]) == 2
        kin2 = solve_designs(SEED002, rows, phi, chunk=2, client=client)
    finally:
        close(client)
    for name in ("valid", "ok", "angle", "xy", "vq", "aq"):
        assert np.array_equal(getattr(kin, name), getattr(kin2, name), equal_nan=True)
    assert [(lim.design, lim.phi, lim.kind) for lim in kin.limits] == [(lim.design, lim.phi, lim.kind) for lim in kin2.limits]


HEAVY = open("models/fourbar_design.toml").read().replace(
    '''  { name = "1" },                 # crank OA
  { name = "2" },                 # coupler AB
  { name = "3" },                 # rocker CB''',
    '''  { name = "1", mass = 0.5, inertia = 0.001, centre = "S1" },
  { name = "2", mass = "m2", inertia = 0.004, centre = "M" },
  { name = "3", mass = 1.5, inertia = 0.008, centre = "S3" },''').replace(
    '''points = [''', '''points = [
  { name = "S1", link = "1", along = ["O", "A"], fraction = 0.5 },
  { name = "S3", link = "3", along = ["C", "B"], fraction = 0.4 },''').replace(
    "[parameters]", "[gravity]\ng = 9.81\n\n[parameters]\nm2 = 1.0") + "omega = 10.0\n"


def test_forces_in_the_summary_balance_over_a_turn(tmp_path):
    """With masses, gravity and a constant input speed but no working load, the drive does no net work
    over a full turn (kinetic and potential energy come back): the mean balancing moment over the
    samples of a turn vanishes against its swing, while the reactions do not."""
    model = tmp_path / "heavy.toml"
    model.write_text(HEAVY)
    table = tmp_path / "v.csv"
    table.write_text("variant,m2,a\nlight,0.5,0.08\nheavy,2.0,0.1\n")
    study = run_study(model, table, samples=48)
    for d in study.designs:
        assert d.full_turn and d.max_reaction > 0 and d.max_reaction_joint in "OABC"
        engine = with_dimensions(mbplanar.Engine(mbplanar.read_model(model)),
                                 mbplanar.parse_model(study_template(model).bind(d.parameters)))
        motion = mbplanar.analyse(engine, d.samples_phi * math.pi / 180)
        swing = np.ptp(next(iter(mbplanar.kinetostatics(engine, motion).balancing.values())))
        assert abs(d.mean_balancing) < 1e-9 * swing
    assert study.designs[1].max_reaction > study.designs[0].max_reaction


def study_template(path):
    return mbplanar.study.load_template(path)


LOADED = HEAVY.replace("[gravity]", '''loads = [
  { name = "resistance", type = "moment", link = "3", moment = -5.0 },
  { name = "push", type = "force", link = "2", force = [3.0, -2.0], at = "M" },
]

[gravity]''').replace('mass = 1.5, inertia = 0.008', 'mass = 1.5, inertia = "i3"').replace(
    "m2 = 1.0", "m2 = 1.0\ni3 = 0.008")


@pytest.mark.parametrize("backend", BACKENDS)
def test_design_kinetostatics_equals_each_designs_own(tmp_path, backend):
    """Reactions and balancing moments of a design batch (all pairs in one solve; masses, inertias
    and dimensions per design) against each design's own engine's `kinetostatics`, to 1e-12 relative
    to the largest reaction."""
    from mbplanar.study.forces import design_kinetostatics
    from mbplanar.study.variants import variants_from

    model = tmp_path / "loaded.toml"
    model.write_text(LOADED)
    template = study_template(model)
    vals = {"a": [0.08, 0.1, 0.09], "m2": [0.5, 2.0, 1.0], "i3": [0.002, 0.01, 0.008], "h": [0.0, 0.03, -0.02]}
    variants = variants_from(template, vals)
    batch = design_batch(template, variants, backend=backend)
    phi = np.radians(np.arange(0.0, 360.0, 15.0))
    motion = batch.solve(phi)
    got = design_kinetostatics(batch, motion, template, variants)
    base = mbplanar.Engine(mbplanar.read_model(model))
    for d in range(3):
        engine = base.with_dimensions(mbplanar.parse_model(template.bind(variants.row(d))))
        ref = mbplanar.kinetostatics(engine, mbplanar.analyse(engine, phi))
        scale = max(np.abs(r.magnitude).max() for r in ref.reactions.values())
        for k, j in enumerate(got.joints):
            r = ref.reactions[j]
            assert np.abs(got.reactions[d, :, k, 0] - r.fx).max() < 1e-12 * scale
            assert np.abs(got.reactions[d, :, k, 1] - r.fy).max() < 1e-12 * scale
        assert np.abs(got.balancing[d] - ref.balancing["O"]).max() < 1e-12 * scale
    largest, where = got.largest()
    assert where[0] in "OABC" and largest[1] > largest[0] > 0
    assert np.allclose(got.mean_balancing(), np.nanmean(got.balancing, axis=1), rtol=0, atol=1e-12)


def test_study_forces_through_the_batch_equal_the_serial_reference(tmp_path):
    """A study's largest reaction and mean balancing moment, all designs in one kinetostatic solve,
    equal the serial reference's (each design's own `kinetostatics`)."""
    model = tmp_path / "loaded.toml"
    model.write_text(LOADED)
    table = tmp_path / "v.csv"
    # D locks (a crank longer than Grashof allows): its samples stop at its limits
    table.write_text("variant,m2,a,i3\nA,0.5,0.08,0.002\nB,2.0,0.1,0.01\nC,1.0,0.12,0.005\nD,1.0,0.25,0.004\n")
    batch, serial = (run_study(model, table, samples=24, method=m) for m in ("batch", "serial"))
    assert [d.full_turn for d in batch.designs] == [True, True, True, False]
    for x, y in zip(batch.designs, serial.designs):
        assert x.max_reaction_joint == y.max_reaction_joint and abs(x.max_reaction / y.max_reaction - 1) < 1e-12
        assert abs(x.mean_balancing - y.mean_balancing) < 1e-12 * y.max_reaction


def test_progress_bar_only_when_asked_or_on_a_terminal(tmp_path, capsys):
    """stderr is not a terminal under pytest: no bar by default; `--progress` shows one (tqdm's, or a
    counter), with the number of designs."""
    table = tmp_path / "v.csv"
    table.write_text("variant,l3\nA,1.2\nB,1.1\nC,1.0\n")
    assert main(["study", SEED002, "--variants", str(table), "--chunk", "1"]) == 0
    assert capsys.readouterr().err == ""
    assert main(["study", SEED002, "--variants", str(table), "--chunk", "1", "--progress"]) == 0
    assert "3/3" in capsys.readouterr().err


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_batch_computes_only_the_points_asked_for(backend):
    """`points=`, `links=` and `accelerations=False` leave the rest out and change nothing in what is
    computed; an unknown point or link is refused."""
    vals = {"a": [0.08, 0.1, 0.12], "h": [0.0, 0.02, -0.03]}
    phi = np.radians(np.arange(0.0, 360.0, 10.0))
    full = design_batch("models/fourbar_design.toml", vals, backend=backend).solve(phi)
    some = design_batch("models/fourbar_design.toml", vals, backend=backend).solve(
        phi, points=["M", "B"], accelerations=False)
    assert some.points == ["M", "B"] and some.eq is None and some.aq is None
    cols = [full.point("M"), full.point("B")]
    assert np.array_equal(some.xy, full.xy[:, :, cols]) and np.array_equal(some.vq, full.vq[:, :, cols])
    assert np.array_equal(some.angle, full.angle) and np.array_equal(some.valid, full.valid)
    with pytest.raises(ValueError, match="Q: neither a joint nor a point"):
        design_batch("models/fourbar_design.toml", vals, backend=backend).solve(phi, points=["Q"])
    # `links=` likewise: the links asked for, in their order, or none
    two = design_batch("models/fourbar_design.toml", vals, backend=backend).solve(phi, links=["3", "1"])
    k = [full.link("3"), full.link("1")]
    assert two.links == ["3", "1"] and two.angle.shape == (3, len(phi), 2)
    for name in ("angle", "wq", "eq"):
        assert np.array_equal(getattr(two, name), getattr(full, name)[:, :, k])
    assert np.array_equal(two.xy, full.xy) and np.array_equal(two.aq, full.aq)
    none = design_batch("models/fourbar_design.toml", vals, backend=backend).solve(phi, points=["M"], links=[],
                                                                                   accelerations=False)
    assert none.angle.shape == (3, len(phi), 0) and np.array_equal(none.vq, some.vq[:, :, :1])
    with pytest.raises(ValueError, match="7: not a link"):
        design_batch("models/fourbar_design.toml", vals, backend=backend).solve(phi, links=["7"])


@pytest.mark.skipif(__import__("importlib").util.find_spec("numba") is None, reason="numba not installed")
def test_compiled_sweep_followed_position_by_position_equals_the_march():
    """The compiled batch follows an ordered sweep position by position from each drawn pose; the same
    positions shuffled take the march and its interpolant: both equal to 1e-12, and a design that locks
    inside the sweep still gets its limits."""
    vals = {"a": [0.08, 0.1, 0.12, 0.25], "b": [0.3, 0.3, 0.3, 0.2], "theta0": [10.0, 200.0, 359.5, 60.0],
            "h": [0.0, 0.02, -0.03, 0.01]}
    phi = np.radians(np.arange(0.0, 360.0, 1.0))
    order = np.random.default_rng(3).permutation(len(phi))
    followed = design_batch("models/fourbar_design.toml", vals, backend="numba").solve(phi)
    marched = design_batch("models/fourbar_design.toml", vals, backend="numba").solve(np.tile(phi[order], (4, 1)))
    back = np.argsort(order)
    assert np.array_equal(followed.valid, marched.valid[:, back]) and followed.valid[:3].all()
    assert not followed.valid[3].all() and followed.limits_of(3)
    for name in ("angle", "wq", "eq", "xy", "vq", "aq"):
        a, b = getattr(followed, name), getattr(marched, name)[:, back]
        assert np.nanmax(np.abs(a - b) / (1 + np.abs(b))) < 1e-12, name
    assert [(lim.design, lim.direction) for lim in followed.limits] == \
        [(lim.design, lim.direction) for lim in marched.limits]
    assert all(abs(a.phi - b.phi) < 1e-12 for a, b in zip(followed.limits, marched.limits))


@pytest.mark.skipif(__import__("importlib").util.find_spec("numba") is None, reason="numba not installed")
def test_compiled_followed_sweep_of_slider_cranks_equals_numpy(slider_crank_model):
    """Slider-cranks (a guide among the joints) followed at 2° steps by the compiled batch equal numpy's
    batch to 1e-12, the one whose coupler is shorter than its crank stopping at the same limits."""
    vals = {"r": [0.1, 0.05, 0.2], "l": [0.3, 0.25, 0.15], "t0": [40.0, 300.0, 80.0], "beta": [-10.0, 5.0, -60.0],
            "g": [0.0, 12.0, -8.0]}
    phi = np.radians(np.arange(-180.0, 180.0, 2.0))
    fast = design_batch(slider_crank_model, vals, backend="numba").solve(phi)
    ref = design_batch(slider_crank_model, vals, backend="numpy").solve(phi)
    assert np.array_equal(fast.valid, ref.valid) and fast.valid[:2].all() and not fast.valid[2].all()
    for name in ("angle", "wq", "eq", "xy", "vq", "aq"):
        a, b = getattr(fast, name), getattr(ref, name)
        assert np.nanmax(np.abs(a - b) / (1 + np.abs(b))) < 1e-12, name
    assert [(lim.design, lim.direction) for lim in fast.limits] == [(lim.design, lim.direction) for lim in ref.limits]
    assert all(abs(a.phi - b.phi) < 1e-12 for a, b in zip(fast.limits, ref.limits))


def test_numpy_batch_second_pass_ends_where_the_full_newton_does(monkeypatch):
    """The numpy batch corrects a chunk by one Newton step and one evaluation, then only the pairs not at
    the rounding floor by the engine's full iteration: the same as the full iteration over the whole
    chunk (the former one-pass correction), to the rounding, with the second pass taken."""
    from mbplanar.study import batch as B

    vals = {"a": [0.06, 0.08, 0.1, 0.12], "b": [0.3, 0.26, 0.33, 0.3], "theta0": [10.0, 200.0, 100.0, 300.0],
            "beta": [20.0, 60.0, 340.0, 45.0]}
    phi = np.radians(np.arange(0.0, 360.0, 1.0))
    second = []
    correct, bound = B.DesignBatch._correct, B.DesignBatch.bound

    def spy_correct(self, *args):
        self._in_correct = True
        try:
            return correct(self, *args)
        finally:
            self._in_correct = False

    def spy_bound(self, index, tol=None):
        if getattr(self, "_in_correct", False) and tol is None:
            second.append(len(index))
        return bound(self, index, tol)

    monkeypatch.setattr(B.DesignBatch, "_correct", spy_correct)
    monkeypatch.setattr(B.DesignBatch, "bound", spy_bound)
    two = design_batch("models/fourbar_design.toml", vals).solve(phi)
    assert second and 0 < sum(second) < two.valid.sum() / 4  # a few pairs took the second pass
    monkeypatch.setattr(B, "_one_step", lambda tol: tol)  # the engine's full iteration over every pair
    one = design_batch("models/fourbar_design.toml", vals).solve(phi)
    assert np.array_equal(two.valid, one.valid) and two.valid.sum() > 800 and two.limits  # two designs lock
    for name in ("angle", "wq", "eq", "xy", "vq", "aq"):
        a, b = getattr(two, name), getattr(one, name)
        assert np.array_equal(np.isnan(a), np.isnan(b)), name
        assert np.mean(a[two.valid] == b[two.valid]) > 0.99, name  # the pairs at the floor: the same bits
        # the others to the rounding (their rates, near the limits, as amplified as the Jacobian's inverse)
        assert np.nanmax(np.abs(a - b) / (1 + np.abs(b))) < (1e-14 if name in ("angle", "xy") else 1e-12), name
