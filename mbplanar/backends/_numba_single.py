"""The compiled lean path of one position (optional, needs numba): `mbplanar.position` on an engine with
``backend="numba"`` runs one kernel call per position, with every table and work array made once per
engine.

The kernel (`_position`) is the sweep kernel's work for one position (`_numba_kinematics`: the joint
laws' placement and closure, the block Jacobian, its LU, the rate passes and the joint values are its
functions), plus what `Motion` derives: the link angles, the points' positions, velocities and
accelerations, the real rates and the instantaneous centres, written into the answer's own buffer (a
`Position` record, `kinematics._single.FIELDS`). Input values far from the drawn pose are reduced by the
branch's period as the numpy path does (`engine._atlas._solve_periodic`): solved at the equivalent
value near the drawn pose, moved on by whole turns, and corrected at the value asked.

It answers only where it can vouch for the position, as the sweep kernel: a status other than 0 sends
the position to the slow path here (extend the atlas, find the period) or to the numpy reference
(a change point's bracket, a step the batch corrector would repair, a position past a motion limit,
which the reference reports with its `MotionError`).

Calling cost. A numba dispatcher types every argument on every call, and typing a named tuple of arrays
costs ~1 µs; the solver therefore calls the compiled overload's entry point directly, with arguments
whose types are fixed when the solver binds them (`_Solver._bind`), so that a call costs well under a
microsecond before the arithmetic.
"""

from __future__ import annotations

import math

import numpy as np

from ..engine._atlas import LOST_PRECISION, far_span
from ..kinematics._motion import _tables
from ..kinematics._single import (FIELDS, Position, checked_speeds, finite_input, layout_of, reference)
from ._numba_kinematics import (_atlas_tables, _block_rates, _closure, _inline, _interval, _jacobian, _jit, _lu,
                                _lu_solve, _place, _plan, _scratch, _write)

__all__ = ["single"]

