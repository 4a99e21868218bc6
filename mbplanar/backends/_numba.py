"""The numba backend: the compiled kinematics and kinetostatics of one-input batches behind the
`Backend` seam (`mbplanar.engine._backend`). Each method first says whether it can take the batch
(None: numpy, the reference, takes it) and otherwise returns what numpy would, equal to rounding."""

from __future__ import annotations

import numpy as np

from ..engine._atlas import met_along
from ..forces._kinetostatics import plan_of, result
from ..forces._loads import heavy_links, needs_numpy
from ..kinematics._motion import Motion, _per_position, _tables, point_selection

__all__ = ["BACKEND", "NumbaBackend", "PAYS_FROM", "declines"]

#: positions from which a new process gains by loading the compiled kernels: importing numba and loading
#: the kernels from its cache (``mbplanar compile`` fills it) costs about 0.4 s of CPU per process (numba's
#: own start included), the kernels save about 1 µs per position
PAYS_FROM = 500_000


def _kernels():
    """The kernel modules, imported on first use (numba only when a kernel is compiled: `_jit`)."""
    if not _loaded:
        from . import _numba_kinematics, _numba_kinetostatics
        _loaded.extend((_numba_kinematics, _numba_kinetostatics))
    return _loaded


_loaded: list = []


def declines(engine) -> str | None:
    """Why the compiled kernels take none of this engine's batches (None: they may take them): the
    kernels hold the laws of the revolute and prismatic pairs only, so a model with higher pairs (gear,
    rack, cam, slot) is solved by numpy, the reference, whatever its backend."""
    if engine.mech.higher:
        return ("the model has higher pairs (" + ", ".join(sorted({h.kind for h in engine.mech.higher.values()}))
                + "), whose laws the compiled kernels do not hold: numpy solves it")
    return None


class NumbaBackend:
    """Compiled per-position loops for one-input sweeps (`_numba_kinematics`, `_numba_kinetostatics`)."""

    name = "numba"

    @staticmethod
    def declines(engine) -> str | None:
        """Why this backend takes none of the engine's batches, or None (`declines`)."""
        return declines(engine)

    def pays(self, positions: int) -> bool:
        """Whether a process that has not loaded the kernels yet gains by loading them for a batch of
        `positions` (the command line runs one batch per process: it takes numpy below `PAYS_FROM`)."""
        import sys
        return positions >= PAYS_FROM or "numba" in sys.modules

    def kinematics(self, engine, phi, omega, epsilon, points=None, rates=True) -> Motion | None:
        """`analyse` of one input's values (of the points `points`, a `PointSelection` or None for every
        point; with or without `rates`), or None: several inputs, no positions, a non-finite value, or a
        position the kernel hands back (a change point's bracket, one the corrector would repair)."""
        if len(engine.inputs) != 1 or not phi.size or engine.mech.higher:  # (analyse checked that phi is finite)
            return None  # (higher pairs: `declines`)
        return _motion(engine, phi.reshape(-1, 1), omega, epsilon, points, rates)

    def kinetostatics(self, engine, motion, input_inertia, loads, inertia):
        """`kinetostatics` of a compiled Motion (its rows in step with its arrays) of one input with the
        model's own loads (no springs, dampers, torques or switched rows) and no input inertia, or None."""
        no_inertia = input_inertia == 0 if type(input_inertia) in (int, float) else not np.any(input_inertia)
        if not (motion.has_rates and loads is None and len(engine.inputs) == 1 and no_inertia
                and not needs_numpy(engine.mech) and not engine.mech.higher):  # (np.any of the default 0: ~4 µs)
            return None
        rows = motion.rows  # (a compiled sweep that did not write them solves again for them, once)
        if not (rows is not None and len(rows) == len(motion.phi) > 0 and np.may_share_memory(rows, motion.wq)):
            return None
        plan = plan_of(engine)
        x, singular, residual, values = _kernels()[1].solve(engine, motion, plan, inertia)
        return result(engine, motion, plan.lay, x, singular, residual, values)

    def single(self, engine):
        """The lean solver of one position (`mbplanar.position`), or None (several inputs, higher pairs)."""
        if engine.mech.higher:
            return None
        from . import _numba_single
        return _numba_single.single(engine)


BACKEND = NumbaBackend()


