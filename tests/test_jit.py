"""The compiled kernels' decorator (`mbplanar.backends._jit`): numba's on-disk cache of a kernel is tied
to every kernel module, since a kernel inlines the building blocks of the others."""

import os

import pytest

numba = pytest.importorskip("numba")

from mbplanar.backends import _jit, _numba_design, _numba_kinematics  # noqa: E402


def _stamp(dispatcher) -> str:
    return dispatcher._cache._cache_file._source_stamp


@pytest.mark.parametrize("dispatcher", [_numba_kinematics._sweep.dispatcher, _numba_design._block_rates],
                         ids=["sweep", "design"])
def test_cached_kernel_is_checked_against_every_kernel_module(dispatcher):
    stamp = _stamp(dispatcher)
    assert stamp == _jit._kernel_sources_stamp()
    folder = os.path.dirname(_jit.__file__)
    blocks = os.stat(os.path.join(folder, "_numba_blocks.py"))
    assert f"_numba_blocks.py:{blocks.st_size}:{blocks.st_mtime_ns}" in stamp.splitlines()
    assert "_tables.py:" in stamp and "_numba_kinetostatics.py:" in stamp
