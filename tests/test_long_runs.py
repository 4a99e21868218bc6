"""Fail fast, say why, show progress (issue 27, item 4): `simulate` finds a stall as it happens (or, for a
machine of `[dynamics]`, before it integrates) and names what the model lacks; long runs show a progress
bar with the time left on a terminal, stop on Ctrl-C with exit status 130 keeping what they wrote, and a
request estimated above 10 minutes says so first and runs only with --yes.

The processes are real (`python -m mbplanar`), interrupted by SIGINT; the terminal is a pseudo-terminal.
"""

import csv
import fcntl
import io
import json
import os
import pty
import select
import signal
import struct
import subprocess
import sys
import termios
import time
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from mbplanar._progress import LONG_RUN, LongRun, Progress, confirm_long_run, duration
from mbplanar.forces._dynamics import machine_dynamics, stall_ahead
from mbplanar.forces._simulation import read_simulate, simulate_motion

from test_units import run

HERE = Path(__file__).resolve().parent
MODELS = HERE.parent / "models"
SHAPER = MODELS / "shaper.toml"
pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="SIGINT and pseudo-terminals are POSIX here")


def _cli(*argv, **kw):
    return subprocess.Popen([sys.executable, "-m", "mbplanar", *map(str, argv)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, **kw)


def _wait_for(path: Path, lines: int, proc, timeout: float = 60.0):
    """Wait until `path` holds at least `lines` lines (the run is under way)."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if path.exists() and path.read_text().count("\n") >= lines:
            return
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.05)
    raise AssertionError(f"{path} did not grow to {lines} lines")


def _cpu_seconds(pid: int) -> float | None:
    """The CPU time a running process has used (Linux's /proc), or None where it cannot be read."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return None
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _interrupted_after(proc, seconds: float) -> str:
    """SIGINT to the running `proc` once it has computed for `seconds` of CPU time (of wall time where the
    CPU time cannot be read), so that a loaded machine does not interrupt it before it is under way: it
    exits 130; its last line on stderr."""
    end = time.monotonic() + 20 * seconds
    while time.monotonic() < end and proc.poll() is None:
        used = _cpu_seconds(proc.pid)
        if used is None:
            time.sleep(seconds)
            break
        if used >= seconds:
            break
        time.sleep(0.05)
    assert proc.poll() is None, proc.communicate()
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    return err.strip().splitlines()[-1]


# -- simulate: stalls ----------------------------------------------------------------------------------
def test_the_shaper_without_its_flywheel_stalls_at_once_and_says_why():
    """`simulate models/shaper.toml --t 0.05`: the machine of its [dynamics] (M_dr = 102.058 N·m, from
    ω_m) cannot run through its cycle without a flywheel: refused at once (≤ 5 s), one line naming the
    flywheel and --input-inertia, exit 1."""
    import resource
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    proc = _cli("simulate", SHAPER, "--t", "0.05")
    out, err = proc.communicate(timeout=60)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    seconds = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime  # CPU: the load does not count
    assert proc.returncode == 1 and out == "" and len(err.strip().splitlines()) == 1, err
    assert err.startswith(f"mbplanar: {SHAPER}: f stalls at t ≈ 0.0975") and "the model has no flywheel" in err
    assert "--input-inertia" in err and "J_I = 147.141 kg·m² for δ = 0.05" in err
    assert seconds <= 5.0, seconds


def test_the_shaper_runs_with_its_flywheel_on_the_command_line_or_in_dynamics(tmp_path):
    code, out, err = run("simulate", SHAPER, "--t", "0.05", "--input-inertia", "147.141", "--json")
    assert code == 0, err
    omega = json.loads(out)["inputs"]["f"]["omega"]
    assert min(omega) > 0.9 * 7.64454 and max(omega) < 1.1 * 7.64454     # it runs near ω_m
    text = SHAPER.read_text(encoding="utf-8").replace("density = 7800", "density = 7800\ninertia = 147.141")
    model = tmp_path / "shaper_flywheel.toml"
    model.write_text(text, encoding="utf-8")
    code, out2, err = run("simulate", model, "--t", "0.05", "--json")
    assert code == 0, err
    assert json.loads(out2)["inputs"]["f"]["omega"] == pytest.approx(omega, rel=1e-12)


def test_the_stall_found_in_time_is_where_the_energy_equation_puts_it(engine_of):
    """Driven by M_dr from ω_m with no flywheel (given explicitly, so no check beforehand), the time
    integration stops where the input's speed falls to zero; the energy equation in φ (`stall_ahead`,
    an independent integration over the cycle grid) puts the stop at the same time and place."""
    engine = engine_of("shaper")
    dyn = machine_dynamics(engine, simulate_motion=False)
    phi0, om0 = float(engine.phi_drawn[0]), dyn.spec.omega_mean
    phi_stop, t_stop = stall_ahead(dyn, dyn.input_link_inertia, phi0, om0)
    spec = read_simulate(engine.mech, t=0.5, torque=[dyn.driving_moment], omega=[om0], input_inertia=[0.0])
    with pytest.raises(mbplanar.MotionError, match=r"f stalls at t = (\S+) s \(f = (\S+) deg\): its speed falls to "
                                                   r"zero and the drive cannot restart it") as info:
        simulate_motion(engine, spec)
    t, f = (float(x) for x in __import__("re").search(r"t = (\S+) s \(f = (\S+) deg", str(info.value)).groups())
    assert t == pytest.approx(t_stop, rel=2e-3)
    assert np.radians(f) == pytest.approx(engine.inputs[0].from_si(phi_stop) * np.pi / 180, abs=2e-3)


def test_a_machine_at_rest_that_its_drive_cannot_start_stalls_at_t_0():
    code, out, err = run("simulate", SHAPER, "--t", "0.05", "--torque", "0")
    assert code == 1 and out == ""
    assert "f stalls at t = 0 s (f = 140.769 deg): its speed is zero and the drive cannot start it" in err
    assert "give a drive that overcomes the loads there (--torque" in err


def test_a_swing_through_zero_speed_is_not_a_stall(tmp_path):
    """A four-bar under gravity let go from rest swings back and forth: its speed passes through zero
    with the loads pushing it back the way it came, which is no stall; the energy stays constant."""
    text = (MODELS / "fourbar.toml").read_text(encoding="utf-8")
    model = tmp_path / "pendulum.toml"
    model.write_text(text.replace('{ name = "2", length = 0.30 }', '{ name = "2", length = 0.30, mass = 2.0, '
                                  'centre = "M" }') + "\n[gravity]\ng = 9.81\n", encoding="utf-8")
    code, out, err = run("simulate", model, "--t", "1.0", "--steps", "100", "--json", "--rtol", "1e-9")
    assert code == 0, err
    doc = json.loads(out)
    omega = np.array(doc["inputs"]["phi"]["omega"])
    assert np.sum(np.diff(np.sign(omega[np.abs(omega) > 1e-9])) != 0) >= 1      # it turned back
    e = doc["energy"]
    total = np.array(e["kinetic"]) + np.array(e["potential"])
    assert np.ptp(total) < 1e-7 * np.max(np.abs(e["potential"]))


def test_the_stepped_integration_gives_solve_ivps_numbers(engine_of):
    """The solver stepped here (for progress, Ctrl-C and stalls) gives what solve_ivp gives with t_eval,
    bit for bit: the same solver, the same steps, the same dense output."""
    from scipy.integrate import solve_ivp
    from mbplanar.forces import _simulation as sim
    engine = engine_of("squeezer")
    spec = sim._drive(engine, sim.read_simulate(engine.mech, t=0.002, steps=7))[0]
    n, J = 1, np.zeros(1)

    def rhs(t, y):
        q, qd = y[:n], y[n:2 * n]
        M, b, drive, _ = sim._mass_and_forces(engine, sim._columns(engine, q, qd), qd, spec, J)
        return np.concatenate([qd, sim._solve_mass(engine, M, b), [float(drive @ qd)]])
    y0 = np.array([engine.phi_drawn[0], 0.0, 0.0])
    ref = solve_ivp(rhs, (0.0, spec.t), y0, method=spec.method, t_eval=np.linspace(0.0, spec.t, 8),
                    rtol=spec.rtol, atol=spec.atol)
    t, y, ok, message = sim._integrate(rhs, y0, spec, n, sim._Stall(engine, spec, J, None), None)
    assert ok and message == ref.message
    assert np.array_equal(t, ref.t) and np.array_equal(y, ref.y.T)


# -- Ctrl-C -----------------------------------------------------------------------------------------
def test_ctrl_c_stops_a_sweep_keeping_the_rows_written(tmp_path):
    out = tmp_path / "long.csv"
    proc = _cli("sweep", MODELS / "fourbar.toml", "--steps", "3000000", "-o", out, "--forces", "no")
    _wait_for(out, 20001, proc)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"mbplanar: {MODELS / 'fourbar.toml'}: interrupted (Ctrl-C): "
                                                   "wrote the first ")
    written = int(lines[0].split("wrote the first ")[1].split(" ")[0])
    rows = list(csv.reader(io.StringIO(out.read_text())))
    assert rows[0][0].startswith("phi") and len(rows) - 1 >= written >= 20000
    assert float(rows[written][0]) == pytest.approx(360.0 * (written - 1) / 3000000, rel=1e-9)


def test_ctrl_c_stops_a_simulation_writing_the_motion_so_far(tmp_path):
    out = tmp_path / "motion.csv"
    proc = _cli("simulate", SHAPER, "--t", "200", "--input-inertia", "147.141", "--steps", "2000", "-o", out,
                "--yes", "--rtol", "1e-6")
    last = _interrupted_after(proc, 3.0)
    assert "interrupted (Ctrl-C) at t = " in last and f"wrote the motion up to t = " in last
    rows = list(csv.reader(io.StringIO(out.read_text())))
    assert rows[0][:2] == ["t[s]", "f[rad]"] and len(rows) > 2
    t_end = float(last.split("wrote the motion up to t = ")[1].split(" s")[0])
    assert float(rows[-1][0]) == pytest.approx(t_end, rel=1e-5)


def test_ctrl_c_stops_a_study_writing_the_designs_done(tmp_path):
    table = tmp_path / "many.csv"
    lines = ["variant,l3"] + [f"{k},{1.0 + 0.4 * (k % 50) / 50}" for k in range(4000)]
    table.write_text("\n".join(lines) + "\n")
    out = tmp_path / "summary.csv"
    proc = _cli("study", MODELS / "crank_slider_rocker.toml", "--variants", table, "-o", out, "--chunk", "4",
                "--no-progress", "--yes")
    last = _interrupted_after(proc, 3.0)
    done = int(last.split("interrupted (Ctrl-C) after ")[1].split(" ")[0])
    assert f"wrote the {done} designs done to {out}" in last
    rows = list(csv.reader(io.StringIO(out.read_text())))
    assert len(rows) - 1 == done > 0 and rows[1][0] == "0"


# -- estimates -------------------------------------------------------------------------------------
def test_a_sweep_estimated_above_ten_minutes_is_refused_before_it_starts(tmp_path):
    out = tmp_path / "never.csv"
    start = time.monotonic()
    proc = _cli("sweep", MODELS / "fourbar.toml", "--steps", "1e8", "-o", out)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 2 and time.monotonic() - start < 20
    assert err.startswith(f"mbplanar: {MODELS / 'fourbar.toml'}: a sweep of 100000001 positions would take about ")
    assert "(the first 20000 took " in err and "more than 10 min: add --yes to run it anyway, or ask for less" in err
    assert not out.exists()


def test_a_long_simulation_is_refused_after_its_probe():
    start = time.monotonic()
    proc = _cli("simulate", SHAPER, "--t", "1000", "--input-inertia", "147.141")
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 2 and out == "" and time.monotonic() - start < 20, err
    assert f"{SHAPER}: simulating 1000 s of motion would take about " in err and "add --yes" in err


def test_with_yes_a_long_run_says_so_and_goes_on(tmp_path):
    log = tmp_path / "stderr.txt"
    with open(log, "w") as err_file:
        proc = subprocess.Popen([sys.executable, "-m", "mbplanar", "sweep", str(MODELS / "fourbar.toml"), "--steps",
                                 "1e8", "--yes", "-o", str(tmp_path / "big.csv")], stderr=err_file,
                                stdout=subprocess.DEVNULL)
        deadline = time.monotonic() + 60
        while "going on" not in log.read_text() and time.monotonic() < deadline:
            assert proc.poll() is None
            time.sleep(0.1)
        proc.send_signal(signal.SIGINT)
        proc.wait(timeout=60)
    err = log.read_text()
    assert "would take about" in err and "going on (--yes)" in err and proc.returncode == 130


def test_the_estimate_rule():
    assert LONG_RUN == 600.0
    confirm_long_run(600.0, "x", "probe")          # at the limit: goes on
    with pytest.raises(LongRun, match="x would take about 10 min"):
        confirm_long_run(601.0, "x", "probe")
    assert [duration(s) for s in (5, 600, 7200, 3e5)] == ["5 s", "10 min", "2.0 h", "3.5 days"]


# -- progress on a terminal ------------------------------------------------------------------------
def _on_a_terminal(argv, stdin_text=None, timeout=90.0):
    """Run the CLI with stderr (and stdin) on a pseudo-terminal: its exit status and what it drew there."""
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))   # a terminal has a size
    proc = subprocess.Popen([sys.executable, "-m", "mbplanar", *map(str, argv)], stdout=subprocess.DEVNULL,
                            stderr=slave, stdin=slave if stdin_text is not None else subprocess.DEVNULL)
    os.close(slave)
    seen, end = b"", time.monotonic() + timeout
    sent = False
    while time.monotonic() < end:
        ready, _, _ = select.select([master], [], [], 0.2)
        if ready:
            try:
                chunk = os.read(master, 4096)
            except OSError:
                break
            if not chunk:
                break
            seen += chunk
            if stdin_text is not None and not sent and b"Go on?" in seen:
                os.write(master, stdin_text.encode())
                sent = True
        elif proc.poll() is not None:
            break
    proc.wait(timeout=30)
    os.close(master)
    return proc.returncode, seen.decode("utf-8", "replace")


