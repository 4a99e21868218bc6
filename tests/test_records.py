"""Every result is a plain frozen record (as scipy's OptimizeResult): a frozen dataclass of data, with no
engine, solver or callback inside, whose sub-results are records too; `dataclasses.replace` makes a new
one and `dataclasses.asdict` takes it apart, and nothing is computed when a field is read."""

import dataclasses
import math
import pathlib
import tomllib

import numpy as np
import pytest

import mbplanar
from mbplanar.engine import Engine
from mbplanar.kinematics import _motion

ROOT = pathlib.Path(__file__).resolve().parent.parent
MODELS = ROOT / "models"


def _engine(name, backend="numpy"):
    return mbplanar.Engine(mbplanar.read_model(MODELS / f"{name}.toml"), backend=backend, threads=1)


def _results():
    """One of each result type, made through the public API (name → result)."""
    from mbplanar.analysis import check_region
    from mbplanar.cam import design, read_cam
    from mbplanar.forces import (FrictionSpec, PairFriction, balance, friction_kinetostatics, read_simulate, shaking,
                                 simulate_motion)
    from mbplanar.study import design_batch, run_study
    from mbplanar.study.forces import design_kinetostatics
    from mbplanar.study.run import load_template
    from mbplanar.synthesis import FunctionTask, synthesise_function

    loaded = _engine("fourbar_loaded")
    phi = loaded.phi_drawn[0] + np.linspace(0.0, 2 * math.pi, 24, endpoint=False)
    motion = mbplanar.analyse(loaded, phi)
    forces = mbplanar.kinetostatics(loaded, motion)
    shaper = _engine("shaper")
    out = {"Motion": motion, "Motion (positions only)": mbplanar.analyse(loaded, phi, rates=False),
           "Position": mbplanar.position(loaded, float(phi[3])), "Kinetostatics": forces,
           "Reaction": forces.reactions["A"], "Dynamics": mbplanar.machine_dynamics(shaper, steps=72),
           "CheckReport": mbplanar.check(_engine("crank_slider_rocker_locking")),
           "CheckReport (four-bar)": mbplanar.check(loaded),
           "RegionReport": check_region(_engine("five_bar"), samples=5),
           "Shaking": shaking(loaded, forces), "Balancing": balance(loaded, ["1"], steps=36),
           "FrictionResult": friction_kinetostatics(loaded, motion, FrictionSpec((PairFriction("A", 0.1, 0.01),))),
           "CamDesign": design(read_cam(MODELS / "shaper_cam.toml")),
           "FunctionResult": synthesise_function(FunctionTask("1/x", (1.0, 2.0), (30.0, 120.0), (60.0, 150.0), 3))}
    out["Trajectory"] = simulate_motion(loaded, read_simulate(loaded.mech, t=0.02, steps=3))
    table = MODELS / "crank_slider_rocker_variants.csv"
    batch = design_batch(MODELS / "crank_slider_rocker.toml", str(table))
    out["DesignMotion"] = batch.solve(np.radians(np.arange(0.0, 360.0, 30.0)))
    study = run_study(MODELS / "crank_slider_rocker.toml", table, samples=8)
    out["Study"], out["DesignSummary"] = study, next(d for d in study.designs if d.limits)
    from test_study import LOADED
    from mbplanar.study.variants import variants_from
    template = load_template(tomllib.loads(LOADED))
    variants = variants_from(template, {"m2": [0.5, 2.0], "i3": [0.002, 0.01]})
    b = design_batch(template, variants)
    out["DesignForces"] = design_kinetostatics(b, b.solve(np.radians(np.arange(0.0, 360.0, 30.0))), template,
                                               variants)
    from mbplanar.accuracy import accuracy
    from mbplanar.kinematics import contacts
    out["Accuracy"] = accuracy(MODELS / "fourbar.toml", samples=200, positions=12, seed=1)
    cam = _engine("cam_eccentric")
    cam_motion = mbplanar.analyse(cam, cam.phi_drawn[0] + np.linspace(0.0, 2 * math.pi, 12, endpoint=False))
    out["Contact"] = contacts(cam, cam_motion)["K"]
    out["Kinetostatics (higher pairs)"] = mbplanar.kinetostatics(cam, cam_motion)
    follower = mbplanar.read_model(MODELS / "cam_follower.toml")  # (spun 3× faster: its contact pulls)
    follower = dataclasses.replace(follower, inputs=[dataclasses.replace(i, omega=3 * i.omega) for i in follower.inputs])
    out["CheckReport (cam)"] = mbplanar.check(mbplanar.Engine(follower))
    return {k: v for k, v in out.items() if v is not None}


@pytest.fixture(scope="module")
def results():
    return _results()


