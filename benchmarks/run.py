"""Benchmark of mbplanar on equal work: every timed case produces and reads what its baseline produces.

    python benchmarks/run.py [--quick] [--json [FILE]] [--docs] [--processes [ROUNDS]]

Sweeps of N positions over a turn: every point's x, y (and vx, vy, ax, ay where velocities and
accelerations are timed) and every link's angle, read (summed) inside the timed call, so that work the
compiled backend leaves for the first read (`kinematics.DERIVED`) is timed. Baselines of the same run:
the vectorised numpy closed forms of `closed_forms.py` (the same arrays, read the same way), and
pylinkage+numba where it is installed (`pip install -e ".[bench]"`; its `step_fast` and
`step_fast_with_kinematics` on the four-bar of models/fourbar.toml, checked to give the same points).

Timing: the cases are timed in turn, in rounds; each round calls every case a few times in a row and
keeps the fastest call; the figure is the median over the rounds (µs per position, or per call). A ratio
to a baseline is the median over the rounds of the ratio within a round (the baseline is timed right
after the case), so that the load of the moment cancels. The compiled backend runs on one core for the headline
(`Engine(threads=1)`, the baselines use one core) and on two as a second column. Process-level figures
(`mbplanar solve`, `import mbplanar` alone and with its first use, numba's cold and warm start) are medians
of subprocess runs.

Beside them, the paths that must cost about what the fastest one does (no cliffs): the analogues vq, aq
read after `analyse` against v, a; `analyse` of one value [φ] against `position`; the numpy backend's one
position.

`--json FILE` writes the run ('-': stdout), `--docs` rewrites the table in docs/speed.md from
benchmarks/latest.json, `--study` runs the design-study cases (benchmarks/study.py), `--processes [ROUNDS]`
only the process cases.
"""

from __future__ import annotations

import argparse
import datetime
import inspect
import json
import math
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import closed_forms as cf  # noqa: E402
from chains import class4_chain, dyad_chain  # noqa: E402
import mbplanar  # noqa: E402

try:
    import numba  # noqa: F401
    BACKENDS = ["numpy", "numba"]
except ImportError:
    BACKENDS = ["numpy"]
BEST = BACKENDS[-1]
SKIPPED = 'not installed, skipped (pip install -e ".[bench]")'
LATEST = ROOT / "benchmarks" / "latest.json"
SPEED_DOC = ROOT / "docs" / "speed.md"

WORK = {"positions": "positions", "kinematics": "positions + velocities + accelerations",
        "reactions": "with reactions"}
# (model, work) of the sweeps; the closed forms and pylinkage apply where they are named
SWEEPS = [("fourbar", "positions"), ("slider_crank", "positions"), ("six_bar_press", "positions"),
          ("fourbar", "kinematics"), ("slider_crank", "kinematics"), ("six_bar_press", "kinematics"),
          ("class4_group", "kinematics"), ("six_bar_press", "reactions"), ("class4_group", "reactions"),
          ("shaper", "reactions")]
TARGETS = [  # (label, case name, work, column, limit)
    ("four-bar positions, × closed form", "fourbar", "positions", "ratio", 1.5),
    ("four-bar positions + velocities + accelerations, × closed form", "fourbar", "kinematics", "ratio", 2.0),
    ("slider-crank positions + velocities + accelerations, × closed form", "slider_crank", "kinematics",
     "ratio", 3.0),
    ("six-bar positions + velocities + accelerations, µs/position", "six_bar_press", "kinematics",
     "mbplanar_us", 1.0),
    ("six-bar with reactions, µs/position", "six_bar_press", "reactions", "mbplanar_us", 1.2),
    ("class IV group with reactions, µs/position", "class4_group", "reactions", "mbplanar_us", 2.5),
    ("one position with velocities and accelerations, µs", "fourbar", "one position", "mbplanar_us", 10.0),
    # no cliffs: the paths beside the fastest cost about as much
    ("reading the analogues vq, aq after analyse, × reading v, a", "fourbar", "analogues", "ratio_to_real", 1.1),
    ("analyse of one value [φ], × position()", "fourbar", "one position", "analyse_ratio", 1.5),
    ("numpy backend's one position, µs", "fourbar", "one position", "position_numpy_us", 100.0),
    # processes: CPU time of the child (on a loaded shared machine its wall time is 2 to 3 times longer)
    ("mbplanar solve end to end, CPU s", "fourbar", "mbplanar solve", "cpu_s", 0.25),
    ("numba cold start over numpy, CPU s", "fourbar_loaded", "numba cold start", "cpu_s", 5.0),
    ("numba warm start over numpy, CPU s", "fourbar_loaded", "numba warm start", "cpu_s", 0.3),
    ("import mbplanar, CPU s", "mbplanar", "import", "cpu_s", 0.2),
    ("four-bar positions, × pylinkage+numba", "fourbar", "positions", "pylinkage_ratio", 0.9),
    ("four-bar positions + velocities + accelerations, × pylinkage+numba", "fourbar", "kinematics",
     "pylinkage_ratio", 0.6),
]


# ---------------------------------------------------------------------------------------------------
# timing


def fastest(call, burst):
    """The shortest wall time (s) of `burst` calls in a row."""
    best = math.inf
    for _ in range(burst):
        t = time.perf_counter()
        call()
        best = min(best, time.perf_counter() - t)
    return best


