"""Design batches of the higher-pair models in the compiled design kernel (`backends._numba_design`)
against numpy's: every bundled model with a gear, a rack, a cam or a slot, with `[parameters]` in a
higher pair's own numbers (a module, a radius, a curve's centre, a follower's point) and the joints that
move with them, solved by both backends at the same input values. numpy solves each design by its own
engine, made from its own table; the kernel takes every design's pairs from its table in one call. The
positions, the velocity and acceleration analogues agree to 1e-12 of their size, the designs that cannot be
made (gears that cannot mesh, a roller off its cam, a pin off its slot) are reported with the same
reason. The study and the accuracy Monte Carlo run on the kernel (the seam's log says so) and agree."""

from __future__ import annotations

import logging
import math
import tomllib

import numpy as np
import pytest

import mbplanar
from conftest import MODELS

pytest.importorskip("numba")

from mbplanar.model._curves import Offset, shape  # noqa: E402
from mbplanar.study import design_batch  # noqa: E402


def _follower_height(rr: float) -> float:
    """The height (mm) of cam_follower's roller centre on the line x = 8 mm over the profile (the drawn
    cam angle 0) for a roller of radius `rr` (mm): where the profile's offset by `rr` crosses that line."""
    from scipy.optimize import brentq
    mech = mbplanar.read_model(MODELS / "cam_follower.toml")
    path = Offset(shape(mech.higher["K"].curve), 1e-3 * rr)
    u0 = path.closest(np.array([0.008, 0.04935585071701227]))[0] if rr == 10.0 else None
    u0 = u0 if u0 is not None else path.closest(np.array([0.008, 0.0394 + 1e-3 * rr]))[0]
    u = brentq(lambda t: path.point(np.array([t]))[0, 0] - 0.008, u0 - 0.05, u0 + 0.05, xtol=1e-15)
    return 1e3 * float(path.point(np.array([u]))[1, 0])