def test_a_sweep_shows_progress_with_the_time_left_on_a_terminal(tmp_path):
    code, seen = _on_a_terminal(["sweep", MODELS / "fourbar.toml", "--steps", "60000", "--forces", "no",
                                 "-o", tmp_path / "s.csv"])
    assert code == 0, seen
    assert "positions" in seen and "%" in seen and ("<" in seen or "left" in seen)   # tqdm's [elapsed<left]
    code, _, err = run("sweep", MODELS / "fourbar.toml", "--steps", "600", "-o", tmp_path / "t.csv")
    assert code == 0 and err == ""            # not a terminal: no bar


def test_a_simulation_shows_progress_on_a_terminal():
    code, seen = _on_a_terminal(["simulate", MODELS / "squeezer.toml", "--t", "0.003"])
    assert code == 0 and "s of motion" in seen, seen


def test_on_a_terminal_a_long_run_asks_and_no_means_no(tmp_path):
    code, seen = _on_a_terminal(["sweep", MODELS / "fourbar.toml", "--steps", "1e8", "-o", tmp_path / "n.csv"],
                                stdin_text="n\n")
    assert "would take about" in seen and "Go on? [y/N]" in seen and code == 2
    assert not (tmp_path / "n.csv").exists()


def test_the_plain_progress_line_without_tqdm(monkeypatch, capsys):
    """Without tqdm the bar is a plain line with the count, the percentage and the time left."""
    monkeypatch.setitem(sys.modules, "tqdm", None)
    with Progress(4, "designs", show=True, guard=False) as bar:
        for k in range(1, 5):
            bar.update(k)
    err = capsys.readouterr().err
    assert "4/4 designs (100 %)" in err and "left" in err


def test_the_estimate_leaves_one_off_costs_out(monkeypatch):
    """A compile before the first report (9 s for one step) does not count: the pace is timed from the
    first report on. 1000 steps of 10 ms after it: at 2 s past it (step 201) the run has taken 11 s and has
    799 steps left at 10 ms, an estimate of 18.99 s (not 11 s × 1000/201 = 54.7 s)."""
    import mbplanar._progress as progress
    clock = [0.0]
    monkeypatch.setattr(progress.time, "perf_counter", lambda: clock[0])
    asked = []
    monkeypatch.setattr(progress, "confirm_long_run", lambda estimate, *a, **k: asked.append(estimate))
    bar = Progress(1000, "steps", show=False, what="x")
    for k in range(1, 400):
        clock[0] = 9.0 + 0.01 * (k - 1)
        bar.update(k)
    assert asked == [pytest.approx(11.0 + 2.0 * 799 / 200, rel=1e-9)]