def in_rounds(calls, rounds, burst):
    """Per callable, its fastest of `burst` calls in a row (s) in each of `rounds` rounds. Every round
    times every callable in turn, so that a slow spell of a shared machine falls on all of them."""
    times = [[] for _ in calls]
    for _ in range(rounds):
        for call, seen in zip(calls, times):
            seen.append(fastest(call, burst))
    return times


def median_of_rounds(calls, rounds, burst):
    """Per callable, the median over the rounds of its fastest call (s) (`in_rounds`)."""
    return [statistics.median(seen) for seen in in_rounds(calls, rounds, burst)]


def run_process(cmd, env):
    """Wall time and CPU time (user + system of the child) in s of one run of the command `cmd`."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True, env=env, cwd=ROOT)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def processes_in_rounds(commands, rounds):
    """Per command (name → (argv, env)), the medians over `rounds` rounds of its wall and CPU times (s);
    every round runs every command once, in turn, so that the load of a shared machine falls on all."""
    seen = {name: [] for name in commands}
    for _ in range(rounds):
        for name, (cmd, env) in commands.items():
            seen[name].append(run_process(cmd, env))
    return {name: tuple(statistics.median(x[k] for x in times) for k in (0, 1)) for name, times in seen.items()}


# ---------------------------------------------------------------------------------------------------
# the equal work: what a case produces and reads


def read_motion(motion, rates=True) -> float:
    """Touch every point's position (and velocity, acceleration) and every link's angle of a Motion:
    the compiled backend computes these on first read, so reading them is part of the work."""
    total = float(motion.xy.sum()) + float(motion.angle.sum())
    if rates:
        total += float(motion.v.sum()) + float(motion.a.sum())
    return total


def read_one(motion) -> float:
    """Read every value of one position's outputs (positions, velocities, accelerations of every point,
    every link's angle), as `read_motion` does, but through Python floats: numpy's reduction of a tiny
    array (about 1.3 µs each) would outweigh the solve. pylinkage's one-position call is read the same way."""
    return sum(sum(a.ravel().tolist()) for a in (motion.xy, motion.angle, motion.v, motion.a))


def read_reactions(result) -> float:
    """Touch every reaction (fx, fy, moment) and balancing load of a Kinetostatics, and its Motion."""
    total = read_motion(result.motion)
    for r in result.reactions.values():
        total += float(r.fx.sum()) + float(r.fy.sum()) + float(r.moment.sum())
    return total + sum(float(b.sum()) for b in result.balancing.values())


def positions_request() -> dict:
    """Keyword arguments of `analyse` that ask for positions only (every point's x, y and every link's
    angle, none of the optional outputs: what the baselines produce), where this version has them."""
    parameters = inspect.signature(mbplanar.analyse).parameters
    return {"rates": False, **({"outputs": ()} if "outputs" in parameters else {})} if "rates" in parameters else {}


def kinematics_request() -> dict:
    """Keyword arguments of `analyse` that ask for the points' velocities and accelerations beside the
    positions and angles (none of the other optional outputs: what the baselines produce), where this
    version has them."""
    return {"outputs": ("v", "a")} if "outputs" in inspect.signature(mbplanar.analyse).parameters else {}


def mbplanar_call(engine, phi, work):
    """The timed call of a case: solve `phi` on `engine` and read the work's outputs."""
    if work == "positions":
        request = positions_request()
        return lambda: read_motion(mbplanar.analyse(engine, phi, **request), rates=False)
    if work == "kinematics":
        request = kinematics_request()
        return lambda: read_motion(mbplanar.analyse(engine, phi, **request))
    return lambda: read_reactions(mbplanar.kinetostatics(engine, mbplanar.analyse(engine, phi)))


def closed_form(name, engine):
    """The closed form of a model as f(phi, positions_only) with the model's input speed, or None."""
    inp = engine.inputs[0]
    omega, epsilon = float(inp.omega), float(inp.epsilon)
    if name == "fourbar":
        return lambda phi, only: cf.fourbar(phi, omega, epsilon, positions_only=only)
    if name == "slider_crank":
        return lambda phi, only: cf.slider_crank(phi, omega, epsilon, positions_only=only)
    if name == "six_bar_press":
        joints = engine.mech.joints  # the rocker's D as assembled (B the middle of CD to 1e-7 m)
        B, C, D = (np.array(joints[n].at) for n in "BCD")
        r, d = B - C, D - C
        rocker = (float(r @ d / (r @ r)), float((r[0] * d[1] - r[1] * d[0]) / (r @ r)))
        zero = math.radians(inp.zero) if inp.unit == "deg" else inp.zero
        return lambda phi, only: cf.six_bar_press(phi, omega, epsilon, positions_only=only, rocker=rocker,
                                                  zero=zero, sense=inp.sense)
    return None


def same(label, got, want, rel=1e-9, angle=False):
    """Assert that two arrays agree to `rel` of the larger of 1 and the baseline's magnitude (angles:
    modulo a turn)."""
    got, want = np.asarray(got, float), np.asarray(want, float)
    scale = max(1.0, float(np.abs(want).max()))
    diff = np.abs(np.angle(np.exp(1j * (got - want)))) if angle else np.abs(got - want)
    worst = float(diff.max()) / scale
    assert worst <= rel, f"{label}: differs by {worst:.3g} (relative) from the baseline"