def _case(name: str):
    """(table with [parameters], variants {name: (D,)}, the index of the design that cannot be made): a
    higher pair's numbers varied with the joints that follow them."""
    text = (MODELS / f"{name.replace('_end', '')}.toml").read_text(encoding="utf-8")
    if name == "geared_five_bar":   # the module, and the crank EB's pivot at the centre distance 24·m
        text = (text.replace("module = 0.005", 'module = "m"').replace("at = [0.12, 0.0]", 'at = ["e", 0.0]')
                .replace("at = [0.12, 0.05]", 'at = ["e", 0.05]'))
        m = np.array([0.005, 0.0052, 0.0049, 0.0051])
        return text, {"m": 0.005, "e": 0.12}, {"m": m, "e": np.array([0.12, 0.1248, 0.1176, 0.12])}, 3
    if name == "planetary":         # the module: the planet's axis at 33·m, the pitch points at 10·m and 56·m
        text = (text.replace("module = 0.002", 'module = "m"').replace("[0.066, 0.0]", '["a", 0.0]')
                .replace("at = [0.02, 0.0]", 'at = ["p", 0.0]').replace("at = [0.112, 0.0]", 'at = ["q", 0.0]'))
        m = np.array([0.002, 0.0025, 0.0015, 0.002])
        return text, {"m": 0.002, "a": 0.066, "p": 0.02, "q": 0.112}, {"m": m, "a": np.append(33 * m[:3], 0.07),
                                                                      "p": 10 * m, "q": 56 * m}, 3
    if name == "rack_pinion":       # the module: the pinion's centre 12.5·m above the pitch line
        text = text.replace("module = 0.002", 'module = "m"').replace("at = [0.2, 0.05]", 'at = [0.2, "y"]')
        m = np.array([0.002, 0.0024, 0.0016, 0.002])
        return text, {"m": 0.002, "y": 0.05}, {"m": m, "y": np.append(0.025 + 12.5 * m[:3], 0.06)}, 3
    if name == "cam_eccentric":     # the eccentric's centre and radius, the roller's radius (52 mm apart)
        text = (text.replace("centre = [15.0, 0.0], radius = 40.0", 'centre = ["ex", 0.0], radius = "R"')
                .replace('radius = 12.0', 'radius = "rr"').replace("at = [0.0, 49.78955713801841]", 'at = [0.0, "by"]'))
        ex, big = np.array([15.0, 14.0, 16.0, 15.0]), np.array([40.0, 41.0, 39.0, 41.0])
        by = np.sqrt(52.0 ** 2 - ex ** 2)
        return text, {"ex": 15.0, "R": 40.0, "rr": 12.0, "by": float(by[0])}, {
            "ex": ex, "R": big, "rr": np.array([12.0, 11.0, 13.0, 12.0]), "by": by}, 3
    if name == "cam_follower":      # the roller's radius, its centre on the offset profile (x = 8 mm)
        text = (text.replace('radius = 10.0', 'radius = "rr"').replace("49.35585071701227]", '"by"]')
                .replace('file = "cam_roller_profile.csv"', f'file = "{MODELS / "cam_roller_profile.csv"}"'))
        rr = np.array([10.0, 9.0, 11.0, 10.0])
        by = np.array([_follower_height(r) for r in rr[:3]] + [50.0])
        return text, {"rr": 10.0, "by": float(by[0])}, {"rr": rr, "by": by}, 3
    if name in ("slot_arc", "slot_arc_end"):   # the slot's centre, the rocker's point there (an arc of 20°:
        text = text.replace("[0.25, 0.31]", '["cx", "cy"]')           # the pin stops at its ends)
        text = text.replace("arc = [190.0, 260.0]", "arc = [215.0, 235.0]") if name.endswith("end") else text
        return text, {"cx": 0.25, "cy": 0.31}, {"cx": np.array([0.25, 0.24, 0.26, 0.25]),
                                               "cy": np.array([0.31, 0.30, 0.32, 0.31])}, None
    if name == "scotch_yoke":       # the pin's place on the crank (on the slot's line x = 0.05 of the yoke)
        text = text.replace("at = [0.05, 0.0] }", 'at = [0.05, "ay"] }')
        return text, {"ay": 0.0}, {"ay": np.array([0.0, 0.01, -0.02, 0.1])}, 3
    if name == "shaper_geared":     # the last pair's module: the two shafts and the motor 90·m further
        text = (text.replace('module = 0.004', 'module = "m"').replace("at = [-0.36, 0.0]", 'at = ["x", 0.0]')
                .replace("at = [-0.36, 0.135]", 'at = ["x", 0.135]')
                .replace("at = [-0.274, 0.135]", 'at = ["xm", 0.135]'))
        m = np.array([0.004, 0.0041, 0.0039, 0.004])
        x = np.append(-90 * m[:3], -0.35)
        return text, {"m": 0.004, "x": -0.36, "xm": -0.274}, {"m": m, "x": x, "xm": x + 0.086}, 3
    raise KeyError(name)


MODELS_WITH_PAIRS = ["geared_five_bar", "planetary", "rack_pinion", "cam_eccentric", "cam_follower", "slot_arc",
                     "slot_arc_end", "scotch_yoke", "shaper_geared"]


def _largest(a) -> float:
    return max(1e-300, float(np.nanmax(np.abs(a))))


