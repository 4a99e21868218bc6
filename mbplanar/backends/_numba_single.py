"""The compiled lean path of one position (optional, needs numba): `mbplanar.position` on an engine with
``backend="numba"`` runs one kernel call per position, with every table and work array made once per
engine.

The kernel (`_position`) has the sweep kernel (`_numba_kinematics._sweep`) solve the position as a
batch of one, on its tables, work arrays and the atlas interpolant, at input speed 1 and acceleration 0
(so that its rates are the analogues); then it writes what `Motion` derives (the real rates, the
instantaneous centres, the joints' values and rates, the analogues) into the answer's own buffer (a
`Position` record, `kinematics._single.FIELDS`). Input values far from the drawn pose are reduced by
the branch's period as the numpy path does (`engine._atlas._solve_periodic`): solved at the equivalent
value near the drawn pose, moved on by whole turns, and corrected at the value asked (the sweep kernel
again, predicting from a one-interval atlas that holds the moved unknowns).

It answers only where it can vouch for the position, as the sweep kernel: a status other than 0 sends
the position to the slow path here (extend the atlas, find the period) or to the numpy reference
(a change point's bracket, a step the batch corrector would repair, a position past a motion limit,
which the reference reports with its `MotionError`).

Calling cost. A numba dispatcher types every argument on every call, and typing a named tuple of arrays
costs ~1 µs; the solver therefore calls the compiled overload's entry point directly, with arguments
whose types are fixed when the solver binds them (`_Solver._bind`). Numba unboxes every array of every
call (~10 ns each): the sweep kernel's tables travel as one tuple, and this module's own 39 arrays (work
arrays, offsets, the atlas' interpolant) are packed by type into four flat buffers (`PACKED`) whose
views the kernel takes, so that a call passes ten arguments and ~40 arrays rather than 52 and ~76
(~0.4 µs less); the answer is made without the dataclass' ``__init__`` (`kinematics._single.made`).
"""

from __future__ import annotations

import math

import numpy as np

from ..engine._atlas import LOST_PRECISION, far_span
from ..kinematics._motion import _tables
from ..kinematics._single import (FIELDS, PendingSolver, Position, checked_speeds, finite_input, layout_of, made,
                                  reference)
from ._jit import njit
from ._numba_kinematics import _ORDER, _atlas_tables, _plan, _scratch, _sweep

__all__ = ["single"]

# the kernel's status (the kernel returns the numbers): a position written, or where it goes instead
DONE, REFERENCE, OUTSIDE, FAR = 0, 1, 2, 3
# the largest uncertainty (rad) of a value reduced by whole periods that the kernel takes; above it the
# numpy path warns (`PrecisionWarning`) and takes it
FAR_ERROR = 1e-12
_empty, _ndarray = np.empty, np.ndarray


def single(engine):
    """The lean solver of one-input positions on this engine (a callable ``(phi, omega, epsilon) →
    Position``), or None (several inputs: the numpy reference takes them)."""
    if len(engine.inputs) != 1:
        return None
    return _Solver(engine)


