"""What a new process loads: `import mbplanar` loads neither numpy nor a subpackage (each public name loads
its own on first use) and leaves the heavy optional packages alone, `mbplanar solve` imports only its own
command's code, and the compiled backend is imported when a batch reaches it.
(Behaviour, not timing: the times are in benchmarks/startup.py.)"""

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from mbplanar.cli import CORE_COMMANDS, OWN_MODULE, build_parser, command_in, main

ROOT = Path(__file__).resolve().parent.parent
HEAVY = ("scipy", "networkx", "matplotlib", "numba", "dask")


def _loaded_after(code: str) -> set[str]:
    """The top-level packages and mbplanar subpackages a new process has loaded after running `code`."""
    probe = (code + "\nimport json, sys\n"
             "print(json.dumps(sorted({m.split('.')[0] for m in sys.modules} | {m for m in sys.modules "
             "if m.startswith('mbplanar.') and m.count('.') == 1})))")
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    done = subprocess.run([sys.executable, "-c", probe], cwd=ROOT, env=env, capture_output=True, text=True,
                          check=True)
    return set(json.loads(done.stdout.splitlines()[-1]))


def test_import_mbplanar_leaves_the_heavy_packages_alone():
    loaded = _loaded_after("import mbplanar")
    assert "mbplanar" in loaded and not loaded & set(HEAVY)


def test_import_mbplanar_loads_the_public_names_on_first_use():
    """`import mbplanar` loads neither numpy nor a subpackage; a public name loads its own subpackage."""
    loaded = _loaded_after("import mbplanar")
    ours = {m for m in loaded if m.startswith("mbplanar.")}
    assert "numpy" not in loaded and ours <= {"mbplanar.errors"}
    loaded = _loaded_after("import mbplanar\nmbplanar.Engine")
    assert {"numpy", "mbplanar.engine"} <= loaded and not loaded & {"mbplanar.forces", "mbplanar.analysis"}


