"""The compiled kernels' building blocks (`mbplanar.backends._numba_blocks`), run as Python."""



def test_building_blocks_do_not_inherit_their_first_callers_fastmath():
    """numba compiles a function without an explicit ``fastmath`` with its first caller's, and keeps
    that copy in its cache for every kernel: the design kernel contracts multiplications and additions,
    and the sweep's answers at a motion limit would depend on which kernel was compiled first."""
    from mbplanar.backends import _numba_blocks

    blocks = [getattr(_numba_blocks, name) for name in _numba_blocks.__all__ if name != "_part"]
    assert blocks and all(block.options.get("fastmath") is False for block in blocks)
