"""The benchmark's harness (`benchmarks/run.py`), without timing anything: every timed case does the work
of its baseline (the closed forms produce the same points and angles as the engine, pylinkage the same
points), the targets are read from the cases they name, and docs/speed.md shows benchmarks/latest.json."""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

import mbplanar

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
import run  # noqa: E402


def case(name, work, **columns):
    return dict(name=name, work=work, n=3600, **columns)


def test_targets_read_their_cases_and_limits():
    cases = [case("fourbar", "positions", ratio=1.4, pylinkage_us=0.2, pylinkage_ratio=1.1),
             case("fourbar", "kinematics", ratio=2.1), case("slider_crank", "kinematics", ratio=2.9),
             case("six_bar_press", "kinematics", mbplanar_us=0.9), case("six_bar_press", "reactions", mbplanar_us=1.3),
             case("class4_group", "reactions", mbplanar_us=2.4),
             case("fourbar", "one position", mbplanar_us=9.0, analyse_ratio=1.6, position_numpy_us=90.0),
             case("fourbar", "analogues", ratio_to_real=1.05),
             case("fourbar", "mbplanar solve", seconds=0.2, cpu_s=0.3),
             case("fourbar_loaded", "numba cold start", seconds=9.0, cpu_s=4.0),
             case("fourbar_loaded", "numba warm start", seconds=0.2, cpu_s=0.2),
             case("mbplanar", "import", seconds=0.1, cpu_s=0.25)]
    met = {t["target"]: t["met"] for t in run.check_targets(cases)}
    assert met == {"four-bar positions, × closed form": True,
                   "four-bar positions + velocities + accelerations, × closed form": False,
                   "slider-crank positions + velocities + accelerations, × closed form": True,
                   "six-bar positions + velocities + accelerations, µs/position": True,
                   "six-bar with reactions, µs/position": False,
                   "class IV group with reactions, µs/position": True,
                   "one position with velocities and accelerations, µs": True,
                   "reading the analogues vq, aq after analyse, × reading v, a": True,
                   "analyse of one value [φ], × position()": False, "numpy backend's one position, µs": True,
                   "mbplanar solve end to end, CPU s": False, "numba cold start over numpy, CPU s": True,
                   "numba warm start over numpy, CPU s": True, "import mbplanar, CPU s": False,
                   "four-bar positions, × pylinkage+numba": False}   # (no pylinkage figure for kinematics)


def test_numbas_own_start_does_the_jobs_work_and_loads_a_kernel_from_numbas_cache():
    """The floor row's process is the cold script's numpy process (the same job, read the same way) with a
    one-line kernel compiled with numba's cache and called once: what any use of numba costs."""
    assert run.FLOOR_SCRIPT.endswith(run.COLD_SCRIPT)
    assert run.FLOOR_SCRIPT.startswith("import numba_floor\n")
    assert "cache=True" in run.FLOOR_KERNEL and "one(1.0)" in run.FLOOR_KERNEL


def test_a_missing_case_is_a_miss():
    verdict = run.check_targets([])
    assert len(verdict) == len(run.TARGETS) - 2 and not any(t["met"] for t in verdict)  # pylinkage's left out
    assert all(t["value"] is None for t in verdict)


@pytest.mark.parametrize("name", ["fourbar", "slider_crank", "six_bar_press"])
def test_closed_forms_produce_and_equal_what_the_engine_produces(name):
    """Every point (with velocity and acceleration) and every link angle of the engine's Motion, on every
    backend, equals the closed form's to 1e-9: the timed work is the same on both sides."""
    engines = run.engines_of(name)
    phi = run.full_turn(engines["numpy"], 48)
    closed = run.closed_form(name, engines["numpy"])
    for only in (True, False):
        ref = closed(phi, only)
        assert ("v" in ref) is not only and np.isfinite(run.cf.read(ref))
        for engine in engines.values():
            run.check_equal_work(mbplanar.analyse(engine, phi), ref, rates=not only)
    motion = mbplanar.analyse(engines["numpy"], phi)
    ref["xy"].pop(next(iter(ref["xy"])))                          # a point left out is not equal work
    with pytest.raises(AssertionError):
        run.check_equal_work(motion, ref, rates=True)
    ref = closed(phi + 1e-6, False)                                # nor is another position
    with pytest.raises(AssertionError, match="differs"):
        run.check_equal_work(motion, ref, rates=True)