@pytest.mark.parametrize("name", MODELS_WITH_PAIRS)
def test_a_design_batch_of_a_higher_pair_model_on_numba_equals_numpy(name, caplog):
    """Four designs (one that cannot be made, but for the slot) over a turn of the input: the kernel's
    positions, ω_q, ε_q and the points' velocity and acceleration analogues equal numpy's to 1e-12 of
    their size; the same designs fail, with the same reason (numpy's own engine's); the same motion
    limits (a pin at the end of its slot), located to 1e-9 rad."""
    text, defaults, values, bad = _case(name)
    data = dict(tomllib.loads(text), parameters=defaults)
    ref, fast = design_batch(data, values), design_batch(data, values, backend="numba")
    phi = ref.geometry.phi0[:, None] + np.linspace(-math.pi, math.pi, 73)
    caplog.set_level(logging.DEBUG, logger="mbplanar.backends")
    b = fast.solve(phi)
    assert f"design of {phi.size}: numba\n" in caplog.text
    a = ref.solve(phi)
    assert a.reasons == b.reasons and a.ok.tolist() == b.ok.tolist()
    good = [d for d in range(len(a.ok)) if d != bad]
    assert a.ok[good].all() and (bad is None or "joint" in a.reasons[bad])
    np.testing.assert_array_equal(b.valid, a.valid)
    assert a.valid[good].sum() >= (20 if name.endswith("end") else 70) * len(good)
    assert len(a.limits) == (8 if name.endswith("end") else 0)
    size = ref.engine.size
    np.testing.assert_allclose(b.xy, a.xy, rtol=0, atol=1e-12 * size)
    np.testing.assert_allclose(b.angle, a.angle, rtol=0, atol=1e-12 * _largest(a.angle))  # (a motor: ~20 turns)
    for field in ("wq", "eq", "vq", "aq"):
        np.testing.assert_allclose(getattr(b, field), getattr(a, field), rtol=0,
                                   atol=1e-12 * _largest(getattr(a, field)), err_msg=field)
    ends = [sorted(m.limits, key=lambda lim: (lim.design, lim.direction)) for m in (a, b)]
    assert [(lim.design, lim.direction, lim.kind) for lim in ends[0]] == [(lim.design, lim.direction, lim.kind)
                                                                          for lim in ends[1]]
    for x, y in zip(*ends):
        assert x.phi == pytest.approx(y.phi, abs=1e-9)


def test_a_study_of_a_higher_pair_model_runs_on_numba_and_agrees(caplog):
    """`mbplanar study`'s run (`run_study`) of the geared five-bar's module, numba against numpy: the design
    batch is the kernel's (the seam's log says so), every summary the same (range, full turn, the coupler
    point's path extent to 1e-12 of the size), the design that cannot mesh failed with numpy's reason."""
    from mbplanar.study import run_study
    from mbplanar.study.variants import variants_from
    from mbplanar.study.run import load_template
    text, defaults, values, bad = _case("geared_five_bar")
    template = load_template(dict(tomllib.loads(text), parameters=defaults))
    variants = variants_from(template, values)
    caplog.set_level(logging.DEBUG, logger="mbplanar.backends")
    fast = run_study(template, variants, points=["P"], samples=90, backend="numba")
    assert "design of 8: numba\n" in caplog.text
    ref = run_study(template, variants, points=["P"], samples=90)
    assert fast.counts == ref.counts == {"designs": 4, "assembled": 3, "full_turn": 3, "locking": 0}
    for x, y in zip(fast.designs, ref.designs):
        assert x.assembles == y.assembles and x.reason == y.reason and x.full_turn == y.full_turn
        if x.assembles:
            np.testing.assert_allclose(x.samples_phi, y.samples_phi, rtol=0, atol=1e-12)
            np.testing.assert_allclose(x.samples["P"], y.samples["P"], rtol=0, atol=1e-12 * 0.2)
            assert x.transmission_min_deg == pytest.approx(y.transmission_min_deg, abs=1e-9)
    assert "cannot mesh" in fast.designs[bad].reason