def check_equal_work(motion, ref, rates):
    """The closed form's result `ref` holds the same points and links as `motion`, with the same values."""
    assert sorted(ref["xy"]) == sorted(motion.point_names), (sorted(ref["xy"]), motion.point_names)
    assert sorted(ref["angle"]) == sorted(motion.link_names), (sorted(ref["angle"]), motion.link_names)
    for key in ("xy", "v", "a") if rates else ("xy",):
        values = batched(getattr(motion, key), 3)
        for point, x in ref[key].items():
            same(f"{key} of {point}", values[:, motion.point(point)], x)
    for link, th in ref["angle"].items():
        same(f"angle of link {link}", batched(motion.angle, 2)[:, motion.link(link)], th, angle=True)


def batched(x, ndim):
    """`x` with a batch axis of one in front if it has none (a one-position result)."""
    x = np.asarray(x)
    return x if x.ndim == ndim else x[None]


# ---------------------------------------------------------------------------------------------------
# pylinkage+numba


def pylinkage_fourbar(engine, steps):
    """pylinkage's four-bar of models/fourbar.toml (crank O-A, dyad A-B-C, coupler point M fixed to A, B),
    turning a whole turn in `steps` steps from the drawn pose, at ω = 1 rad/s, and the names of its points
    in the order of its outputs; None without pylinkage."""
    try:
        import pylinkage as pl
    except ImportError:
        return None
    at = {name: np.array(j.at) for name, j in engine.mech.joints.items()}
    at.update({name: np.array(p.at) for name, p in engine.mech.points.items()})
    O, C = pl.Ground(*at["O"], name="O"), pl.Ground(*at["C"], name="C")
    a, b, c = (math.dist(at[p], at[q]) for p, q in ("OA", "AB", "BC"))
    crank = pl.Crank(anchor=O, radius=a, angular_velocity=2 * math.pi / steps,
                     initial_angle=math.atan2(*(at["A"] - at["O"])[::-1]), name="A")
    B = pl.RRRDyad(anchor1=crank.output, anchor2=C, distance1=b, distance2=c, x=at["B"][0], y=at["B"][1], name="B")
    m, ab = at["M"] - at["A"], at["B"] - at["A"]
    M = pl.FixedDyad(anchor1=crank.output, anchor2=B, distance=float(np.hypot(*m)),
                     angle=math.atan2(m[1], m[0]) - math.atan2(ab[1], ab[0]), name="M")
    linkage = pl.Linkage([O, C, crank, B, M])
    linkage.set_input_velocity(crank, 1.0, 0.0)
    return linkage, [comp.name for comp in linkage.components]


def pylinkage_version():
    try:
        from importlib.metadata import version
        return version("pylinkage")
    except Exception:  # noqa: BLE001 (not installed)
        return None


def check_pylinkage(engine, names, pos, vel=None, acc=None):
    """pylinkage's points (steps, P, 2) equal mbplanar's at the crank angles pylinkage reached."""
    A = pos[:, names.index("A")] - pos[:, names.index("O")]
    motion = mbplanar.analyse(engine, np.arctan2(A[:, 1], A[:, 0]), 1.0, 0.0)
    for k, name in enumerate(names):
        p = motion.point(name)
        same(f"pylinkage {name}", pos[:, k], motion.xy[:, p])
        if vel is not None:
            same(f"pylinkage velocity of {name}", vel[:, k], motion.v[:, p])
            same(f"pylinkage acceleration of {name}", acc[:, k], motion.a[:, p])


def pylinkage_calls(engine, n):
    """(positions call, kinematics call, one-position call) of pylinkage on the four-bar, each checked
    against mbplanar once; None without pylinkage."""
    made = pylinkage_fourbar(engine, n)
    if made is None:
        return None
    linkage, names = made
    check_pylinkage(engine, names, linkage.step_fast(iterations=n))
    check_pylinkage(engine, names, *linkage.step_fast_with_kinematics(iterations=n))

    def positions():
        return float(linkage.step_fast(iterations=n).sum())

    def kinematics():
        return sum(float(x.sum()) for x in linkage.step_fast_with_kinematics(iterations=n))

    def one():  # read as `read_one` reads mbplanar's: every value, through Python floats
        return sum(sum(x.ravel().tolist()) for x in linkage.step_fast_with_kinematics(iterations=1))
    return positions, kinematics, one


# ---------------------------------------------------------------------------------------------------
# the cases


def full_turn(engine, n):
    """n input values over one turn from the drawn pose (SI)."""
    return engine.phi_drawn[0] + np.linspace(0.0, 2 * np.pi, n, endpoint=False)


def engines_of(name):
    """The engines of a model: numpy, and the compiled one on one and on two threads (when installed)."""
    mech = mbplanar.read_model(ROOT / "models" / f"{name}.toml")
    found = {"numpy": mbplanar.Engine(mech)}
    if BEST == "numba":
        found["numba"] = mbplanar.Engine(mech, backend="numba", threads=1)
        found["numba_2t"] = mbplanar.Engine(mech, backend="numba", threads=2)
    return found


