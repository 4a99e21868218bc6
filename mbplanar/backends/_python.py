"""The kernels run as plain Python: what an engine on numpy asks before numpy (`engine._backend`).

The compiled backend's kinematics kernel (`_numba_kinematics._sweep`) is ordinary Python that numba
compiles; run as Python on memoryviews of its arrays (`_jit.interpret`) it does the same floating-point
operations in the same order, position by position. For one position that costs less than numpy's batch
machinery (a few hundred array operations of a few µs each): about a third of numpy's time for a
four-bar with every point's velocity and acceleration. From two positions numpy's vectorised batch
wins, and this backend declines (`should_run`); so does it in a process that plans fewer positions
than repay importing the kernel's module (~6 ms of CPU: a command line's `solve`). It needs nothing
besides numpy, and this module imports nothing until it runs.
"""

from __future__ import annotations

import sys

import numpy as np

__all__ = ["BACKEND", "PythonBackend", "PAYS_FROM", "sweep_can_run"]

#: positions a process must plan before importing the kernel's module (~6 ms of CPU) pays, at ~0.2 ms
#: saved per position
PAYS_FROM = 50
_KERNEL = "mbplanar.backends._numba_kinematics"


def sweep_can_run(request) -> bool | str:
    """Whether the kinematics kernel can vouch for a request: an atlas of two nodes or more, and no input
    value between the nodes bracketing a change point (where the interpolant gives the rates)."""
    atlas = request.atlas
    if len(atlas.grid) < 2:
        return "an atlas of one node"
    if not len(atlas.brackets):
        return True
    x = request.inp.x
    for lo, hi in atlas.brackets:
        if (lo <= x[0] <= hi) if len(x) == 1 else bool(np.any((x >= lo) & (x <= hi))):
            return "an input value next to a change point"
    return True


class PythonBackend:
    """The kinematics kernel as plain Python, for one position."""

    name = "python"

    def should_run(self, job: str, size: int) -> bool | str:
        if job != "kinematics":
            return (f"numpy's {job} is faster than the kernels as plain Python" if job in ("kinetostatics", "design")
                    else f"no {job} kernel")
        if size != 1:
            return f"{size} positions: numpy's vectorised batch is faster from 2 on"
        from ..engine import planned
        if planned.positions is not None and planned.positions < PAYS_FROM and _KERNEL not in sys.modules:
            return (f"{planned.positions} position(s) planned: importing the kernel (~6 ms) pays from "
                    f"{PAYS_FROM}")
        return True

    def can_run(self, job: str, request) -> bool | str:
        if isinstance(request, str):  # (the layer could not write the request for the kernels: why)
            return request
        return sweep_can_run(request) if job == "kinematics" else f"no {job} kernel as plain Python"

    def run(self, job: str, request):
        from ._jit import interpret, plain
        from ._numba_kinematics import _sweep
        store = request.store
        fixed = store.get("plain")
        if fixed is None or fixed[0] is not request.atlas:  # (made again when the atlas grew)
            work = store.get("plain work")
            if work is None:
                from ..engine import SweepWork, work_sizes
                work = store["plain work"] = plain(SweepWork.new(work_sizes(request.tables)))
            fixed = store["plain"] = (request.atlas, (plain(request.tables), plain(request.atlas), request.tol))
        viewed = fixed[1]
        if request.size == 1:  # (one position's request is made once per thread: its views with it)
            found = store.get("plain one")
            if found is None or found[0] is not request:
                found = store["plain one"] = (request, viewed + (plain(request.inp), plain(request.out),
                                                                 store["plain work"]))
            args, viewed = (), found[1]
        else:
            args = (request.inp, request.out, store["plain work"])
        try:
            status = interpret(_sweep, args, viewed)
        except ArithmeticError as exc:  # (a division by zero the compiled code would carry on with)
            return f"the kernel as plain Python raised {type(exc).__name__}"
        return "a position the kernel cannot vouch for (numpy's corrector repairs it)" if status else status


BACKEND = PythonBackend()