def _records(value, path="result"):
    """Every dataclass instance reachable from `value` (itself included), with where it was found."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        yield path, value
        for f in dataclasses.fields(value):
            if not isinstance(getattr(value, f.name), mbplanar.Mechanism):  # (a model: its description, not a result)
                yield from _records(getattr(value, f.name), f"{path}.{f.name}")
    elif isinstance(value, dict):
        for k, v in value.items():
            yield from _records(v, f"{path}[{k!r}]")
    elif isinstance(value, (list, tuple)):
        for k, v in enumerate(value):
            yield from _records(v, f"{path}[{k}]")


def test_every_result_is_a_frozen_record_of_data(results):
    assert {"Motion", "Position", "Kinetostatics", "Dynamics", "CheckReport", "DesignMotion", "Study",
            "CamDesign", "FunctionResult"} <= set(results)
    for name, result in results.items():
        for where, record in _records(result, name):
            assert record.__dataclass_params__.frozen, where
            for f in dataclasses.fields(record):
                value = getattr(record, f.name)
                assert not isinstance(value, Engine) and not callable(value), f"{where}.{f.name}"
                assert not isinstance(value, dict) or f.name not in ("flywheel", "grashof"), f"{where}.{f.name}"
            with pytest.raises(dataclasses.FrozenInstanceError):
                setattr(record, dataclasses.fields(record)[0].name, None)


def test_replace_and_asdict_work_on_every_result(results):
    for name, result in results.items():
        first = dataclasses.fields(result)[0].name
        other = dataclasses.replace(result)
        assert other is not result and getattr(other, first) is getattr(result, first), name
        doc = dataclasses.asdict(result)
        assert set(doc) == {f.name for f in dataclasses.fields(result)}, name


def test_sub_results_are_records(results):
    dyn, report = results["Dynamics"], results["CheckReport"]
    assert dyn.flywheel.needed and dyn.flywheel.rim.outer_diameter > 0 and dyn.simulation.success
    assert report.limits and all(dataclasses.is_dataclass(lim) for lim in report.limits)
    assert dataclasses.is_dataclass(results["CheckReport (four-bar)"].grashof)
    assert all(dataclasses.is_dataclass(e) and all(dataclasses.is_dataclass(loc) for loc in e.local)
               for e in report.extremes)
    summary = results["DesignSummary"]
    assert all(dataclasses.is_dataclass(x) for x in summary.limits + summary.extremes)
    assert results["Motion"].frames.th.shape == results["Motion"].angle.shape
    cam = results["Kinetostatics (higher pairs)"]
    assert cam.motion.frames.contact.shape == (12, 1) and set(cam.contact_forces) == set(cam.pulling) == {"K"}
    pulls = results["CheckReport (cam)"].separations
    assert pulls and all(dataclasses.is_dataclass(s) and s.pair == "K" and s.start < s.end for s in pulls)
    assert [(s["from"], s["to"]) for s in results["CheckReport (cam)"].as_dict()["separations"]] == \
        [(s.start, s.end) for s in pulls]


def test_a_later_need_makes_a_new_record():
    """`positions_at_limits` and the figures' cycle build new motions (`dataclasses.replace`), the motion
    they start from unchanged."""
    from mbplanar.kinematics import positions_at_limits
    engine = _engine("crank_slider_rocker_locking")
    inp = engine.inputs[0]
    motion = mbplanar.analyse(engine, [inp.to_si(v) for v in np.linspace(0.0, 360.0, 73)])
    at = positions_at_limits(engine, motion.limits)
    assert len(at.phi) == len([lim for lim in motion.limits if lim.q is not None]) > 0
    assert np.all(np.isnan(at.w)) and np.all(np.isnan(at.frames.v)) and np.all(np.isfinite(at.frames.r))
    assert np.all(np.isfinite(motion.w))


def test_what_a_call_did_not_compute_is_none_and_reading_computes_nothing(monkeypatch):
    """Reading a field runs no solver: with the engine's solvers switched off after `analyse`, every
    array of the motion is still there (or None where it was not asked for)."""
    engine = _engine("shaper")
    phi = engine.phi_drawn[0] + np.linspace(0.0, 1.0, 5)
    full, some = mbplanar.analyse(engine, phi), mbplanar.analyse(engine, phi, rates=False, outputs=["value"])
    monkeypatch.setattr(_motion, "solve_positions", lambda *a: pytest.fail("a field read solved again"))
    monkeypatch.setattr(type(engine.solver), "solve_batch", lambda *a: pytest.fail("a field read solved again"))
    for name in mbplanar.kinematics.OUTPUTS:
        assert getattr(full, name) is not None, name
        assert (getattr(some, name) is None) == (name != "value"), name
    assert repr(full).startswith("Motion(") and "array(5, " in repr(full)