def sweep_cases(n, rounds, burst, plk=None):
    """The sweeps of `SWEEPS`, checked for equal work, timed in rounds; one dict per case. `plk`:
    pylinkage's calls (`pylinkage_calls`), timed on the four-bar."""
    rows, calls, slots = [], [], []
    engines, builds = {}, []
    for name, work in SWEEPS:
        if name not in engines:
            t = time.perf_counter()
            engines[name] = engines_of(name)
            builds.append(dict(name=name, build_s=(time.perf_counter() - t) / len(engines[name])))
        found = engines[name]
        phi = full_turn(found["numpy"], n)
        columns = {f"{b}_us": mbplanar_call(e, phi, work) for b, e in found.items()}
        if "numba" in found and work != "reactions":  # analyse alone, the lazily derived arrays unread
            request = positions_request() if work == "positions" else kinematics_request()
            columns["analyse_only_us"] = lambda e=found["numba"], phi=phi, r=request: mbplanar.analyse(e, phi, **r)
        closed = closed_form(name, found["numpy"])
        if closed is not None and work != "reactions":
            only = work == "positions"
            ref, request = closed(phi, only), positions_request() if only else kinematics_request()
            for e in found.values():
                check_equal_work(mbplanar.analyse(e, phi, **request), ref, rates=not only)
            columns["closed_form_us"] = lambda closed=closed, phi=phi, only=only: cf.read(closed(phi, only))
        if name == "fourbar" and plk is not None and work in ("positions", "kinematics"):
            columns["pylinkage_us"] = plk[0] if work == "positions" else plk[1]
        for call in columns.values():
            call()  # warm: compiled, cached, the branch atlas built
        rows.append(dict(name=name, work=work, n=n))
        for column, call in columns.items():
            calls.append(call)
            slots.append((rows[-1], column))
    seen = {}
    for (row, column), times in zip(slots, in_rounds(calls, rounds, burst)):
        row[column] = 1e6 * statistics.median(times) / n
        seen[id(row), column] = times
    for row in rows:
        finish(row, {column: seen[id(row), column] for column in list(row) if (id(row), column) in seen})
    return rows, builds


def finish(row, rounds, headline=None):
    """The headline figure of a case: the column `headline`, by default the compiled backend on one core
    (else numpy); and its ratios to the baselines, the medians over the rounds of the ratios within a
    round (`rounds`: column → its time in each round), so that the load of the moment cancels."""
    headline = headline or f"{BEST}_us"
    row["backend"] = BEST
    row["headline"] = headline
    row["mbplanar_us"] = row.get(headline)
    for base, key in (("closed_form_us", "ratio"), ("pylinkage_us", "pylinkage_ratio")):
        ok = base in rounds and headline in rounds
        row[key] = statistics.median(a / b for a, b in zip(rounds[headline], rounds[base])) if ok else None


def one_position_cases(rounds, burst, plk_one=None):
    """One position of the four-bar with velocities and accelerations of every point, µs per call,
    through the public API on each backend: `analyse` with a scalar, and the lean `mbplanar.position`
    where this version has it (and pylinkage's one step where installed)."""
    found = engines_of("fourbar")
    phi = float(found["numpy"].phi_drawn[0]) + 0.3
    columns = {f"{b}_us": (lambda e=e: read_one(mbplanar.analyse(e, phi))) for b, e in found.items()
               if b != "numba_2t"}
    ref = closed_form("fourbar", found["numpy"])(np.array([phi]), False)
    for e in found.values():
        check_equal_work(mbplanar.analyse(e, phi), ref, rates=True)
    lean = getattr(mbplanar, "position", None)  # the lean one-position API, where this version has it
    if lean is not None:
        for b, e in found.items():
            if b != "numba_2t":
                check_equal_work(lean(e, phi), ref, rates=True)
                columns[f"position_{b}_us"] = lambda e=e: read_one(lean(e, phi))
        # `analyse` of a batch of one value, beside `position` (no cliff between them)
        columns["analyse_list_us"] = lambda e=found[BEST]: read_one(mbplanar.analyse(e, [phi]))
    if plk_one is not None:
        columns["pylinkage_us"] = plk_one
    for call in columns.values():
        call()
    row = dict(name="fourbar", work="one position", n=1)
    seen = dict(zip(columns, in_rounds(list(columns.values()), rounds, burst)))
    for column, times in seen.items():
        row[column] = 1e6 * statistics.median(times)
    # the target is met through the public API's fastest path
    finish(row, seen, min((k for k in seen if k != "pylinkage_us"), key=row.get))
    if lean is not None:
        row["analyse_ratio"] = statistics.median(a / b for a, b in zip(seen["analyse_list_us"],
                                                                       seen[f"position_{BEST}_us"]))
    return row


