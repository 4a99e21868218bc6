"""The compiled kernels' decorator (`mbplanar.backends._jit`): a kernel module imports without numba, and
numba's cache folder of the kernels is checked against their sources (`_aot.prepare`) when the first
kernel of a process is made, before numba loads anything from it."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

numba = pytest.importorskip("numba")

from mbplanar.backends import _aot, _jit, _numba_design, _numba_kinematics  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.parametrize("kernel", [_numba_kinematics._sweep, _numba_design._designs], ids=["sweep", "design"])
def test_a_kernels_cache_folder_is_checked_when_it_is_made(kernel):
    folder = Path(kernel.dispatcher.stats.cache_path)
    assert folder == Path(_jit.cache_path())
    assert _aot.prepare(folder)["digest"] == _aot.digest()
    assert json.loads((folder / _aot.INDEX).read_text())["digest"] == _aot.digest()


def test_kernel_modules_import_without_numba():
    probe = ("import sys\nfrom mbplanar.backends import _numba_kinematics, _numba_kinetostatics, "
             "_numba_design\nprint('numba' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", probe], env=dict(os.environ, PYTHONPATH=str(ROOT)),
                         capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False"]
