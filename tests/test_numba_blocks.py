"""The compiled kernels' building blocks (`mbplanar.backends._numba_blocks`), run as Python."""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

def test_building_blocks_do_not_inherit_their_first_callers_fastmath():
    """numba compiles a function without an explicit ``fastmath`` with its first caller's, and keeps
    that copy in its cache for every kernel: the design kernel contracts multiplications and additions,
    and the sweep's answers at a motion limit would depend on which kernel was compiled first."""
    from mbplanar.backends import _numba_blocks

    blocks = [getattr(_numba_blocks, name) for name in _numba_blocks.__all__ if name != "_part"]
    assert blocks and all(block.options.get("fastmath") is False for block in blocks)


def _exact_ratio(first, det):
    """The pivot ratio of a 2 × 2 block as `engine._linalg.factor` and the kernels formed it: two
    divisions."""
    p0, p1 = first, abs(det / first)
    return min(p0, p1) / max(max(p0, p1), 1e-300)


magnitudes = st.floats(min_value=1e-160, max_value=1e160, allow_nan=False, allow_infinity=False)


@settings(max_examples=400, deadline=None)
@given(first=magnitudes, det=st.one_of(magnitudes, magnitudes.map(lambda v: -v), st.just(0.0)),
       polish=st.one_of(st.just(0.05), st.floats(min_value=0.0, max_value=2.0)))
def test_the_pivot_ratio_shortcut_decides_as_the_two_divisions_do(first, det, polish):
    """The sweep kernel's 2 × 2 pivot ratio without divisions (`_pivot_ratio_2`) answers `polish` only
    where the exact ratio is at least `polish`; elsewhere it is the exact ratio, bit for bit. So Newton's
    polish decision, its one use, is the same."""
    from mbplanar.backends._numba_blocks import _pivot_ratio_2

    got, exact = _pivot_ratio_2.py_func(first, det, polish), _exact_ratio(first, det)
    assert (got >= polish) == (exact >= polish)
    if got != polish:
        assert got == exact


@settings(max_examples=200, deadline=None)
@given(scale=st.floats(min_value=1e-6, max_value=1e6), ratio=st.floats(min_value=0.0, max_value=1.0),
       polish=st.sampled_from([0.05, 0.3, 1.0]))
def test_the_pivot_ratio_shortcut_at_its_threshold(scale, ratio, polish):
    """Blocks whose ratio lies at or around the threshold (f² and |det| set from the ratio wanted, then
    nudged by an ulp either way): the decision is the two divisions' every time."""
    from mbplanar.backends._numba_blocks import _pivot_ratio_2

    for target in (ratio, polish, math.nextafter(polish, 0.0), math.nextafter(polish, 2.0)):
        first = scale
        for det in (first * first * target, math.nextafter(first * first * target, math.inf),
                    -math.nextafter(first * first * target, 0.0)):
            got = _pivot_ratio_2.py_func(first, det, polish)
            assert (got >= polish) == (_exact_ratio(first, det) >= polish)


def test_scalar_codegen_restores_numbas_settings():
    """The kernels' compilation changes numba's vectorizer and optimisation settings for itself alone
    (`_jit._scalar_codegen`): inside they are off and at level 2 at most, after it they are numba's
    again, whatever happened inside."""
    numba = pytest.importorskip("numba")
    from numba.core import config

    from mbplanar.backends import _jit

    before = config.LOOP_VECTORIZE, config.SLP_VECTORIZE, int(config.OPT)
    with pytest.raises(RuntimeError):
        with _jit._scalar_codegen(2):
            assert (config.LOOP_VECTORIZE, config.SLP_VECTORIZE) == (False, False)
            assert int(config.OPT) == min(before[2], 2)
            raise RuntimeError("a failed compilation")
    assert (config.LOOP_VECTORIZE, config.SLP_VECTORIZE, int(config.OPT)) == before
    assert numba.__version__