def analogue_case(n, rounds, burst):
    """The four-bar's sweep on the compiled backend (one core), its velocity and acceleration analogues
    read after `analyse` (`vq`, `aq`), beside the same sweep with its real velocities and accelerations
    read (`v`, `a`): reading the one costs what reading the other does (µs per position; the ratio, the
    median over the rounds of the ratios within a round)."""
    engine = engines_of("fourbar")[BEST]
    phi = full_turn(engine, n)

    def read(names):
        return lambda: sum(float(getattr(m, name).sum()) for m in [mbplanar.analyse(engine, phi)] for name in names)
    columns = {"analogues_us": read(("xy", "angle", "vq", "aq")), "real_us": read(("xy", "angle", "v", "a"))}
    for call in columns.values():
        call()
    row = dict(name="fourbar", work="analogues", n=n, backend=BEST, headline="analogues_us")
    seen = dict(zip(columns, in_rounds(list(columns.values()), rounds, burst)))
    for column, times in seen.items():
        row[column] = 1e6 * statistics.median(times) / n
    row["mbplanar_us"] = row["analogues_us"]
    row["ratio_to_real"] = statistics.median(a / b for a, b in zip(seen["analogues_us"], seen["real_us"]))
    return row


COLD_SCRIPT = """import sys, numpy as np, mbplanar
e = mbplanar.Engine(mbplanar.read_model('models/fourbar_loaded.toml'), backend=sys.argv[1])
m = mbplanar.analyse(e, e.phi_drawn[0] + np.linspace(0, 2 * np.pi, 3600, endpoint=False))
k = mbplanar.kinetostatics(e, m)
print(m.xy.sum() + m.v.sum() + m.a.sum() + k.balancing['O'].sum())
"""


#: numba's own start in the same job: the numpy process of `COLD_SCRIPT` that also loads a one-line kernel
#: from numba's cache (a module of the temporary folder, `numba_floor.py`): what any use of numba costs
FLOOR_SCRIPT = "import numba_floor\n" + COLD_SCRIPT
FLOOR_KERNEL = """import numba


@numba.njit(cache=True)
def one(x):
    return x + 1.0


one(1.0)
"""


# `import mbplanar` loads its names on first use; the first use of the API loads numpy and the model,
# engine and kinematics code, as any program that uses mbplanar pays for it
FIRST_USE = "import mbplanar; mbplanar.Engine, mbplanar.read_model, mbplanar.analyse"


def process_cases(rounds, cold):
    """`mbplanar solve` end to end, `import mbplanar`, and numba's cold and warm start: new processes
    timed in rounds (wall and CPU time, medians), with `python -c pass` and `import numpy` as context."""
    py = sys.executable
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, PYTHONPATH=str(ROOT), MBPLANAR_THREADS="1", MBPLANAR_CACHE_DIR=cache)
        # bytecode compiled once, as an installed package has it; the engine cache of the command line
        # filled as by a user's first command on the file
        subprocess.run([py, "-m", "compileall", "-q", str(ROOT / "mbplanar")], check=True, capture_output=True)
        solve = [py, "-m", "mbplanar", "solve", "models/fourbar.toml", "--at", "30"]
        subprocess.run(solve, check=True, capture_output=True, env=env, cwd=ROOT)
        commands = {"python": ([py, "-c", "pass"], env), "numpy": ([py, "-c", "import numpy"], env),
                    "import": ([py, "-c", "import mbplanar"], env),
                    "first_use": ([py, "-c", FIRST_USE], env), "solve": (solve, env)}
        cold_s = None
        if cold and BEST == "numba":
            # installed with its install step: `mbplanar compile` (into an empty numba cache), then the first
            # run after it (cold) and the next ones (warm); and without it: numba compiles on the first run,
            # into another empty cache
            numba_env = dict(env, NUMBA_CACHE_DIR=str(Path(cache) / "numba"))
            jit_env = dict(env, NUMBA_CACHE_DIR=str(Path(cache) / "numba-jit"))
            jit_cold_s = run_process([py, "-c", COLD_SCRIPT, "numba"], jit_env)
            install_s = run_process([py, "-m", "mbplanar", "compile"], numba_env)
            cold_s = run_process([py, "-c", COLD_SCRIPT, "numba"], numba_env)
            # numba's own start: the numpy job with a one-line kernel loaded from numba's cache (filled once)
            Path(cache, "numba_floor.py").write_text(FLOOR_KERNEL, encoding="utf-8")
            floor_env = dict(numba_env, PYTHONPATH=os.pathsep.join([str(ROOT), cache]))
            subprocess.run([py, "-c", FLOOR_SCRIPT, "numpy"], check=True, capture_output=True, env=floor_env, cwd=ROOT)
            commands.update(sweep_numpy=([py, "-c", COLD_SCRIPT, "numpy"], env),
                            sweep_numba=([py, "-c", COLD_SCRIPT, "numba"], numba_env),
                            sweep_numba_jit=([py, "-c", COLD_SCRIPT, "numba"], jit_env),
                            sweep_floor=([py, "-c", FLOOR_SCRIPT, "numpy"], floor_env))
        t = processes_in_rounds(commands, rounds)
    context = dict(python_s=t["python"][0], python_cpu_s=t["python"][1], numpy_s=t["numpy"][0],
                   numpy_cpu_s=t["numpy"][1])
    rows = [dict(name="fourbar", work="mbplanar solve", n=1, seconds=t["solve"][0], cpu_s=t["solve"][1], **context),
            dict(name="mbplanar", work="import", n=1, seconds=t["import"][0], cpu_s=t["import"][1], **context),
            dict(name="mbplanar", work="import and first use", n=1, seconds=t["first_use"][0],
                 cpu_s=t["first_use"][1], **context)]
    if cold_s is not None:
        np_wall, np_cpu = t["sweep_numpy"]

        def over_numpy(work, process):
            return dict(name="fourbar_loaded", work=work, n=1, seconds=process[0] - np_wall, cpu_s=process[1] - np_cpu,
                        process_s=process[0], process_cpu_s=process[1], numpy_process_s=np_wall,
                        numpy_process_cpu_s=np_cpu)
        rows += [dict(name="mbplanar", work="numba install step (mbplanar compile)", n=1, seconds=install_s[0],
                      cpu_s=install_s[1]),
                 over_numpy("numba cold start", cold_s), over_numpy("numba warm start", t["sweep_numba"]),
                 over_numpy("numba cold start, not compiled", jit_cold_s),
                 over_numpy("numba warm start, not compiled", t["sweep_numba_jit"]),
                 over_numpy("numba's own start (one cached one-line kernel)", t["sweep_floor"])]
    for r in rows:
        print(f"  {r['work']:18s} ({r['name']}) wall {r['seconds']:.3f} s, CPU {r['cpu_s']:.3f} s; {context_of(r)}")
    if cold_s is None:
        print("  numba cold and warm start: skipped" + (" (--quick)" if not cold else " (no numba)"))
    return rows


