"""The compiled lean path of one position (optional, needs numba): `mbplanar.position` on an engine with
``backend="numba"`` runs one kernel call per position, with every table and work array made once per
engine.

The kernel (`_position`) does for one position what the sweep kernel (`_numba_kinematics`) does per
position of a batch, on the same tables (`_tables.kinematics_tables`), work arrays and atlas
interpolant, with the numpy engine's arithmetic: the joint laws' placement and closure, the scaled block
Jacobian and its factors, the Newton polish, the rate passes; then it writes what `Motion` derives (the
link angles, the points' positions, velocities and accelerations, the joints' values and rates, the
real rates and the instantaneous centres) into the answer's own buffer (a `Position` record,
`kinematics._single.FIELDS`). Input values far from the drawn pose are reduced by the branch's period
as the numpy path does (`engine._atlas._solve_periodic`): solved at the equivalent value near the drawn
pose, moved on by whole turns, and corrected at the value asked.

It answers only where it can vouch for the position, as the sweep kernel: a status other than 0 sends
the position to the slow path here (extend the atlas, find the period) or to the numpy reference
(a change point's bracket, a step the batch corrector would repair, a position past a motion limit,
which the reference reports with its `MotionError`).

Calling cost. A numba dispatcher types every argument on every call, and typing a named tuple of arrays
costs ~1 µs; the solver therefore calls the compiled overload's entry point directly, with arguments
whose types are fixed when the solver binds them (`_Solver._bind`), so that a call costs about a
microsecond before the arithmetic.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..engine._atlas import LOST_PRECISION, far_span
from ..kinematics._motion import _tables
from ..kinematics._single import (FIELDS, Position, checked_speeds, finite_input, layout_of, reference)
from ._numba_kinematics import _atlas_tables, _lu, _lu_solve, _scratch
from ._tables import kinematics_tables

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
        steps, cuts, blocks, joints = kinematics_tables(engine, joint_table)
        offsets = np.array([self.layout.offsets[name] for name, _, _ in FIELDS], np.int64)
        alpha = np.array([engine.reference_angle[n] for n in engine.links], float)
        # the walk's reach from the drawn pose, the period (0 until it is needed), and the limits of a reduction
        self.far = np.array([far_span(engine.solver), 0.0, LOST_PRECISION, FAR_ERROR])
        self.shift = np.zeros(sum(bp.m for bp in engine.blocks))  # the unknowns' change over one period
        self.fixed = (steps, cuts, blocks, joints, float(inp.sense), self.phi0, engine.tol.as_array(), self.far,
                      self.shift, np.ascontiguousarray(links, np.int64), np.ascontiguousarray(at, float), alpha,
                      offsets)
        m_max = max([1] + [bp.m for bp in engine.blocks])
        self.work = _scratch(len(steps.parent), len(cuts.a), len(engine.links), len(self.shift), m_max)
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
_jit = numba.njit(cache=True, error_model="numpy", nogil=True, _nrt=False)
_inline = numba.njit(cache=True, error_model="numpy", nogil=True, _nrt=False, inline="always")

# Scalar loops over arrays indexed in place, compiled without numba's reference counting, nothing
# allocated (the caller passes every work array, `_numba_kinematics._scratch`). Pose ps (5, L): θ, cos θ,
# sin θ, r_x, r_y per link. Rates rt (slots, 3, L): ω, v_x, v_y per link; slots 0 … m−1 hold a block's
# sensitivities to its unknowns, then the velocities, then the accelerations. The arithmetic is the
# numpy engine's, operation for operation where it matters for rounding: the joint laws (`_constraints`),
# the scaled block Jacobian and its factors (`_blocks.ScaledLU`; explicit inverse up to 2 × 2, else LU,
# as `_linalg.factor`), the Newton polish and the rate passes (`BlockSolver.newton`, `_block_rates`).
@_jit
def _solve_blocks(xb, check, rates, near, steps, cuts, blocks, sense, phi_drawn, tol, signs, ps, rt, sc, cc, q,
                  guess, jac, perm, res, col, sol, qd_u):
    """Newton on every block at input value xb from the unknowns q; with `check`, the branch checks of
    `atlas.solve_along` against the atlas node `near` (determinant signs) and the prediction `guess`
    (corrector distance); with `rates`, each block's velocity and acceleration analogues (input rate
    sense·1, acceleration 0) after its solve. Returns 0, or 1 where the numpy path must answer."""
    closure, max_newton, pivot_polish, pivot_cross, max_correction = (  # Tolerances.KERNEL_FIELDS
        tol[0], int(tol[1]), tol[2], tol[3], tol[4])
    row_scale, var_scale = blocks.row_scale, blocks.var_scale
    vel, acc = len(rt) - 2, len(rt) - 1
    q_in = sense * (xb - phi_drawn)
    for bk in range(len(blocks.m)):
        k0, k1, c0, c1 = blocks.step0[bk], blocks.step1[bk], blocks.cut0[bk], blocks.cut1[bk]
        var0, m = blocks.var0[bk], blocks.m[bk]
        # phase 0: Newton; 1: velocity analogues; 2: acceleration analogues
        phase, it, polished, err, finite, det, ratio = 0, 0, False, 0.0, True, 1.0, 1.0
        while True:
            if phase == 0:
                for k in range(k0, k1):  # place the child of tree step k (Revolute/Prismatic.place)
                    parent, child, var = steps.parent[k], steps.child[k], steps.var[k]
                    value = q[var] if var >= 0 else steps.sign[k] * q_in
                    cp, sp = ps[1, parent], ps[2, parent]
                    if not steps.prismatic[k]:
                        s0x, s0y = steps.s0[k, 0], steps.s0[k, 1]
                        rpx, rpy = cp * s0x - sp * s0y, sp * s0x + cp * s0y
                        th = ps[0, parent] + value if steps.relative[k] else value
                        ct, st = np.cos(th), np.sin(th)
                        ps[0, child], ps[1, child], ps[2, child] = th, ct, st
                        rcx, rcy = ct * s0x - st * s0y, st * s0x + ct * s0y
                        ps[3, child] = ps[3, parent] + rpx - rcx
                        ps[4, child] = ps[4, parent] + rpy - rcy
                        sc[k, 0], sc[k, 1], sc[k, 2], sc[k, 3] = rpx, rpy, rcx, rcy
                    else:
                        sign = steps.carrier[k]
                        ux, uy = cp * steps.u0[k, 0] - sp * steps.u0[k, 1], sp * steps.u0[k, 0] + cp * steps.u0[k, 1]
                        ps[0, child], ps[1, child], ps[2, child] = ps[0, parent], cp, sp
                        ps[3, child] = ps[3, parent] + (sign * value) * ux
                        ps[4, child] = ps[4, parent] + (sign * value) * uy
                        sc[k, 0], sc[k, 1], sc[k, 4] = ux, uy, value
                if m == 0:
                    if not rates:
                        break
                    phase = 1
                else:
                    err, finite = 0.0, True
                    for k in range(c0, c1):  # closure rows of cut k (Revolute/Prismatic.closure)
                        row, a, b = 2 * (k - c0), cuts.a[k], cuts.b[k]
                        s0x, s0y = cuts.s0[k, 0], cuts.s0[k, 1]
                        rax, ray = ps[1, a] * s0x - ps[2, a] * s0y, ps[2, a] * s0x + ps[1, a] * s0y
                        rbx, rby = ps[1, b] * s0x - ps[2, b] * s0y, ps[2, b] * s0x + ps[1, b] * s0y
                        if not cuts.prismatic[k]:
                            res[row] = ps[3, a] + rax - ps[3, b] - rbx
                            res[row + 1] = ps[4, a] + ray - ps[4, b] - rby
                        else:  # a carrier, b slider
                            nx = ps[1, a] * cuts.n0[k, 0] - ps[2, a] * cuts.n0[k, 1]
                            ny = ps[2, a] * cuts.n0[k, 0] + ps[1, a] * cuts.n0[k, 1]
                            dx = ps[3, b] + rbx - ps[3, a] - rax
                            dy = ps[4, b] + rby - ps[4, a] - ray
                            res[row] = ps[0, b] - ps[0, a]
                            res[row + 1] = nx * dx + ny * dy
                            cc[k, 4], cc[k, 5], cc[k, 6], cc[k, 7], cc[k, 8] = nx, ny, dx, dy, -ny * dx + nx * dy
                        cc[k, 0], cc[k, 1], cc[k, 2], cc[k, 3] = rax, ray, rbx, rby
                    for i in range(m):
                        r = abs(res[i]) * row_scale[var0 + i]
                        finite = finite and np.isfinite(r)
                        err = max(err, r)
            # a rate pass per slot: the sensitivities to each unknown (the Jacobian's columns), or the
            # velocities, or the accelerations with the velocities' centripetal and Coriolis terms
            s_lo = 0 if phase == 0 else (vel if phase == 1 else acc)
            s_hi = m if phase == 0 else s_lo + 1
            for sl in range(s_lo, s_hi):
                if phase == 0:
                    for t in range(blocks.anchor0[bk], blocks.anchor1[bk]):  # read, not placed: at rest
                        for comp in range(3):
                            rt[sl, comp, blocks.anchors[t]] = 0.0
                for k in range(k0, k1):  # (Revolute/Prismatic.place_rates)
                    parent, child, var = steps.parent[k], steps.child[k], steps.var[k]
                    if phase == 0:
                        qd, qv = (1.0 if var - var0 == sl else 0.0) if var >= 0 else 0.0, 0.0
                    elif var >= 0:
                        qd, qv = 0.0, qd_u[var - var0]
                    else:
                        qd, qv = steps.sign[k] * (sense if phase == 1 else 0.0), steps.sign[k] * sense
                    wp, vpx, vpy = rt[sl, 0, parent], rt[sl, 1, parent], rt[sl, 2, parent]
                    if not steps.prismatic[k]:
                        rpx, rpy, rcx, rcy = sc[k, 0], sc[k, 1], sc[k, 2], sc[k, 3]
                        wc = qd + wp if steps.relative[k] else qd
                        cx = vpx + wp * -rpy - wc * -rcy
                        cy = vpy + wp * rpx - wc * rcx
                        if phase == 2:
                            wvp, wvc = rt[vel, 0, parent], rt[vel, 0, child]
                            cx = cx - (wvp * wvp) * rpx + (wvc * wvc) * rcx
                            cy = cy - (wvp * wvp) * rpy + (wvc * wvc) * rcy
                        rt[sl, 0, child], rt[sl, 1, child], rt[sl, 2, child] = wc, cx, cy
                    else:
                        sign, ux, uy, qq = steps.carrier[k], sc[k, 0], sc[k, 1], sc[k, 4]
                        cx = vpx + sign * (qd * ux + (qq * wp) * -uy)
                        cy = vpy + sign * (qd * uy + (qq * wp) * ux)
                        if phase == 2:
                            wvp = rt[vel, 0, parent]
                            cx = cx + sign * ((2 * qv * wvp) * -uy - (qq * wvp * wvp) * ux)
                            cy = cy + sign * ((2 * qv * wvp) * ux - (qq * wvp * wvp) * uy)
                        rt[sl, 0, child], rt[sl, 1, child], rt[sl, 2, child] = wp, cx, cy
                for k in range(c0, c1):  # the closure's rates (Revolute/Prismatic.closure_rates)
                    row, a, b = 2 * (k - c0), cuts.a[k], cuts.b[k]
                    rax, ray, rbx, rby = cc[k, 0], cc[k, 1], cc[k, 2], cc[k, 3]
                    wa, wb = rt[sl, 0, a], rt[sl, 0, b]
                    if not cuts.prismatic[k]:
                        ox = rt[sl, 1, a] + wa * -ray - rt[sl, 1, b] - wb * -rby
                        oy = rt[sl, 2, a] + wa * rax - rt[sl, 2, b] - wb * rbx
                        if phase == 2:
                            wva, wvb = rt[vel, 0, a], rt[vel, 0, b]
                            ox = ox - (wva * wva) * rax + (wvb * wvb) * rbx
                            oy = oy - (wva * wva) * ray + (wvb * wvb) * rby
                        col[row], col[row + 1] = ox, oy
                    else:  # a carrier, b slider
                        nx, ny, dx, dy, pnd = cc[k, 4], cc[k, 5], cc[k, 6], cc[k, 7], cc[k, 8]
                        drx = rt[sl, 1, b] + wb * -rby - rt[sl, 1, a] - wa * -ray
                        dry = rt[sl, 2, b] + wb * rbx - rt[sl, 2, a] - wa * rax
                        o1 = drx * nx + dry * ny + wa * pnd
                        if phase == 2:
                            ws, wcr = rt[vel, 0, b], rt[vel, 0, a]
                            dvx = rt[vel, 1, b] + ws * -rby - rt[vel, 1, a] - wcr * -ray
                            dvy = rt[vel, 2, b] + ws * rbx - rt[vel, 2, a] - wcr * rax
                            bx = -(ws * ws) * rbx + (wcr * wcr) * rax
                            by = -(ws * ws) * rby + (wcr * wcr) * ray
                            o1 += (-(wcr * wcr) * (nx * dx + ny * dy) + 2 * wcr * (-ny * dvx + nx * dvy)
                                   + (nx * bx + ny * by))
                        col[row], col[row + 1] = wb - wa, o1
                if phase == 0:
                    for i in range(m):
                        jac[i, sl] = col[i]
            if phase == 0:
                # the Jacobian made dimensionless (ScaledLU) and factored as _linalg.factor
                for i in range(m):
                    for j in range(m):
                        jac[i, j] = jac[i, j] * row_scale[var0 + i] / var_scale[var0 + j]
                if m == 1:
                    det = jac[0, 0]
                    jac[0, 0] = 1.0 / det
                    ratio = abs(det) / max(abs(det), 1e-300)
                elif m == 2:
                    a00, a01, a10, a11 = jac[0, 0], jac[0, 1], jac[1, 0], jac[1, 1]
                    det = a00 * a11 - a01 * a10
                    jac[0, 0], jac[0, 1], jac[1, 0], jac[1, 1] = a11 / det, -a01 / det, -a10 / det, a00 / det
                    first = max(abs(a00), abs(a10))
                    p0, p1 = abs(first), abs(det / first)
                    ratio = min(p0, p1) / max(max(p0, p1), 1e-300)
                else:
                    det, ratio = _lu(jac, m, perm)
                ok = err < closure and finite
                done = False
                if ok and not polished:
                    # near a singular position one more step, as BlockSolver.newton does
                    polished = True
                    done = ratio >= pivot_polish or ratio < pivot_cross * 1e3
                elif ok or it == max_newton:
                    done = True
                if done:
                    if not ok:
                        return 1
                    if check:  # the checks of atlas.solve_along
                        if not (det != 0.0 and np.isfinite(det)) or (det > 0) != (signs[near, bk] > 0):
                            return 1
                        for i in range(m):
                            if not abs(q[var0 + i] - guess[var0 + i]) * var_scale[var0 + i] <= max_correction:
                                return 1
                    if not rates:
                        break
                    phase = 1
                    continue
                rhs = res
            elif m == 0:
                phase += 1
                if phase == 3:
                    break
                continue
            else:
                rhs = col
            # sol = J⁻¹ (−rhs): the Newton step, or the unknowns' rates (ScaledLU.solve)
            for i in range(m):
                rhs[i] = -rhs[i] * row_scale[var0 + i]
            if m == 1:
                sol[0] = jac[0, 0] * rhs[0]
            elif m == 2:
                sol[0] = jac[0, 0] * rhs[0] + jac[0, 1] * rhs[1]
                sol[1] = jac[1, 0] * rhs[0] + jac[1, 1] * rhs[1]
            else:
                _lu_solve(jac, m, perm, rhs, sol)
            for i in range(m):
                sol[i] = sol[i] / var_scale[var0 + i]
            if phase == 0:
                for i in range(m):
                    if np.isfinite(sol[i]):
                        q[var0 + i] += sol[i]
                it += 1
                continue
            slot = vel if phase == 1 else acc
            for k in range(k0, k1):  # the block's links corrected by the sensitivities
                link = steps.child[k]
                for comp in range(3):
                    total = rt[0, comp, link] * sol[0]
                    for j in range(1, m):
                        total += rt[j, comp, link] * sol[j]
                    rt[slot, comp, link] += total
            if phase == 1:
                for i in range(m):
                    qd_u[i] = sol[i]
            phase += 1
            if phase == 3:
                break
    return 0


@_jit
def _position(x, omega, epsilon, out, steps, cuts, blocks, joints, sense, phi_drawn, tol, far, shift, point_link,
              point_at, alpha, off, grid, coef, signs, limits, brackets, ps, rt, sc, cc, q, guess, jac, perm, res,
              col, sol, qd_u):
    """Solve the position x and write its `Position` record into out (at the offsets `off` of `FIELDS`);
    returns the status (0 written; 1 the reference's, 2 outside the atlas, 3 far from the drawn pose with
    the period not yet known: see `_Solver._slow`). far: the walk's reach, the period T, the largest
    float spacing of a reduced value and the largest uncertainty of a reduction
    (`engine._atlas._periods_away`); shift (M,): the unknowns' change over one period."""
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
    # the interval around the value (numpy's searchsorted − 1, clipped) by bisection, the quintic Hermite
    # interpolant between its nodes, and the nearest node
    lo, hi = 0, n_grid - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if grid[mid] < near_x:
            lo = mid
        else:
            hi = mid
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
    rt[:, :, :] = 0.0  # the ground stays at rest; every other link is placed
    # a value reduced by whole periods: solved at near_x, moved on by the periods, corrected at x (the
    # numpy path checks the branch at near_x only); else solved and checked at x
    for stage in range(2 if reduced else 1):
        last = stage == 1 or not reduced
        if stage == 1:
            for i in range(m_all):
                q[i] = q[i] + shift[i] * periods
        if _solve_blocks(x if last else near_x, not reduced or not last, last, near, steps, cuts, blocks, sense,
                         phi_drawn, tol, signs, ps, rt, sc, cc, q, guess, jac, perm, res, col, sol, qd_u):
            return 1
    _outputs(x, omega, epsilon, out, off, joints, ps, rt, point_link, point_at, alpha)
    return 0


