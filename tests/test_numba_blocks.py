"""The compiled kernels' building blocks (`mbplanar.backends._numba_blocks`), run as Python."""

import math

import numpy as np

from mbplanar.backends._numba_blocks import _turned


def test_turned_cos_and_sin_are_libms_to_a_rounding_and_depend_on_the_angle_alone():
    """cos t and sin t turned from the anchor (the nearest 1/32 rad) equal math.cos and math.sin to one
    rounding of 1 (2.2e-16), far from 0 and across anchors; the answer for t is the same whatever anchor
    the link held before (a fresh one, or its neighbour's), so it cannot depend on the positions solved
    before it or on how a batch is split between threads."""
    rng = np.random.default_rng(5)
    angles = np.concatenate([np.linspace(-7.0, 7.0, 4001), rng.uniform(-1e4, 1e4, 500),
                             [0.0, 1 / 64, -1 / 64, 3 / 64, math.pi / 2, math.pi]])
    fresh, walked = np.full((8, 1), np.nan), np.full((8, 1), np.nan)
    worst = 0.0
    for t in angles:
        fresh[5, 0] = np.nan
        c, s = _turned.py_func(t, fresh, 0)
        worst = max(worst, abs(c - math.cos(t)), abs(s - math.sin(t)))
        assert (c, s) == _turned.py_func(t, walked, 0)  # (walked keeps the anchor of the angle before)
    assert worst <= 2.3e-16
    t = 0.3 + 1 / 64 - 1e-12  # (the largest turn: cos δ and sin δ from their series at |δ| = 1/64)
    assert abs(_turned.py_func(t, fresh, 0)[1] - math.sin(t)) <= 2.3e-16


def test_building_blocks_do_not_inherit_their_first_callers_fastmath():
    """numba compiles a function without an explicit ``fastmath`` with its first caller's, and keeps
    that copy in its cache for every kernel: the design kernel contracts multiplications and additions,
    and the sweep's answers at a motion limit would depend on which kernel was compiled first."""
    from mbplanar.backends import _numba_blocks

    blocks = [getattr(_numba_blocks, name) for name in _numba_blocks.__all__ if name != "_part"]
    assert blocks and all(block.options.get("fastmath") is False for block in blocks)