def context_of(row) -> str:
    """The context processes of a process case, wall / CPU time each (s)."""
    names = [k[:-2] for k in row if k.endswith("_s") and not k.endswith("cpu_s") and k != "seconds"]
    return ", ".join(f"{k.replace('_', ' ')} {row[k + '_s']:.3f} / {row[k + '_cpu_s']:.3f}" for k in names)


def scaling_groups(builder, label, ks, n, rounds):
    """µs per position (positions, velocities, accelerations read, N = n over a turn) of the mechanisms
    builder(k) for k in ks, one core, and the fitted exponent of time against k per backend."""
    times = {b: [] for b in BACKENDS}
    for k in ks:
        mech = builder(k)
        for b in BACKENDS:
            e = mbplanar.Engine(mech, backend=b, threads=1) if b == "numba" else mbplanar.Engine(mech)
            phi = full_turn(e, n)
            call = mbplanar_call(e, phi, "kinematics")
            call()
            times[b].append(median_of_rounds([call], rounds, 1)[0])
        print(f"  k = {k:3d}: " + ", ".join(f"{b} {1e6 * times[b][-1] / n:.2f}" for b in BACKENDS)
              + " µs/position")
    slopes = {b: float(np.polyfit(np.log(ks), np.log(times[b]), 1)[0]) for b in BACKENDS}
    print(f"  time per position ∝ k^{slopes[BEST]:.2f} over k = {ks[0]}…{ks[-1]} {label} "
          f"(numpy k^{slopes['numpy']:.2f})")
    return slopes


# ---------------------------------------------------------------------------------------------------
# verdict and report


def check_targets(cases):
    """The targets against the cases of a run: (target, value, limit, met); a missing case is a miss
    (value None), except pylinkage's, which are left out where it is not installed."""
    found = []
    for label, name, work, column, limit in TARGETS:
        case = next((c for c in cases if c["name"] == name and c["work"] == work), {})
        value = case.get(column)
        if column == "pylinkage_ratio" and case.get("pylinkage_us") is None:
            continue
        found.append(dict(target=label, value=value, limit=limit, met=value is not None and value <= limit))
    return found


def fmt(x, digits=3):
    return "—" if x is None else f"{x:.{digits}g}"


def print_sweeps(rows):
    head = ["case", "work", "numpy", f"{BEST} 1 core", f"{BEST} 2 threads", "analyse() alone",
            "closed form", "× closed", "pylinkage+numba", "× pylinkage"]
    print("  " + " | ".join(head))
    for r in rows:
        print("  " + " | ".join([r["name"], WORK.get(r["work"], r["work"]), fmt(r.get("numpy_us")),
                                 fmt(r.get("numba_us")), fmt(r.get("numba_2t_us")), fmt(r.get("analyse_only_us")),
                                 fmt(r.get("closed_form_us")), fmt(r.get("ratio"), 2), fmt(r.get("pylinkage_us")),
                                 fmt(r.get("pylinkage_ratio"), 2)]))