@_inline
def _real(xq, xqq, omega, epsilon):
    """Real rate and acceleration from the analogues, as `kinematics._motion._real`."""
    if epsilon == 0.0:
        return xq * omega, xqq * (omega * omega)
    return xq * omega, xqq * (omega * omega) + xq * epsilon


@_jit
def _outputs(x, omega, epsilon, out, off, joints, ps, rt, point_link, point_at, alpha):
    """The record of one solved position (`FIELDS`, at offsets `off`) from its link states, with the
    operations of `Motion` (`kinematics._motion`: `_moving_points`, `_joint_values`, `_real`,
    `_instant_centres`)."""
    n_l, n_p = ps.shape[1], len(point_link)
    vel, acc = len(rt) - 2, len(rt) - 1
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
    for j in range(len(joints.a)):
        la, lb = joints.a[j], joints.b[j]
        ws, wc, es, ec = rt[vel, 0, lb], rt[vel, 0, la], rt[acc, 0, lb], rt[acc, 0, la]
        if not joints.prismatic[j]:
            value, rq, aq = ps[0, lb] - ps[0, la] + joints.drawn[j], ws - wc, es - ec
        else:  # slider point minus carrier point, along the carrier's guide
            atx, aty = joints.at[j, 0], joints.at[j, 1]
            psx, psy = ps[1, lb] * atx - ps[2, lb] * aty, ps[2, lb] * atx + ps[1, lb] * aty
            pcx, pcy = ps[1, la] * atx - ps[2, la] * aty, ps[2, la] * atx + ps[1, la] * aty
            dx, dy = ps[3, lb] + psx - ps[3, la] - pcx, ps[4, lb] + psy - ps[4, la] - pcy
            ddx = rt[vel, 1, lb] - ws * psy - rt[vel, 1, la] + wc * pcy
            ddy = rt[vel, 2, lb] + ws * psx - rt[vel, 2, la] - wc * pcx
            dddx = (rt[acc, 1, lb] - es * psy - ws * ws * psx) - (rt[acc, 1, la] - ec * pcy - wc * wc * pcx)
            dddy = (rt[acc, 2, lb] + es * psx - ws * ws * psy) - (rt[acc, 2, la] + ec * pcx - wc * wc * pcy)
            ux = ps[1, la] * joints.u0[j, 0] - ps[2, la] * joints.u0[j, 1]
            uy = ps[2, la] * joints.u0[j, 0] + ps[1, la] * joints.u0[j, 1]
            pud, ud = -uy * dx + ux * dy, ux * dx + uy * dy
            value = joints.drawn[j] + ud
            rq = wc * pud + ux * ddx + uy * ddy
            aq = ec * pud - wc * wc * ud + 2 * wc * (-uy * ddx + ux * ddy) + ux * dddx + uy * dddy
        rate, accel = _real(rq, aq, omega, epsilon)
        out[off[10] + j], out[off[11] + j], out[off[12] + j] = value, rate, accel
        out[off[17] + j], out[off[18] + j] = rq, aq