def test_the_monte_carlo_of_a_higher_pair_model_runs_on_numba_and_agrees(caplog):
    """The accuracy Monte Carlo of the eccentric cam (its roller's radius, the eccentric's centre and
    radius, the arm's pivot): 600 made designs in chunks of 150 through the compiled design kernel (the
    seam's log says so), each with its own pairs (placed where its cam sits), equal to numpy's: mean,
    σ, lowest and highest value of every output at every position to 1e-12 of the output's size."""
    from mbplanar.accuracy import DesignSpace, Tolerance, catalogue, monte_carlo, resolve_outputs
    from mbplanar.accuracy.run import cycle, load
    names = ["joints.K.radius", "joints.K.profile.x", "joints.K.profile.radius", "joints.C.y"]
    tols = [Tolerance(n, -0.05, 0.05) for n in names[:3]] + [Tolerance(names[3], sigma=0.02)]
    got = {}
    for backend in ("numba", "numpy"):
        template, raw, engine = load(MODELS / "cam_eccentric.toml", backend)
        space = DesignSpace(engine, raw, template, names)
        assert set(names) <= set(catalogue(engine, raw, template))
        phi = cycle(engine, 24)[0]
        outputs = resolve_outputs(engine.mech, ["arm", "M"])
        caplog.clear()
        caplog.set_level(logging.DEBUG, logger="mbplanar.backends")
        got[backend] = monte_carlo(space, tols, phi, outputs, samples=600, seed=3, chunk=150)
        assert ("design of 3600: numba\n" in caplog.text) == (backend == "numba")
    a, b = got["numpy"], got["numba"]
    assert a.count == b.count == 600
    size = np.abs(a.mean).max(axis=0)   # (per output)
    for field in ("mean", "std", "low", "high"):
        gap = np.abs(getattr(b, field) - getattr(a, field)) / size
        assert gap.max() <= 1e-12, (field, gap.max())


def test_a_design_batch_asked_for_links_only_on_numba():
    """No point asked for (a Monte Carlo of a link's angle): the kernel writes the links' angles and
    rates alone, equal to numpy's."""
    text, defaults, values, bad = _case("cam_eccentric")
    data = dict(tomllib.loads(text), parameters=defaults)
    got = [design_batch(data, values, backend=b).solve(np.radians(np.arange(0.0, 360.0, 10.0)), points=[],
                                                        links=["arm"], accelerations=False)
           for b in ("numpy", "numba")]
    assert got[1].xy.shape == (4, 36, 0, 2) and got[1].ok.tolist() == got[0].ok.tolist() == [True] * 3 + [False]
    np.testing.assert_allclose(got[1].angle, got[0].angle, rtol=0, atol=1e-12)
    np.testing.assert_allclose(got[1].wq, got[0].wq, rtol=0, atol=1e-12 * np.nanmax(np.abs(got[0].wq)))


def test_the_design_kernel_takes_every_model_with_the_types_mbplanar_compile_builds():
    """The request of a higher-pair model's design batch (a study's, a made design's) has the types of
    `mbplanar compile`'s sample (a four-bar, `study.batch.compile_sample`): one compiled kernel serves
    every model, none compiles in a process after the install step (a read-only array, say, would be
    another type to numba)."""
    from numba import typeof
    from mbplanar.study.batch import _SAMPLE
    from mbplanar.accuracy import DesignSpace
    from mbplanar.accuracy.made import made_geometry
    from mbplanar.accuracy.run import load
    from mbplanar.study.batch import DesignBatch

    def request_type(batch):
        phi = batch.geometry.phi0[:, None] + np.linspace(0.0, 0.5, 3)
        job = batch._design_request(phi, list(batch.points), True, list(batch.engine.links))
        return typeof(job.tables), typeof(job.x)

    sample = request_type(design_batch(tomllib.loads(_SAMPLE), {"a": np.linspace(0.09, 0.11, 4)}, backend="numba"))
    text, defaults, values, bad = _case("cam_follower")
    assert request_type(design_batch(dict(tomllib.loads(text), parameters=defaults), values)) == sample
    one = {k: v[:1] for k, v in values.items()}
    assert request_type(design_batch(dict(tomllib.loads(text), parameters=defaults), one)) == sample
    template, raw, engine = load(MODELS / "cam_eccentric.toml")
    space = DesignSpace(engine, raw, template, ["joints.K.radius", "joints.K.profile.x"])
    made = made_geometry(engine, space.sided(np.zeros((3, 2))))
    assert request_type(DesignBatch(engine, made)) == sample