def markdown(doc) -> str:
    """The run of `doc` (a latest.json) as the Markdown of docs/speed.md's latest-run section."""
    m = doc["machine"]
    lines = [f"Run of {doc['date']} on {m['cpus']} CPUs ({m['cpu']}), Python {m['python']}, numpy {m['numpy']}, "
             f"numba {m['numba'] or '—'}, pylinkage {m['pylinkage'] or 'not installed'}; "
             f"load average {m['load_before']:.1f} before and {m['load_after']:.1f} after (other jobs shared "
             f"the machine). N = {doc['n']} positions over a turn, {doc['rounds']} rounds, one core unless "
             "the column says otherwise.", "",
             "Sweeps, µs per position (×: the headline's time over the baseline's in the same round, median "
             "over the rounds):", "",
             "| model | work | numpy | numba | numba, 2 threads | analyse() alone | closed form | × closed "
             "form | pylinkage+numba | × pylinkage |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in (c for c in doc["cases"] if c["work"] in WORK):
        lines.append("| " + " | ".join([r["name"], WORK[r["work"]], fmt(r.get("numpy_us")), fmt(r.get("numba_us")),
                                        fmt(r.get("numba_2t_us")), fmt(r.get("analyse_only_us")),
                                        fmt(r.get("closed_form_us")), fmt(r.get("ratio"), 2),
                                        fmt(r.get("pylinkage_us")), fmt(r.get("pylinkage_ratio"), 2)]) + " |")
    one = next((c for c in doc["cases"] if c["work"] == "one position"), None)
    if one:
        lines += ["", "One position of the four-bar with velocities and accelerations of every point, µs per "
                  "call: " + ", ".join(f"{k[:-3].replace('_', ' ')} {fmt(v)}" for k, v in one.items()
                                       if k.endswith("_us") and k != "mbplanar_us" and v is not None) + "."
                  + (f" `analyse` of [φ] over `position`: × {fmt(one['analyse_ratio'])}." if one.get("analyse_ratio")
                     else "")]
    analogues = next((c for c in doc["cases"] if c["work"] == "analogues"), None)
    if analogues:
        lines += ["", f"The four-bar's sweep with its analogues vq, aq read after `analyse`: "
                  f"{fmt(analogues['analogues_us'])} µs per position; with v, a read: {fmt(analogues['real_us'])} "
                  f"(× {fmt(analogues['ratio_to_real'])})."]
    procs = [c for c in doc["cases"] if "seconds" in c]
    if procs:
        lines += ["", "New processes, medians of the rounds (s; the cold start is one process, and the cold and "
                  "warm start are the time over the same process on numpy):", "",
                  "| process | wall | CPU | context (wall / CPU) |", "|---|---|---|---|"]
        lines += [f"| {c['work']} ({c['name']}) | {c['seconds']:.3f} | {c['cpu_s']:.3f} | {context_of(c)} |"
                  for c in procs]
    if doc.get("chain_exponents"):
        fits = ", ".join(f"{b} k^{v:.2f}" for b, v in doc["chain_exponents"].items())
        fits4 = ", ".join(f"{b} k^{v:.2f}" for b, v in (doc.get("class4_chain_exponents") or {}).items())
        lines += ["", f"Time per position against the number of groups k (a crank and k dyads: {fits}; "
                  f"a crank and k class IV groups: {fits4})."]
    lines += ["", "Targets:", "", "| target | value | limit | met |", "|---|---|---|---|"]
    lines += [f"| {t['target']} | {fmt(t['value'], 4)} | {t['limit']:g} | {'yes' if t['met'] else 'no'} |"
              for t in doc["targets"]]
    return "\n".join(line if line.startswith("|") else wrap(line) for line in lines) + "\n"


def wrap(text):
    """A paragraph of the generated Markdown, cut at 110 characters as the hand-written pages are."""
    return textwrap.fill(text, 110, break_on_hyphens=False, break_long_words=False)


def readme_text(doc) -> str:
    """The README's speed section: the headline equal-work figures of `doc` (a latest.json)."""
    def get(name, work, column):
        return next((c.get(column) for c in doc["cases"] if c["name"] == name and c["work"] == work), None)

    def num(x):
        return "—" if x is None else f"{x:.0f}" if x >= 100 else f"{x:.2g}"

    rows = [("four-bar, positions", "fourbar", "positions"),
            ("four-bar, with velocities and accelerations", "fourbar", "kinematics"),
            ("slider-crank, with velocities and accelerations", "slider_crank", "kinematics"),
            ("six-bar press, with velocities and accelerations", "six_bar_press", "kinematics"),
            ("six-bar press, with reactions", "six_bar_press", "reactions"),
            ("class IV group, with reactions", "class4_group", "reactions")]
    m = doc["machine"]
    prose = [f"Measured on equal work: every point's position (with velocity and acceleration) and every link's "
             f"angle produced and read, as the baselines return them; `--backend {doc['backends'][-1]}` on one "
             f"core of a shared {m['cpus']}-CPU machine ({doc['date'][:10]}); ratios to a vectorised numpy closed "
             "form and to pylinkage+numba timed alongside.",
             f"One position of the four-bar with velocities and accelerations: "
             f"{num(get('fourbar', 'one position', 'mbplanar_us'))} µs per call; `mbplanar solve` end to end "
             f"{num(get('fourbar', 'mbplanar solve', 'cpu_s'))} s of CPU time; `import mbplanar` "
             f"{num(get('mbplanar', 'import', 'cpu_s'))} s ({num(get('mbplanar', 'import and first use', 'cpu_s'))}"
             " s with the first use of the API, which loads numpy). Method, every case and the targets: "
             "[docs/speed.md](docs/speed.md)."]
    prose = [wrap(p) for p in prose]
    lines = [prose[0], "",
             f"| sweep of {doc['n']} positions | µs per position | × closed form | × pylinkage+numba |",
             "|---|---|---|---|"]
    lines += [f"| {label} | {num(get(n, w, 'mbplanar_us'))} | {num(get(n, w, 'ratio'))} | "
              f"{num(get(n, w, 'pylinkage_ratio'))} |" for label, n, w in rows]
    lines += ["", prose[1]]
    return "\n".join(lines) + "\n"


BEGIN, END = "<!-- latest run: written by benchmarks/run.py --docs -->", "<!-- end of the latest run -->"
README = ROOT / "README.md"


def write_between_markers(page, text):
    """Replace what stands between `BEGIN` and `END` in the file `page` with `text`."""
    whole = page.read_text(encoding="utf-8")
    head, rest = whole.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    page.write_text(f"{head}{BEGIN}\n{text}{END}{tail}", encoding="utf-8")


def write_docs(doc):
    """docs/speed.md's latest-run section and the README's speed paragraph from `doc` (a latest.json)."""
    write_between_markers(SPEED_DOC, f"\n{markdown(doc)}\n")
    write_between_markers(README, readme_text(doc))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small sizes, few rounds (smoke run, < 60 s)")
    ap.add_argument("--json", metavar="FILE", nargs="?", const="-", help="write the run as JSON ('-': stdout)")
    ap.add_argument("--docs", action="store_true", help="rewrite docs/speed.md's table from benchmarks/latest.json")
    ap.add_argument("--study", action="store_true", help="only the design-study cases (benchmarks/study.py)")
    ap.add_argument("--no-pylinkage", action="store_true", help="leave pylinkage+numba out")
    ap.add_argument("--processes", type=int, nargs="?", const=7, metavar="ROUNDS",
                    help="only the process cases (start-up; numba's install step, cold and warm start), in ROUNDS "
                         "rounds (default 7)")
    args = ap.parse_args(argv)
    if args.processes:
        print(f"processes, {args.processes} rounds, load {os.getloadavg()[0]:.1f}:")
        cases = process_cases(args.processes, cold=True)
        for t in check_targets(cases):
            if t["value"] is not None:
                print(f"  {'met ' if t['met'] else 'MISS'}  {t['target']}: {fmt(t['value'], 4)} (≤ {t['limit']:g})")
        if args.json:
            text = json.dumps(dict(date=datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
                                   rounds=args.processes, cases=cases), indent=1)
            if args.json == "-":
                print(text)
            else:
                Path(args.json).write_text(text + "\n", encoding="utf-8")
        return 0
    if args.study:  # design batches and Dask: their own script, sizes and JSON
        import study
        study.main(["--quick"] if args.quick else [])
        return 0
    if args.docs:
        write_docs(json.loads(LATEST.read_text(encoding="utf-8")))
        return 0
    quick = args.quick
    rounds, n = (3, 360) if quick else (11, 3600)
    plk_version = None if args.no_pylinkage else pylinkage_version()
    machine = dict(cpu=platform.processor() or platform.machine(), cpus=os.cpu_count(),
                   python=platform.python_version(), numpy=np.__version__,
                   numba=sys.modules["numba"].__version__ if BEST == "numba" else None,
                   pylinkage=plk_version, load_before=os.getloadavg()[0])
    plk_note = plk_version or SKIPPED
    print(f"mbplanar benchmark on equal work — {machine['cpu']}, {machine['cpus']} CPU(s), Python "
          f"{machine['python']}, numpy {machine['numpy']}, numba {machine['numba']}, pylinkage {plk_note}; "
          f"load {machine['load_before']:.1f}")
    print(f"sweeps of N = {n} positions, µs per position, median of {rounds} rounds; every point and angle read:")
    plk = pylinkage_calls(mbplanar.Engine(mbplanar.read_model(ROOT / "models" / "fourbar.toml")), n) \
        if plk_version else None
    cases, builds = sweep_cases(n, rounds, 3, plk)
    print_sweeps(cases)
    print("one position (four-bar, every point with velocities and accelerations), µs per call:")
    one = one_position_cases(rounds, 20, plk[2] if plk else None)
    print("  " + ", ".join(f"{k[:-3]} {v:.1f}" for k, v in one.items() if k.endswith("_us") and v is not None))
    cases.append(one)
    analogues = analogue_case(n, rounds, 3)
    print(f"analogues read after analyse (four-bar): vq, aq {analogues['analogues_us']:.3f} µs/position, v, a "
          f"{analogues['real_us']:.3f}; × {analogues['ratio_to_real']:.3f}")
    cases.append(analogues)
    print("processes:")
    cases += process_cases(3 if quick else 7, cold=not quick)
    slopes = slopes4 = None
    if not quick:
        print("scaling with mechanism size (a crank and k dyads; a crank and k class IV groups):")
        ks = [1, 2, 4, 8, 16, 32]
        slopes = scaling_groups(dyad_chain, "dyads", ks, n, 3)
        slopes4 = scaling_groups(class4_chain, "class IV groups", ks, n, 3)
    targets = check_targets(cases)
    print(f"targets (one core, equal work, backend {BEST}):")
    for t in targets:
        print(f"  {'met ' if t['met'] else 'MISS'}  {t['target']}: {fmt(t['value'], 4)} (≤ {t['limit']:g})")
    machine["load_after"] = os.getloadavg()[0]
    doc = dict(date=datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"), machine=machine,
               n=n, rounds=rounds, backends=BACKENDS, builds=builds, chain_exponents=slopes,
               class4_chain_exponents=slopes4, targets=targets, cases=cases)
    if args.json:
        text = json.dumps(doc, indent=1)
        if args.json == "-":
            print(text)
        else:
            Path(args.json).write_text(text + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