def test_a_forces_name_loads_only_its_own_module():
    probe = ("from mbplanar.forces import Kinetostatics\nimport sys\n"
             "print(sorted(m for m in sys.modules if m.startswith('mbplanar.forces.')))")
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    out = subprocess.run([sys.executable, "-c", probe], cwd=ROOT, env=env, capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["['mbplanar.forces._kinetostatics',", "'mbplanar.forces._loads']"]
    import mbplanar.forces as forces
    assert set(forces.__all__) <= set(dir(forces)) and all(getattr(forces, name) for name in forces.__all__)


def test_the_cad_names_of_io_load_on_first_use():
    """`mbplanar.io` exports the CAD sheet and writers (the cam, the gears and the drawing share them) without
    loading them: a command that writes no drawing does not import `io._cad`; a misspelt name is an error."""
    probe = ("import sys, mbplanar.io as io\nprint('mbplanar.io._cad' in sys.modules)\n"
             "print(io.Sheet.__module__, 'mbplanar.io._cad' in sys.modules)")
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    out = subprocess.run([sys.executable, "-c", probe], cwd=ROOT, env=env, capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "mbplanar.io._cad", "True"]
    import mbplanar.io
    assert {"Sheet", "write_dxf"} <= set(dir(mbplanar.io))
    with pytest.raises(AttributeError, match="no attribute 'Sheets'"):
        mbplanar.io.Sheets


def test_the_lazy_public_names_are_the_subpackages_own():
    import mbplanar
    from mbplanar import analysis, engine, errors, forces, kinematics, model, web
    homes = (errors, analysis, engine, forces, kinematics, model, web)
    for name in mbplanar.__all__:
        home = next(h for h in homes if name in h.__all__)
        assert getattr(mbplanar, name) is getattr(home, name), name
    assert callable(mbplanar.check) and callable(mbplanar.kinetostatics)
    assert set(mbplanar.__all__) <= set(dir(mbplanar)) and mbplanar.forces is forces
    with pytest.raises(AttributeError, match="no attribute 'nonsense'"):
        mbplanar.nonsense


def test_solve_imports_only_its_own_command():
    solve = ("import contextlib, io\nfrom mbplanar.cli import main\n"
             "with contextlib.redirect_stdout(io.StringIO()):\n"
             "    assert main(['solve', 'models/fourbar.toml', '--at', '30']) == 0")
    _loaded_after(solve)  # the first run fills the engine cache (networkx is imported to build it)
    loaded = _loaded_after(solve)
    assert not loaded & set(HEAVY)
    assert not loaded & {"mbplanar.synthesis", "mbplanar.cam", "mbplanar.study", "mbplanar.viz"}
    # nor what other commands print (the forces, the analysis), nor hashlib (the engine cache), nor csv, nor
    # a kernel (one position: the backends decline, `Backend.should_run`, and numpy solves it)
    assert not loaded & {"mbplanar.forces", "mbplanar.analysis", "hashlib", "csv", "mbplanar.backends._jit",
                         "mbplanar.backends._numba_kinematics"}


@pytest.mark.skipif(importlib.util.find_spec("numba") is None, reason="numba not installed")
def test_one_position_on_the_compiled_backend_does_not_load_numba():
    """numba's start (~0.6 s) would cost a one-position command far more than the position (`pays`)."""
    commands = [["solve", "models/fourbar.toml", "--at", "30"], ["forces", "models/fourbar_loaded.toml", "--at", "30"]]
    loaded = _loaded_after("import contextlib, io\nfrom mbplanar.cli import main\n"
                           "with contextlib.redirect_stdout(io.StringIO()):\n"
                           + "".join(f"    assert main(['--backend', 'numba', *{c!r}]) == 0\n" for c in commands))
    assert "numba" not in loaded and "mbplanar.backends" in loaded


@pytest.mark.skipif(importlib.util.find_spec("numba") is None, reason="numba not installed")
def test_the_compiled_backend_is_imported_when_a_batch_reaches_it():
    loaded = _loaded_after("import mbplanar\n"
                           "engine = mbplanar.Engine(mbplanar.read_model('models/fourbar.toml'), backend='numba')\n"
                           "assert (engine.backend, engine.topology.structure.dof) == ('numba', 1)")
    assert "numba" not in loaded and "networkx" in loaded


def test_a_backend_whose_package_is_missing_is_refused_when_the_engine_is_made(monkeypatch):
    import mbplanar
    from mbplanar.engine._backend import BACKENDS
    from mbplanar.errors import MbplanarError
    monkeypatch.setitem(BACKENDS, "fortran", ("mbplanar.backends._fortran", "no_such_package_here", "fortran"))
    mech = mbplanar.read_model(ROOT / "models" / "fourbar.toml")
    with pytest.raises(MbplanarError, match=r"'fortran' needs no_such_package_here: pip install 'mbplanar\[fortran\]'"):
        mbplanar.Engine(mech, backend="fortran")
    with pytest.raises(ValueError, match="backend must be one of"):
        mbplanar.Engine(mech, backend="cobol")


@pytest.mark.parametrize("argv, command", [
    (["solve", "m.toml", "--at", "30"], "solve"),
    (["--backend", "numba", "--threads", "2", "sweep", "m.toml"], "sweep"),
    (["--debug", "--threads", "2", "cam", "c.toml"], "cam"),
    (["--no-cache", "study", "m.toml"], "study"),
    (["synth", "seed001"], "synth"),
    (["--back", "numba", "cam", "c.toml"], None),  # an abbreviated option: every command is built
    (["-h"], None),
    (["--debug", "--help", "solve"], None),  # the global help lists every command
    (["solve", "--help"], "solve"),
    (["nonsense"], None),
])
def test_the_command_is_found_before_parsing(argv, command):
    assert command_in(argv) == command


def _help_of(parser, argv) -> str:
    """What `parser` prints for argv (its help, or its usage and error)."""
    import contextlib
    import io
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out), pytest.raises(SystemExit):
        parser.parse_args(argv)
    return out.getvalue()