# the kernel's status (the kernel returns the numbers): a position written, or where it goes instead
DONE, REFERENCE, OUTSIDE, FAR = 0, 1, 2, 3
# the largest uncertainty (rad) of a value reduced by whole periods that the kernel takes; above it the
# numpy path warns (`PrecisionWarning`) and takes it
FAR_ERROR = 1e-12


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
        plan = _plan(engine, joint_table)
        offsets = np.array([self.layout.offsets[name] for name, _, _ in FIELDS], np.int64)
        row_offsets = np.array([plan.row.fields[n][1] // 8 for n in ("value", "rate_q", "accel_q")], np.int64)
        alpha = np.array([engine.reference_angle[n] for n in engine.links], float)
        # the walk's reach from the drawn pose, the period (0 until it is needed), and the limits of a reduction
        self.far = np.array([far_span(engine.solver), 0.0, LOST_PRECISION, FAR_ERROR])
        self.shift = np.zeros(sum(bp.m for bp in engine.blocks))  # the unknowns' change over one period
        self.fixed = plan.args + (self.far, self.shift, np.ascontiguousarray(links, np.int64),
                                  np.ascontiguousarray(at, float), alpha, offsets, row_offsets)
        self.work = _scratch(*plan.sizes) + (np.zeros((1, plan.row.itemsize // 8)),)
        self._bind()

    def _bind(self):
        """The kernel's arguments from the atlas as it is now, and the compiled entry point for them."""
        atlas = self.atlas
        self.seen = atlas.arrays()
        grid, coef, signs = _atlas_tables(self.engine, atlas)
        limits = np.array([atlas.limits[-1] is not None, atlas.limits[+1] is not None], np.bool_)
        brackets = np.array([c.bracket for c in atlas.crossings], float).reshape(-1, 2)
        self.args = self.fixed + (grid, coef, signs, limits, brackets) + self.work
        self.kernel = _entry(_position, (0.0, 1.0, 0.0, np.empty(self.size)) + self.args)

    def __call__(self, phi, omega=None, epsilon=None) -> Position:
        x = phi if phi.__class__ is float and phi - phi == 0.0 else finite_input(self.engine, phi)
        om, ep = self.defaults if omega is None and epsilon is None else checked_speeds(self.engine, omega, epsilon)
        if self.atlas.arrays() is not self.seen:
            self._bind()  # the atlas grew (another call walked it): predict from it as `analyse` would
        out = np.empty(self.size)
        status = self.kernel(x, om, ep, out, *self.args)
        if status:
            return self._slow(x, om, ep, status)
        return Position(np.ndarray((), self.dtype, out), self.layout)

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
            out = np.empty(self.size)
            status = self.kernel(x, om, ep, out, *self.args)
            if status == DONE:
                return Position(np.ndarray((), self.dtype, out), self.layout)
        return reference(self.engine, self.layout, np.array([[x]]), om, ep)

    def _near(self, x: float) -> float:
        """The value the atlas predicts x from: x itself within the walk's reach, else x − n·T."""
        span, period = self.far[0], self.far[1]
        if abs(x - self.phi0) <= span or period == 0.0:
            return x
        return x - math.floor((x - self.phi0) / period) * period


def _entry(kernel, args):
    """The compiled entry point of `kernel` for `args` (compiled or loaded from numba's cache on first
    use), which skips the dispatcher's typing of every argument; the dispatcher itself where numba
    does not expose it."""
    kernel(*args)
    try:
        return kernel.overloads[tuple(kernel.typeof_pyval(a) for a in args)].entry_point
    except (AttributeError, KeyError):
        return kernel


# -- kernel -----------------------------------------------------------------------------------------
# (`_solve_blocks` and `_outputs` are compiled functions of their own, not inlined: inlining the joint laws'
# building blocks once each keeps numba's first compile short)
@_jit
def _solve_blocks(xb, check, rates, near, steps, cuts, blocks, sense, phi_drawn, tol, signs, ps, rt, sc, cc, q,
                  guess, jac, perm, res, step, qd_u, qdd_u):
    """Newton on every block at input value xb from the unknowns q, as the sweep kernel; with `check`, the
    branch checks against the atlas node `near` (determinant signs) and the prediction `guess`
    (corrector distance); with `rates`, each block's velocity and acceleration analogues after its
    solve. Returns DONE or REFERENCE."""
    closure, max_newton, pivot_polish, pivot_cross, max_correction = (  # Tolerances.KERNEL_FIELDS
        tol[0], int(tol[1]), tol[2], tol[3], tol[4])
    row_scale, var_scale = blocks.row_scale, blocks.var_scale
    vel, acc = len(rt) - 2, len(rt) - 1
    q_in = sense * (xb - phi_drawn)
    for bk in range(len(blocks.m)):
        k0, k1, c0, c1 = blocks.step0[bk], blocks.step1[bk], blocks.cut0[bk], blocks.cut1[bk]
        var0, m = blocks.var0[bk], blocks.m[bk]
        polished, ok, det, ratio, err = False, False, 1.0, 1.0, 0.0
        for it in range(max_newton + 1):
            for k in range(k0, k1):
                _place(k, steps, q, q_in, ps, sc)
            err = 0.0
            for k in range(c0, c1):
                _closure(k, cuts, ps, cc, res, 2 * (k - c0))
            for i in range(m):
                err = max(err, abs(res[i]) * row_scale[var0 + i])
            if m == 0:
                ok = True
                break
            _jacobian(k0, k1, c0, c1, blocks.anchor0[bk], blocks.anchor1[bk], m, var0, steps, cuts, blocks.anchors,
                      sc, cc, rt, jac, step)
            det, ratio = _lu(jac, m, perm)
            ok = err < closure
            if ok and not polished:
                polished = True
                if ratio >= pivot_polish or ratio < pivot_cross * 1e3:
                    break
            elif ok or it == max_newton:
                break
            for i in range(m):
                res[i] = -res[i]
            _lu_solve(jac, m, perm, res, step)
            for i in range(m):
                if np.isfinite(step[i]):
                    q[var0 + i] += step[i]
        if not (ok and np.isfinite(err)):
            return 1
        if check and m:
            if det == 0.0 or (det > 0) != (signs[near, bk] > 0):
                return 1
            for i in range(m):
                if abs(q[var0 + i] - guess[var0 + i]) * var_scale[var0 + i] > max_correction:
                    return 1
        if rates:
            _block_rates(k0, k1, c0, c1, m, var0, steps, cuts, sc, cc, rt, vel, -1, jac, perm, sense, qd_u,
                         0.0, res, qd_u)
            _block_rates(k0, k1, c0, c1, m, var0, steps, cuts, sc, cc, rt, acc, vel, jac, perm, 0.0, qd_u,
                         sense, res, qdd_u)
    return 0


@_jit
def _position(x, omega, epsilon, out, steps, cuts, blocks, joints, sense, phi_drawn, ground, tol, far, shift,
              point_link, point_at, alpha, off, row_off, grid, coef, signs, limits, brackets,
              ps, rt, sc, cc, q, guess, jac, perm, res, step, qd_u, qdd_u, row):
    """Solve the position x and write its `Position` record into out; returns the status (0 written;
    1 the reference's, 2 outside the atlas, 3 far from the drawn pose with the period not yet known:
    see `_Solver._slow`). far: the walk's reach, the period T, the largest float spacing of a reduced
    value and the largest uncertainty of a reduction (`engine._atlas._periods_away`); shift (M,): the
    unknowns' change over one period."""
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
    # the quintic Hermite interpolant between the two nodes around the value, and the nearest node
    lo = _interval(grid, near_x)
    t = (near_x - grid[lo]) / (grid[lo + 1] - grid[lo])
    near = lo if abs(near_x - grid[lo]) <= abs(near_x - grid[lo + 1]) else lo + 1
    for i in range(m_all):
        value = coef[lo, 5, i]
        for p in range(4, -1, -1):
            value = value * t + coef[lo, p, i]
        q[i] = value
        guess[i] = value
    ps[:, :] = 0.0
    ps[1, :] = 1.0
    vel, acc = len(rt) - 2, len(rt) - 1
    rt[vel, :, :] = 0.0
    rt[acc, :, :] = 0.0
    # a value reduced by whole periods: solved at near_x, moved on by the periods, corrected at x (the
    # numpy path checks the branch at near_x only); else solved and checked at x
    for stage in range(2 if reduced else 1):
        last = stage == 1 or not reduced
        if stage == 1:
            for i in range(m_all):
                q[i] = q[i] + shift[i] * periods
        if _solve_blocks(x if last else near_x, not reduced or not last, last, near, steps, cuts, blocks, sense,
                         phi_drawn, tol, signs, ps, rt, sc, cc, q, guess, jac, perm, res, step, qd_u, qdd_u):
            return 1
    _write(0, row, ps, rt, vel, acc, joints)
    _outputs(x, omega, epsilon, out, off, row, row_off, len(joints.a), ps, rt, vel, acc, point_link, point_at,
             alpha)
    return 0


@_inline
def _real(xq, xqq, omega, epsilon):
    """Real rate and acceleration from the analogues, as `kinematics._motion._real`."""
    if epsilon == 0.0:
        return xq * omega, xqq * (omega * omega)
    return xq * omega, xqq * (omega * omega) + xq * epsilon


@_jit
def _outputs(x, omega, epsilon, out, off, row, row_off, n_j, ps, rt, vel, acc, point_link, point_at, alpha):
    """The record of one solved position (`FIELDS`, at offsets `off`) from its link states and the joint
    values in `row` (the sweep kernel's `_write`, at `row_off`), with the operations of `Motion`."""
    n_l, n_p = ps.shape[1], len(point_link)
    out[off[0]], out[off[1]], out[off[2]] = x, omega, epsilon
    for k in range(n_l):
        wq, eq = rt[vel, 0, k], rt[acc, 0, k]
        w, e = _real(wq, eq, omega, epsilon)
        out[off[3] + k], out[off[4] + k], out[off[5] + k] = ps[0, k] + alpha[k], w, e
        out[off[13] + k], out[off[14] + k] = wq, eq
        # instantaneous centre r + perp(v)/ω of the link's frame; NaN where it does not turn
        vx, vy = rt[vel, 1, k] * omega, rt[vel, 2, k] * omega
        icx, icy = ps[3, k] + -vy / w, ps[4, k] + vx / w
        if not (np.isfinite(icx) and np.isfinite(icy)):
            icx, icy = np.nan, np.nan
        out[off[6] + 2 * k], out[off[6] + 2 * k + 1] = icx, icy
    for p in range(n_p):
        k, atx, aty = point_link[p], point_at[p, 0], point_at[p, 1]
        c, s = ps[1, k], ps[2, k]
        rx, ry = c * atx - s * aty, s * atx + c * aty
        wl, el = rt[vel, 0, k], rt[acc, 0, k]
        w2 = wl * wl
        vqx, vqy = rt[vel, 1, k] - wl * ry, rt[vel, 2, k] + wl * rx
        aqx, aqy = rt[acc, 1, k] - el * ry, rt[acc, 2, k] + el * rx
        aqx, aqy = aqx - w2 * rx, aqy - w2 * ry
        vx, ax = _real(vqx, aqx, omega, epsilon)
        vy, ay = _real(vqy, aqy, omega, epsilon)
        j = 2 * p
        out[off[7] + j], out[off[7] + j + 1] = ps[3, k] + rx, ps[4, k] + ry
        out[off[8] + j], out[off[8] + j + 1], out[off[9] + j], out[off[9] + j + 1] = vx, vy, ax, ay
        out[off[15] + j], out[off[15] + j + 1], out[off[16] + j], out[off[16] + j + 1] = vqx, vqy, aqx, aqy
    for j in range(n_j):
        value, rq, aq = row[0, row_off[0] + j], row[0, row_off[1] + j], row[0, row_off[2] + j]
        rate, accel = _real(rq, aq, omega, epsilon)
        out[off[10] + j], out[off[11] + j], out[off[12] + j] = value, rate, accel
        out[off[17] + j], out[off[18] + j] = rq, aq
