"""The kernels' conventions: named bundles (no kernel takes more than 12 parameters), every threshold in the
one `KernelTol` (no number of a kernel module read as a threshold), the same floating-point options
everywhere (fastmath off), numba imported lazily, and one continuation: the acceptance rule and the quintic
Hermite interpolant written once (`engine._continuation`) and compiled as they are for the kernels."""

import ast
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import mbplanar
from mbplanar.backends import _jit
from mbplanar.engine import Tolerances, _continuation
from mbplanar.engine._continuation import (ACCEPT, CROSS, HERMITE5, REJECT, hermite_coefficients, hermite_curvature,
                                           hermite_slope, hermite_value, step_verdict)

ROOT = Path(__file__).resolve().parent.parent
BACKENDS = ROOT / "mbplanar" / "backends"
MODULES = ("_numba_blocks", "_numba_kinematics", "_numba_kinetostatics", "_numba_design")


def _kernel_functions():
    """(module, function name, parameter count) of every function a kernel decorator makes in the kernel
    modules (read from their source: a decorated ``def`` or an assignment of a decorated function)."""
    found = []
    for name in MODULES:
        tree = ast.parse((BACKENDS / f"{name}.py").read_text(encoding="utf-8"))
        for node in tree.body:
            if isinstance(node, ast.FunctionDef) and node.decorator_list:
                found.append((name, node.name, len(node.args.args)))
    return found


def test_no_kernel_takes_more_than_twelve_parameters():
    kernels = _kernel_functions()
    assert {k for _, k, _ in kernels} >= {"_sweep", "_kernel", "_designs", "_walk", "_march", "_solve", "_place"}
    wide = [f"{m}.{k}: {n}" for m, k, n in kernels if n > 12]
    assert not wide, wide
    import mbplanar.backends._numba_design  # noqa: F401  (every kernel module imported: its kernels made)
    import mbplanar.backends._numba_kinematics  # noqa: F401
    import mbplanar.backends._numba_kinetostatics  # noqa: F401
    made = [(k.name, k.py_func.__code__.co_argcount) for k in _jit.kernels()]
    assert made and not [m for m in made if m[1] > 12], made


def test_every_kernel_compiles_with_fastmath_off():
    """The design kernels as the building blocks: no contraction into fused multiply-adds, so that the same
    arithmetic gives the same rounding whichever kernel numba compiles first."""
    import mbplanar.backends._numba_design  # noqa: F401
    options = {k.name: k.options.get("fastmath", False) for k in _jit.kernels()}
    assert options and not [name for name, fm in options.items() if fm], options


def test_kernel_modules_hold_no_threshold_of_their_own():
    """Module-level numbers of the kernel modules are sizes, not thresholds a kernel reads: a kernel reads
    its thresholds from the `KernelTol` it is given."""
    for name in MODULES:
        tree = ast.parse((BACKENDS / f"{name}.py").read_text(encoding="utf-8"))
        numbers = {t.id for node in tree.body if isinstance(node, ast.Assign) and isinstance(node.value, ast.Constant)
                   and isinstance(node.value.value, float) for t in node.targets if isinstance(t, ast.Name)}
        assert not numbers, f"{name}: {numbers}"
    kernel_tol = Tolerances().kernel()
    assert {"turn", "nudge", "lazy_step", "closure", "polish", "pivot_cross", "h_cross"} <= set(kernel_tol._fields)


def test_the_design_kernel_imports_without_numba():
    probe = "import sys\nimport mbplanar.backends._numba_design\nprint('numba' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True, cwd=ROOT,
                         env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    assert out.stdout.split() == ["False"]