def _motion(engine, phi, omega, epsilon, points, rates) -> Motion | None:
    """The `Motion` of one input's values phi (B, 1) as the kernel wrote it: the angles, the points and
    the real rates are its arrays, the frames, analogues and joint values views of its records; the rest
    `Motion` derives when first read. The records are written in the same pass only where the
    kinetostatics will read them (`_records_read`); otherwise the kernel solves again for them when one of
    them is first read (`_refill`)."""
    batch, inp = len(phi), engine.inputs[0]
    x = np.ascontiguousarray(phi[:, 0])
    om, ep = _speed(omega, inp.omega, batch), _speed(epsilon, inp.epsilon, batch)
    lo, hi = (float(x[0]),) * 2 if batch == 1 else (float(x.min()), float(x.max()))
    if not engine.within_walk(lo, hi):
        return None  # far values: the numpy path reduces them by the period
    sel = points if points is not None else point_selection(engine)
    records = bool(rates) and _records_read(engine)
    got = _kernels()[0].sweep(engine, x, lo, hi, _tables(engine)[1], om, ep, sel.links, sel.at, rates,
                              records=records)
    if got is None:
        return None
    keep = slice(None) if got.complete else np.flatnonzero(got.valid)
    atlas = engine.atlas()
    known = atlas.crossings or atlas.limits[-1] is not None or atlas.limits[+1] is not None
    limits, crossings = met_along(atlas, lo, hi) if known else ([], [])  # (neither known: nothing to look up)
    arrays = dict(w=got.w, e=got.e, v=got.v, a=got.a) if rates else dict(w=None, e=None, v=None, a=None)
    common = dict(engine=engine, phi=phi[keep], omega=om[keep, None], epsilon=ep[keep, None],
                  link_names=list(engine.links), angle=got.angle, point_names=list(sel.names), xy=got.xy,
                  joint_names=list(engine.mech.joints), rate=None, accel=None, ic=None, vq=None, aq=None,
                  requested=batch, limits=limits, crossings=crossings, has_rates=bool(rates), **arrays)
    if not records:
        return Motion(**common, value=None, frames=None, rows=None, wq=None, eq=None, rate_q=None, accel_q=None,
                      refill=_refill)
    return Motion(**common, **_views(got.rows, rates))


def _speed(value, default, batch: int) -> np.ndarray:
    """The input's speed or acceleration per position (B,), contiguous: `value` one number (None: the
    model's `default`) or one per position."""
    if value is None or isinstance(value, (int, float)):
        out = np.empty(batch)
        out.fill(default if value is None else value)  # (np.full's Python wrapper costs more than the fill)
        return out
    return np.ascontiguousarray(_per_position(value, [default], batch, 1).reshape(-1))


def _records_read(engine) -> bool:
    """Whether the kinetostatics is likely to read a sweep's records: the model has loads or heavy links,
    or the compiled kinetostatics has had to solve again for them on this engine (`_refill`)."""
    found = engine.prepared.get("numba records read")
    if found is None:
        found = engine.prepared["numba records read"] = bool(engine.mech.loads or heavy_links(engine.mech))
    return found


def _views(rows, rates) -> dict:
    """The fields of a compiled `Motion` that are views of its records `rows`: the joint values, the
    link frames and, with rates, the analogues."""
    field = rows.__getitem__
    frames = {"th": field("th"), "r": field("r")}
    out = dict(rows=rows, value=field("value"), frames=frames)
    if rates:
        wq, eq = field("wq"), field("eq")
        frames.update(w=wq, v=field("fv"), e=eq, a=field("fa"))
        out.update(wq=wq, eq=eq, rate_q=field("rate_q"), accel_q=field("accel_q"))
    return out


def _refill(motion) -> dict:
    """The records of a compiled `motion` whose sweep did not write them, and the fields that are views
    of them (`_views`): the kernel solves its positions again, writing the records only."""
    engine = motion.engine
    x = np.ascontiguousarray(motion.phi[:, 0])
    rates = motion.has_rates
    if rates:
        engine.prepared["numba records read"] = True  # (later sweeps of this engine write them at once)
    none = point_selection(engine, [])
    got = None
    if len(x):
        got = _kernels()[0].sweep(engine, x, float(x.min()), float(x.max()), _tables(engine)[1], np.ones(len(x)),
                                  np.zeros(len(x)), none.links, none.at, rates)
    if got is not None and len(got.rows) == len(x):
        return _views(got.rows, rates)
    if len(x):  # (the kernel takes what it took before; numpy otherwise, the derived arrays with it)
        from ..kinematics._motion import DERIVED, _reference
        ref = _reference(engine, motion.phi, motion.omega, motion.epsilon,
                         point_selection(engine, motion.point_names), rates)
        names = ("value", "frames") + (("wq", "eq", "rate_q", "accel_q") + DERIVED if rates else ())
        return {"rows": None, **{name: getattr(ref, name) for name in names}}
    dtype = _kernels()[0].record_dtype(engine, _tables(engine)[1], rates)  # every position past a limit
    return _views(np.zeros(0, dtype), rates)
