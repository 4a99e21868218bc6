"""The numba backend: the compiled kinematics and kinetostatics of one-input batches behind the
`Backend` seam (`mbplanar.engine._backend`). Each method first says whether it can take the batch
(None: numpy, the reference, takes it) and otherwise returns what numpy would, equal to rounding."""

from __future__ import annotations

import numpy as np

from ..engine._atlas import met_along
from ..forces._kinetostatics import plan_of, result
from ..forces._loads import needs_numpy
from ..kinematics._motion import Motion, _per_position, _tables
from . import _numba_kinematics, _numba_kinetostatics

__all__ = ["BACKEND", "NumbaBackend"]


class NumbaBackend:
    """Compiled per-position loops for one-input sweeps (`_numba_kinematics`, `_numba_kinetostatics`)."""

    name = "numba"

    def kinematics(self, engine, phi, omega, epsilon) -> Motion | None:
        """`analyse` of one input's values, or None: several inputs, no positions, a non-finite value,
        or a position the kernel hands back (a change point's bracket, one the corrector would repair)."""
        if len(engine.inputs) != 1 or not phi.size or not np.isfinite(phi).all():
            return None
        return _motion(engine, phi.reshape(-1, 1), omega, epsilon)

    def kinetostatics(self, engine, motion, input_inertia, loads, inertia):
        """`kinetostatics` of a compiled Motion (its rows in step with its arrays) of one input with the
        model's own loads (no springs, dampers, torques or switched rows) and no input inertia, or None."""
        rows = motion.rows
        if not (rows is not None and len(rows) == len(motion.phi) > 0 and np.may_share_memory(rows, motion.wq)
                and loads is None and len(engine.inputs) == 1 and not np.any(input_inertia)
                and not needs_numpy(engine.mech)):
            return None
        plan = plan_of(engine)
        x, singular, residual, values = _numba_kinetostatics.solve(engine, motion, plan, inertia)
        return result(engine, motion, plan.lay, x, singular, residual, values)

    def single(self, engine):
        """The lean solver of one position (`mbplanar.position`), or None (several inputs)."""
        from . import _numba_single
        return _numba_single.single(engine)


BACKEND = NumbaBackend()


def _motion(engine, phi, omega, epsilon) -> Motion | None:
    """The `Motion` of one input's values phi (B, 1) from the compiled rows: the frames, analogues and
    joint values are views of them, the rest `Motion` derives when first read."""
    batch, inp = len(phi), engine.inputs[0]
    x = np.ascontiguousarray(phi[:, 0])
    om = np.ascontiguousarray(_per_position(omega, [inp.omega], batch, 1).reshape(-1))
    ep = np.ascontiguousarray(_per_position(epsilon, [inp.epsilon], batch, 1).reshape(-1))
    tables = _tables(engine)
    lo, hi = (float(x[0]),) * 2 if batch == 1 else (float(x.min()), float(x.max()))
    if not engine.within_walk(lo, hi):
        return None  # far values: the numpy path reduces them by the period
    got = _numba_kinematics.sweep(engine, x, lo, hi, tables[1])
    if got is None:
        return None
    rows, valid = got
    keep = slice(None) if valid.all() else np.flatnonzero(valid)
    rows = rows[keep]
    limits, crossings = met_along(engine.atlas(), lo, hi)
    return Motion(engine=engine, phi=phi[keep], omega=om[keep, None], epsilon=ep[keep, None],
                  link_names=list(engine.links), angle=None, w=None, e=None,
                  point_names=tables[0][0], xy=None, v=None, a=None,
                  joint_names=list(engine.mech.joints), value=rows["value"], rate=None,
                  accel=None, ic=None, wq=rows["wq"], eq=rows["eq"], vq=None, aq=None,
                  rate_q=rows["rate_q"], accel_q=rows["accel_q"], requested=batch, limits=limits,
                  crossings=crossings, frames={"th": rows["th"], "r": rows["r"], "w": rows["wq"], "v": rows["fv"],
                                               "e": rows["eq"], "a": rows["fa"]}, rows=rows)
