"""The numba backend: the compiled kinematics, kinetostatics and design batches of one-input problems
behind the seam (`mbplanar.engine._backend`). It says which requests it can take and which it should
(`can_run`, `should_run`: True or why not) and computes what numpy would, equal to rounding."""

from __future__ import annotations

import sys

from ._python import sweep_can_run
from ..engine import planned

__all__ = ["BACKEND", "NumbaBackend", "PAYS_FROM", "pays"]

#: positions from which a new process gains by loading the compiled kernels: importing numba and loading
#: the kernels from its cache (``mbplanar compile`` fills it) costs 0.5 to 0.8 s of CPU per process, almost
#: all of it numba's own start and stop (docs/speed.md, "Start-up"), the kernels save about 1 µs per position
PAYS_FROM = 500_000


def _kernels():
    """The kernel modules, imported on first use (numba only when a kernel is compiled: `_jit`)."""
    if not _loaded:
        from . import _numba_kinematics, _numba_kinetostatics
        _loaded.extend((_numba_kinematics, _numba_kinetostatics))
    return _loaded


_loaded: list = []


def pays(positions: int) -> bool | str:
    """True when a process that plans `positions` positions gains by loading the compiled kernels (a
    process that has loaded numba already always does), else why not."""
    if "numba" in sys.modules or positions >= PAYS_FROM:
        return True
    return f"{positions} positions planned: loading numba and the kernels (0.5 to 0.8 s) pays from {PAYS_FROM}"


class NumbaBackend:
    """Compiled per-position loops for one-input problems (`_numba_kinematics`, `_numba_kinetostatics`,
    `_numba_design`)."""

    name = "numba"

    def should_run(self, job: str, size: int) -> bool | str:
        """The compiled loops take kinematics, kinetostatics and design batches, wherever loading them
        pays in this process (`engine._backend.planned`; a long-lived process: always)."""
        if job not in ("kinematics", "kinetostatics", "design"):
            return f"no compiled {job}"
        return True if planned.positions is None else pays(max(size, planned.positions))

    def can_run(self, job: str, request) -> bool | str:
        """True for a request the kernels hold, else why not: the request's own reason where its layer
        could not write one for the kernels (a str: several inputs, higher pairs, ...; a kinetostatics
        program's `why`), a position next to a change point (`sweep_can_run`)."""
        if isinstance(request, str):
            return request
        if job == "kinematics":
            return sweep_can_run(request)
        if job == "kinetostatics":  # (the program, where one could be written)
            return True if request.program is not None else request.why
        if job == "design":
            return True
        return f"no compiled {job}"

    def run(self, job: str, request):
        if job == "kinematics":
            status = (_loaded or _kernels())[0].run(request)
            return "a position the kernel cannot vouch for (numpy's corrector repairs it)" if status else status
        if job == "kinetostatics":
            return (_loaded or _kernels())[1].run(request)
        if job == "design":
            from . import _numba_design
            return _numba_design.solve(request)
        return f"no compiled {job}"


BACKEND = NumbaBackend()