class _Solver:
    """An engine's compiled one-position solver: the kernel's arguments made once (tables, atlas,
    work arrays) and bound again when the atlas grows."""

    def __init__(self, engine):
        self.engine = engine
        self.layout = layout_of(engine)
        self.size, self.dtype = self.layout.size, self.layout.dtype
        inp = engine.inputs[0]
        self.defaults = (float(inp.omega), float(inp.epsilon))
        self.atlas = engine.atlas()
        self.phi0 = float(engine.phi_drawn[0])
        (_, links, at), joint_table = _tables(engine)
        plan = _plan(engine, joint_table)  # the sweep kernel's tables: its `_sweep` solves the position
        row, row_offsets = plan.rows[True]
        offsets = np.array([self.layout.offsets[name] for name, _, _ in FIELDS], np.int64)
        m_all, n_l, n_p = sum(bp.m for bp in engine.blocks), len(engine.links), len(links)
        ps, rt, sc, cc, q, guess, jac, perm, res, col, sol, qd_u = _scratch(*plan.sizes)
        self.tables = plan.args
        # the kernel's own arrays, packed by type into three buffers (`PACKED`), the atlas' into a fourth at
        # every binding: a call unboxes these and their table `lay` rather than 39 arrays (~0.4 µs)
        floats = dict(far=np.array([far_span(engine.solver), 0.0, LOST_PRECISION, FAR_ERROR]),
                      shift=np.zeros(m_all), p_at=np.ascontiguousarray(at, float), xs=np.zeros(1), ones=np.ones(1),
                      zeros=np.zeros(1), angle=np.zeros((1, n_l)), xy=np.zeros((1, n_p, 2)), wq=np.zeros((1, n_l)),
                      eq=np.zeros((1, n_l)), vq=np.zeros((1, n_p, 2)), aq=np.zeros((1, n_p, 2)),
                      rows=np.zeros((1, row.itemsize // 8)), one_grid=np.zeros(2), one_coef=np.zeros((1, 6, m_all)),
                      one_signs=np.zeros((2, len(engine.blocks))), ps=ps, rt=rt, sc=sc, cc=cc, q=q, guess=guess,
                      jac=jac, res=res, col=col, sol=sol, qd_u=qd_u)
        ints = dict(p_link=np.ascontiguousarray(links, np.int64), off=offsets, row_off=row_offsets,
                    rec_off=np.array([row_offsets[_ORDER.index(n)] for n in ("r", "value", "fv", "rate_q", "accel_q")],
                                     np.int64), perm=perm)
        bools = dict(valid=np.zeros(1, np.bool_), no_limits=np.zeros(2, np.bool_), limits=np.zeros(2, np.bool_))
        self.lay = np.zeros((len(PACKED), 4), np.int64)
        self.buffers, views = zip(*(_pack(group, self.lay) for group in (floats, ints, bools)))
        self.views = {name: view for group in views for name, view in group.items()}
        # the walk's reach from the drawn pose, the period (0 until it is needed), and the limits of a
        # reduction; the unknowns' change over one period (written by `_slow`, read by the kernel)
        self.far, self.shift = self.views["far"], self.views["shift"]
        self._bind()

    def __reduce__(self):
        """Pickled as its engine (an engine sent to another process): made again there on first use."""
        return PendingSolver, (self.engine,)

    def _bind(self):
        """The kernel's arguments from the atlas as it is now, and the compiled entry point for them."""
        atlas = self.atlas
        self.seen = atlas.arrays()
        grid, coef, signs = _atlas_tables(self.engine, atlas)
        self.views["limits"][:] = atlas.limits[-1] is not None, atlas.limits[+1] is not None
        brackets = np.array([c.bracket for c in atlas.crossings], float).reshape(-1, 2)
        atlas_buffer, _ = _pack(dict(grid=grid, coef=coef, signs=signs, brackets=brackets), self.lay)
        self.args = (self.tables,) + self.buffers + (atlas_buffer, self.lay)
        self.kernel = _entry(_position, (0.0, 1.0, 0.0, np.empty(self.size)) + self.args)
        self.bound = (self.kernel, self.args, self.size, self.dtype, self.layout, self.seen)

    def __call__(self, phi, omega=None, epsilon=None) -> Position:
        kernel, (tables, floats, ints, bools, interpolant, lay), size, dtype, layout, seen = self.bound
        if omega is None and epsilon is None and phi.__class__ is float and phi - phi == 0.0 \
                and self.atlas.arrays() is seen:  # the usual call: a finite float at the model's speeds
            out = _empty(size)
            om, ep = self.defaults
            status = kernel(phi, om, ep, out, tables, floats, ints, bools, interpolant, lay)
            if not status:
                return made(_ndarray((), dtype, out), layout)
            return self._slow(phi, om, ep, status)
        return self._checked(phi, omega, epsilon)

    def _checked(self, phi, omega, epsilon) -> Position:
        """A call with its arguments checked and converted (`finite_input`, `checked_speeds`)."""
        x = phi if phi.__class__ is float and phi - phi == 0.0 else finite_input(self.engine, phi)
        om, ep = self.defaults if omega is None and epsilon is None else checked_speeds(self.engine, omega, epsilon)
        if self.atlas.arrays() is not self.seen:
            self._bind()  # the atlas grew (another call walked it): predict from it as `analyse` would
        out = _empty(self.size)
        status = self.kernel(x, om, ep, out, *self.args)
        if status:
            return self._slow(x, om, ep, status)
        return made(_ndarray((), self.dtype, out), self.layout)

    def _slow(self, x, om, ep, status) -> Position:
        """A position the kernel could not take at once: extend the atlas to it, or find the period a far
        value is reduced by, and try again; anything else is the reference's (which raises where the
        position is not reached)."""
        for _ in range(3):
            if status == FAR:
                found = self.atlas.period()
                if found is None:
                    break  # the numpy path refuses the value, or finds it past a limit
                self.far[1] = found[0]
                self.shift[:] = np.concatenate([np.zeros(0)] + [np.asarray(s, float) for s in found[1]])
            elif status == OUTSIDE:
                near = self._near(x)
                self.atlas.cover(near, near)
            else:
                break
            if self.atlas.arrays() is not self.seen:
                self._bind()
            out = _empty(self.size)
            status = self.kernel(x, om, ep, out, *self.args)
            if status == DONE:
                return made(_ndarray((), self.dtype, out), self.layout)
        return reference(self.engine, self.layout, np.array([[x]]), om, ep)

    def _near(self, x: float) -> float:
        """The value the atlas predicts x from: x itself within the walk's reach, else x − n·T."""
        span, period = self.far[0], self.far[1]
        if abs(x - self.phi0) <= span or period == 0.0:
            return x
        return x - math.floor((x - self.phi0) / period) * period


def _entry(kernel, args):
    """The compiled function of `kernel` for `args` (`_jit.Kernel.entry`: the ahead-of-time build's, or
    numba's, compiled or loaded from its cache now), which skips the typing of every argument."""
    return kernel.entry(args)


#: the kernel's packed arrays, in the order of the rows of its table `lay` (offset, shape): floats, ints,
#: bools, then the atlas' (floats, packed again when the atlas grows); `_position` reads them in this order
PACKED = ("far", "shift", "p_at", "xs", "ones", "zeros", "angle", "xy", "wq", "eq", "vq", "aq", "rows", "one_grid",
          "one_coef", "one_signs", "ps", "rt", "sc", "cc", "q", "guess", "jac", "res", "col", "sol", "qd_u",
          "p_link", "off", "row_off", "rec_off", "perm",
          "valid", "no_limits", "limits",
          "grid", "coef", "signs", "brackets")


def _pack(arrays: dict, lay: np.ndarray) -> tuple:
    """The arrays (of one dtype) copied into one flat buffer; their rows of `lay` (offset, up to three
    dimensions) written; returns the buffer and the arrays' views in it."""
    dtype = next(iter(arrays.values())).dtype
    buffer = np.zeros(sum(a.size for a in arrays.values()), dtype)
    views, offset = {}, 0
    for name, a in arrays.items():
        assert a.dtype == dtype and a.ndim <= 3, name
        view = views[name] = buffer[offset:offset + a.size].reshape(a.shape)
        view[...] = a
        lay[PACKED.index(name)] = (offset, *a.shape, *(0,) * (3 - a.ndim))
        offset += a.size
    return buffer, views


# -- kernel -----------------------------------------------------------------------------------------
_jit = njit(cache=True, error_model="numpy", nogil=True, _nrt=False)
_inline = njit(cache=True, error_model="numpy", nogil=True, _nrt=False, inline="always")

# Scalar loops over arrays indexed in place, compiled without numba's reference counting, nothing
# allocated (the caller passes every work array, `_numba_kinematics._scratch`). Pose ps (5, L): θ, cos θ,
# sin θ, r_x, r_y per link. Rates rt (slots, 3, L): ω, v_x, v_y per link; slots 0 … m−1 hold a block's
# sensitivities to its unknowns, then the velocities, then the accelerations. The arithmetic is the
# numpy engine's, operation for operation where it matters for rounding: the joint laws (`_constraints`),
# the scaled block Jacobian and its factors (`_blocks.ScaledLU`; explicit inverse up to 2 × 2, else LU,
# as `_linalg.factor`), the Newton polish and the rate passes (`BlockSolver.newton`, `_block_rates`).
@_inline
def _v1(buf, lay, k):
    """Packed array k (`PACKED`) of one dimension, a view of its buffer."""
    o = lay[k, 0]
    return buf[o:o + lay[k, 1]]


@_inline
def _v2(buf, lay, k):
    o, d0, d1 = lay[k, 0], lay[k, 1], lay[k, 2]
    return buf[o:o + d0 * d1].reshape((d0, d1))


@_inline
def _v3(buf, lay, k):
    o, d0, d1, d2 = lay[k, 0], lay[k, 1], lay[k, 2], lay[k, 3]
    return buf[o:o + d0 * d1 * d2].reshape((d0, d1, d2))


@_jit
def _position(x, omega, epsilon, out, tables, fb, ib, bb, ab, lay):
    """Solve the position x and write its `Position` record into out (at the offsets `off` of `FIELDS`);
    tables: the sweep kernel's; fb, ib, bb, ab: the packed arrays (`PACKED`, rows of `lay`). Returns the
    status (0 written; 1 the reference's, 2 outside the atlas, 3 far from the drawn pose with the period not yet
    known: see `_Solver._slow`). The sweep kernel solves it, as a batch of one at
    ω = 1, ε = 0 (so that its rates are the analogues). far: the walk's reach, the period T, the largest
    float spacing of a reduced value and the largest uncertainty of a reduction
    (`engine._atlas._periods_away`); shift (M,): the unknowns' change over one period."""
    steps, cuts, blocks, joints, alpha, sense, phi_drawn, ground, tol, centre = tables
    far, shift, p_at, xs, ones, zeros = _v1(fb, lay, 0), _v1(fb, lay, 1), _v2(fb, lay, 2), _v1(fb, lay, 3), \
        _v1(fb, lay, 4), _v1(fb, lay, 5)
    angle, xy, wq, eq, vq, aq, rows = _v2(fb, lay, 6), _v3(fb, lay, 7), _v2(fb, lay, 8), _v2(fb, lay, 9), \
        _v3(fb, lay, 10), _v3(fb, lay, 11), _v2(fb, lay, 12)
    one_grid, one_coef, one_signs = _v1(fb, lay, 13), _v3(fb, lay, 14), _v2(fb, lay, 15)
    ps, rt, sc, cc, q, guess, jac = _v2(fb, lay, 16), _v3(fb, lay, 17), _v2(fb, lay, 18), _v2(fb, lay, 19), \
        _v1(fb, lay, 20), _v1(fb, lay, 21), _v2(fb, lay, 22)
    res, col, sol, qd_u = _v1(fb, lay, 23), _v1(fb, lay, 24), _v1(fb, lay, 25), _v1(fb, lay, 26)
    p_link, off, row_off, rec_off, perm = _v1(ib, lay, 27), _v1(ib, lay, 28), _v1(ib, lay, 29), _v1(ib, lay, 30), \
        _v1(ib, lay, 31)
    valid, no_limits, limits = _v1(bb, lay, 32), _v1(bb, lay, 33), _v1(bb, lay, 34)
    grid, coef, signs, brackets = _v1(ab, lay, 35), _v3(ab, lay, 36), _v2(ab, lay, 37), _v2(ab, lay, 38)
    n_grid, m_all = len(grid), coef.shape[2]
    span, period, lost, far_error = far[0], far[1], far[2], far[3]
    reduced, periods, near_x = False, 0.0, x
    if abs(x - phi_drawn) > span:  # reduced by whole periods, as the numpy path
        if period == 0.0:
            return 3
        spacing = np.spacing(abs(x))
        periods = np.floor((x - phi_drawn) / period)
        if spacing > lost or spacing + abs(periods) * np.spacing(period) > far_error:
            return 1
        near_x = x - periods * period
        reduced = True
    if (limits[0] and near_x < grid[0]) or (limits[1] and near_x > grid[n_grid - 1]):
        return 1  # past a located limit: the reference says so
    if n_grid < 2 or near_x < grid[0] or near_x > grid[n_grid - 1]:
        return 2
    for c in range(len(brackets)):
        if brackets[c, 0] <= near_x <= brackets[c, 1]:
            return 1  # a change point's bracket: the interpolant gives the rates there, numpy's path
    xs[0] = near_x
    # `_sweep`'s flags as run-time booleans: a constant True or False would be typed as a literal, and
    # numba would compile `_sweep` again for it (two more first compiles of the whole kernel)
    no, yes = n_grid < 0, n_grid >= 0
    if reduced:
        # solved and checked at the equivalent value near the drawn pose, then moved on by whole periods:
        # the prediction at x of a one-interval atlas, corrected there (`engine._atlas._solve_periodic`)
        if _sweep(steps, cuts, blocks, joints, alpha, sense, phi_drawn, ground, tol, centre, grid, coef, signs, limits,
                  xs, ones, zeros, no, no, p_link, p_at, row_off, angle, xy, wq, eq, vq, aq, rows, valid, ps, rt,
                  sc, cc, q, guess, jac, perm, res, col, sol, qd_u) or not valid[0]:
            return 1
        lo = min(max(np.searchsorted(grid, near_x) - 1, 0), n_grid - 2)  # (as `atlas._interpolate`)
        near = lo if abs(near_x - grid[lo]) <= abs(near_x - grid[lo + 1]) else lo + 1  # its determinants' signs
        one_grid[0], one_grid[1] = x - 1.0, x + 1.0
        one_coef[:, :, :] = 0.0
        for i in range(m_all):
            one_coef[0, 0, i] = q[i] + shift[i] * periods
        for k in range(signs.shape[1]):
            one_signs[0, k], one_signs[1, k] = signs[near, k], signs[near, k]
        xs[0] = x
        grid, coef, signs, limits = one_grid, one_coef, one_signs, no_limits
    if _sweep(steps, cuts, blocks, joints, alpha, sense, phi_drawn, ground, tol, centre, grid, coef, signs, limits, xs,
              ones, zeros, no, yes, p_link, p_at, row_off, angle, xy, wq, eq, vq, aq, rows, valid, ps, rt, sc, cc, q,
              guess, jac, perm, res, col, sol, qd_u) or not valid[0]:
        return 1
    _outputs(x, omega, epsilon, out, off, rec_off, len(joints.a), angle, xy, wq, eq, vq, aq, rows)
    return 0


@_inline
def _real(xq, xqq, omega, epsilon):
    """Real rate and acceleration from the analogues, as `kinematics._motion._real`."""
    if epsilon == 0.0:
        return xq * omega, xqq * (omega * omega)
    return xq * omega, xqq * (omega * omega) + xq * epsilon


@_jit
def _outputs(x, omega, epsilon, out, off, rec_off, n_j, angle, xy, wq, eq, vq, aq, rows):
    """The record of one solved position (`FIELDS`, at offsets `off`) from what `_sweep` wrote for ω = 1,
    ε = 0 (angles, points, analogues, and in `rows` the frames and joints, at `rec_off`: r, value, frame
    velocity, joint rate and acceleration analogues), with the operations of `Motion` (`_real`,
    `_instant_centres`)."""
    n_l, n_p = angle.shape[1], xy.shape[1]
    o_r, o_val, o_fv, o_rq, o_aq = rec_off[0], rec_off[1], rec_off[2], rec_off[3], rec_off[4]
    out[off[0]], out[off[1]], out[off[2]] = x, omega, epsilon
    for k in range(n_l):
        w, e = _real(wq[0, k], eq[0, k], omega, epsilon)
        out[off[3] + k], out[off[4] + k], out[off[5] + k] = angle[0, k], w, e
        out[off[13] + k], out[off[14] + k] = wq[0, k], eq[0, k]
        # instantaneous centre r + perp(v)/ω of the link's frame; NaN where it does not turn
        vx, vy = rows[0, o_fv + 2 * k] * omega, rows[0, o_fv + 2 * k + 1] * omega
        icx, icy = rows[0, o_r + 2 * k] + -vy / w, rows[0, o_r + 2 * k + 1] + vx / w
        if not (np.isfinite(icx) and np.isfinite(icy)):
            icx, icy = np.nan, np.nan
        out[off[6] + 2 * k], out[off[6] + 2 * k + 1] = icx, icy
    for p in range(n_p):
        for c in range(2):
            v, a = _real(vq[0, p, c], aq[0, p, c], omega, epsilon)
            j = 2 * p + c
            out[off[7] + j], out[off[8] + j], out[off[9] + j] = xy[0, p, c], v, a
            out[off[15] + j], out[off[16] + j] = vq[0, p, c], aq[0, p, c]
    for j in range(n_j):
        rq, acq = rows[0, o_rq + j], rows[0, o_aq + j]
        rate, accel = _real(rq, acq, omega, epsilon)
        out[off[10] + j], out[off[11] + j], out[off[12] + j] = rows[0, o_val + j], rate, accel
        out[off[17] + j], out[off[18] + j] = rq, acq