def test_the_kernels_compile_the_continuation_as_it_is_written():
    from mbplanar.backends import _numba_blocks as blocks
    for compiled, written in ((blocks._step_verdict, step_verdict), (blocks._rate_jump, _continuation.rate_jump),
                              (blocks._hermite_coefficients, hermite_coefficients),
                              (blocks._hermite_value, hermite_value), (blocks._hermite_slope, hermite_slope)):
        assert compiled.py_func is written
    for module in ("_numba_kinematics", "_numba_design"):
        text = (BACKENDS / f"{module}.py").read_text(encoding="utf-8")
        assert "_hermite_value(" in text and "HERMITE5 @" not in text and "einsum" not in text
    for path in (ROOT / "mbplanar" / "engine" / "_atlas.py", ROOT / "mbplanar" / "study" / "batch.py"):
        text = path.read_text(encoding="utf-8")
        assert "step_verdict(" in text and "hermite_coefficients(" in text and "einsum" not in text


def test_step_verdict_on_arrays_is_the_verdict_of_each_element():
    tol = Tolerances()
    rng = np.random.default_rng(3)
    n = 400
    converged, same = rng.random(n) < 0.8, rng.random(n) < 0.7
    ratio = 10 ** rng.uniform(-12, 0, n)
    dist = 10 ** rng.uniform(-9, 0, n)
    jump = 10 ** rng.uniform(-4, 0.5, n)
    h = 10 ** rng.uniform(-3, -0.5, n)
    dist[::17] = np.nan
    got = step_verdict(converged, ratio, dist, jump, same, h, tol)
    for k in range(n):
        good = (converged[k] and ratio[k] >= tol.pivot_cross and dist[k] <= tol.max_correction
                and jump[k] <= tol.rate_jump)
        want = ACCEPT if good and same[k] else CROSS if good and h[k] <= tol.h_cross and dist[k] <= tol.cross_dist \
            else REJECT
        assert got[k] == want == step_verdict(bool(converged[k]), ratio[k], dist[k], jump[k], bool(same[k]), h[k], tol)


finite = st.floats(-10.0, 10.0, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(st.lists(finite, min_size=6, max_size=6), st.floats(0.05, 3.0), st.floats(0.0, 1.0))
def test_the_interpolant_reproduces_a_quintic_and_its_derivatives(coefs, width, t):
    """A quintic p(φ) on [0, width]: the interpolant built from p, p', p'' at the ends is p itself, its
    slope and curvature p' and p'' (to rounding)."""
    p = np.polynomial.Polynomial(coefs)
    d1, d2 = p.deriv(), p.deriv(2)
    ends = (p(0.0), p(width), width * d1(0.0), width * d1(width), width * width * d2(0.0), width * width * d2(width))
    c = hermite_coefficients(*ends, HERMITE5)
    x = t * width
    scale = 1.0 + sum(abs(v) for v in coefs) * (1.0 + width) ** 5
    assert math.isclose(hermite_value(*c, t), p(x), rel_tol=0, abs_tol=1e-12 * scale)
    assert math.isclose(hermite_slope(*c[1:], t) / width, d1(x), rel_tol=0, abs_tol=1e-11 * scale / width)
    assert math.isclose(hermite_curvature(*c[2:], t) / width ** 2, d2(x), rel_tol=0, abs_tol=1e-10 * scale / width ** 2)
    # on arrays, elementwise, the same numbers
    arr = hermite_coefficients(*(np.full(3, e) for e in ends), HERMITE5)
    assert np.array_equal(hermite_value(*arr, np.full(3, t)), np.full(3, hermite_value(*c, t)))


def test_one_engine_one_position_sweep_and_design_agree():
    """The same continuation serves the sweep and the design batch: a design batch of the model's own
    dimensions gives the sweep's positions (numpy's engine; to the batch's rounding)."""
    from mbplanar.study import design_batch
    model = ROOT / "models" / "fourbar_design.toml"
    batch = design_batch(model, {"a": np.array([0.1])})
    phi = batch.geometry.phi0[0] + np.radians(np.arange(0.0, 360.0, 10.0))
    dm = batch.solve(phi)
    engine = batch.engine_of(0)
    m = mbplanar.analyse(engine, phi)
    for k, name in enumerate(dm.points):
        np.testing.assert_allclose(dm.xy[0, :, k], m.xy[:, m.point(name)], rtol=0, atol=1e-12)