@pytest.mark.parametrize("command", sorted(set(CORE_COMMANDS) | set(OWN_MODULE)))
def test_the_parser_of_one_command_reads_as_the_whole_parser(command):
    """Only the running command's parser is built; its help, and the usage line of a global option's
    error, are those of the whole parser, and it parses the same."""
    whole, one = build_parser(), build_parser(command)
    assert _help_of(one, [command, "--help"]) == _help_of(whole, [command, "--help"])
    assert _help_of(one, ["--threads", "0", command]) == _help_of(whole, ["--threads", "0", command])
    argv = ["--backend", "numba", "solve", "m.toml", "--at", "30", "--omega", "2", "--json"]
    if command == "solve":
        assert vars(one.parse_args(argv)) == vars(whole.parse_args(argv))


def test_every_command_is_listed_once():
    sub = next(a for a in build_parser("")._actions if a.dest == "command")
    assert set(sub.choices) == set(CORE_COMMANDS) | set(OWN_MODULE)
    assert not set(CORE_COMMANDS) & set(OWN_MODULE)


@pytest.mark.parametrize("command, option", [("cam", "--plot-output"), ("study", "--variants"),
                                             ("synth", "seed001")])
def test_a_command_in_its_own_package_shows_its_options(command, option, capsys):
    assert main([command, "-h"]) == 0
    assert option in capsys.readouterr().out


def _blas_threads_after(code: str, **env) -> str:
    """OPENBLAS_NUM_THREADS as a new process running `code` sees it, without the BLAS variables of this
    environment unless given in `env`."""
    from mbplanar.cli import BLAS_THREADS
    clean = {k: v for k, v in os.environ.items() if k not in BLAS_THREADS}
    done = subprocess.run([sys.executable, "-c", code + "\nimport os\nprint(os.environ.get('OPENBLAS_NUM_THREADS'))"],
                          cwd=ROOT, env=dict(clean, PYTHONPATH=str(ROOT), **env), capture_output=True, text=True,
                          check=True)
    return done.stdout.split()[-1]


def test_the_command_line_runs_blas_on_one_thread_unless_told():
    """The command line sets OpenBLAS to one thread before numpy starts its threads; a user's own setting
    (OPENBLAS_NUM_THREADS, OMP_NUM_THREADS) wins, and the library and a program that imported numpy first
    are left alone."""
    cli = "import mbplanar.cli\nimport numpy"
    assert _blas_threads_after(cli) == "1"
    assert _blas_threads_after(cli, OPENBLAS_NUM_THREADS="2") == "2"
    assert _blas_threads_after(cli, OMP_NUM_THREADS="3") == "None"
    assert _blas_threads_after("import numpy\nimport mbplanar.cli") == "None"
    assert _blas_threads_after("import mbplanar\nmbplanar.Engine, mbplanar.analyse") == "None"


def test_the_process_exits_with_the_commands_status_and_its_heap_frozen(tmp_path):
    """`python -m mbplanar` (and the `mbplanar` script, `cli.run`) gives the command's exit status and
    output; the heap is frozen before the interpreter's exit (no collection over it), the written file
    whole."""
    probe = ("import atexit, gc, sys\n"
             "atexit.register(lambda: print('frozen', gc.get_freeze_count() > 0, file=sys.stderr))\n"
             "from mbplanar.cli import run\nsys.exit(run())")
    env = dict(os.environ, PYTHONPATH=str(ROOT), MBPLANAR_CACHE_DIR=str(tmp_path / "cache"))
    out = tmp_path / "sweep.csv"
    for argv, status in ([["sweep", "models/fourbar.toml", "--steps", "7", "-o", str(out)], 0],
                         [["solve", "models/fourbar.toml", "--at", "30,40"], 2],
                         [["solve", "models/crank_slider_rocker_locking.toml", "--at", "1e6"], 1]):
        done = subprocess.run([sys.executable, "-c", probe, *argv], cwd=ROOT, env=env, capture_output=True, text=True)
        assert done.returncode == status, done.stderr
        assert done.stderr.endswith("frozen True\n"), done.stderr
        module = subprocess.run([sys.executable, "-m", "mbplanar", *argv], cwd=ROOT, env=env, capture_output=True,
                                text=True)
        assert (module.returncode, module.stdout) == (done.returncode, done.stdout)
    assert len(out.read_text().splitlines()) == 9