def test_timed_calls_read_every_output():
    """The timed calls of the harness run and return the sum of what they read (quick sizes, no timing)."""
    engine = mbplanar.Engine(mbplanar.read_model(ROOT / "models" / "six_bar_press.toml"))
    phi = run.full_turn(engine, 20)
    motion = mbplanar.analyse(engine, phi)
    for work in run.WORK:
        total = run.mbplanar_call(engine, phi, work)()
        assert np.isfinite(total)
    assert run.mbplanar_call(engine, phi, "kinematics")() == pytest.approx(run.read_motion(motion), rel=1e-12)
    times = run.median_of_rounds([lambda: None, lambda: sum(range(100))], rounds=3, burst=2)
    assert len(times) == 2 and all(t >= 0 for t in times)
    wall, cpu = run.processes_in_rounds({"python": ([sys.executable, "-c", "pass"], None)}, 2)["python"]
    assert wall > 0 and cpu >= 0


def test_one_position_through_every_public_path():
    """One position is timed through `analyse` and the lean `position` on every backend, each checked
    against the closed form first; the headline is the fastest of them."""
    row = run.one_position_cases(rounds=1, burst=1)
    paths = {k for k in row if k.endswith("_us")} - {"mbplanar_us"}
    assert {"numpy_us", "position_numpy_us", "analyse_list_us"} <= paths
    assert row["mbplanar_us"] == min(row[k] for k in paths) and row["analyse_ratio"] > 0


def test_the_analogues_and_the_real_rates_are_read_alike():
    row = run.analogue_case(36, rounds=1, burst=1)
    assert row["work"] == "analogues" and row["ratio_to_real"] == pytest.approx(row["analogues_us"] / row["real_us"])


def test_pylinkage_fourbar_is_the_same_work():
    """pylinkage's four-bar gives mbplanar's points, velocities and accelerations (checked inside
    `pylinkage_calls`, to 1e-9), and a point out of place is caught."""
    pytest.importorskip("pylinkage", reason="pylinkage is the benchmark's optional baseline: pip install -e '.[bench]'")
    engine = mbplanar.Engine(mbplanar.read_model(ROOT / "models" / "fourbar.toml"))
    positions, kinematics, one = run.pylinkage_calls(engine, 36)
    assert np.isfinite(positions()) and np.isfinite(kinematics()) and np.isfinite(one())
    linkage, names = run.pylinkage_fourbar(engine, 36)
    pos = linkage.step_fast(iterations=36)
    pos[:, names.index("M")] += 1e-6
    with pytest.raises(AssertionError, match="pylinkage M"):
        run.check_pylinkage(engine, names, pos)


def test_speed_page_and_readme_show_the_latest_run():
    """docs/speed.md's tables and the README's speed section are benchmarks/latest.json as
    `run.py --docs` writes them."""
    doc = json.loads(run.LATEST.read_text(encoding="utf-8"))
    page = run.SPEED_DOC.read_text(encoding="utf-8")
    assert run.markdown(doc) in page, "stale: python benchmarks/run.py --docs rewrites it"
    assert run.readme_text(doc) in run.README.read_text(encoding="utf-8"), "stale: run.py --docs rewrites it"
    assert all(c.get("mbplanar_us") or c.get("seconds") for c in doc["cases"])
    assert {t["target"] for t in doc["targets"]} <= {t[0] for t in run.TARGETS}
