"""The per-position building blocks of the compiled kernels: placing a tree step, a cut's closure, their
rate passes, a block's Jacobian and rates, LU with partial pivoting. Each is a small function that numba
inlines where it is called (``inline="always"``).

The design kernel (`_numba_design`) calls them from several places of its own; the kinematics kernel
(`_numba_kinematics`) calls the placement, the closure and LU once each and writes its rate passes once
inside its one function, so that numba compiles each piece once.
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["_jit", "_inline", "_place", "_closure", "_step_rates", "_closure_rates", "_lu", "_lu_solve",
           "_jacobian", "_block_rates"]

# -- kernels ----------------------------------------------------------------------------------------
# Scalar loops over whole arrays indexed in place, compiled without numba's reference counting (its
# atomic increments on every array passed or aliased would cost more than the arithmetic): so nothing
# is allocated here, the caller passes every work array (`_scratch`).
# Pose ps (5, L): θ, cos θ, sin θ, r_x, r_y per link. Rates rt (slots, 3, L): ω, v_x, v_y per link;
# slots 0 … m−1 hold a block's sensitivities to its unknowns, then the velocities, then the accelerations.
_jit = numba.njit(cache=True, error_model="numpy", nogil=True, _nrt=False)
_inline = numba.njit(cache=True, error_model="numpy", nogil=True, _nrt=False, inline="always")


@_inline
def _place(k, steps, q, q_in, ps, sc):
    """Place the child of tree step k; caches rho_parent, rho_child (R) or u, q (P) in sc[k]."""
    parent, child, rel, var = steps.parent[k], steps.child[k], steps.relative[k], steps.var[k]
    value = q[var] if var >= 0 else steps.sign[k] * q_in
    cp, sp = ps[1, parent], ps[2, parent]
    if not steps.prismatic[k]:
        s0x, s0y = steps.s0[k, 0], steps.s0[k, 1]
        rpx, rpy = cp * s0x - sp * s0y, sp * s0x + cp * s0y
        t = ps[0, parent] + value if rel else value
        cc, ss = np.cos(t), np.sin(t)
        ps[0, child], ps[1, child], ps[2, child] = t, cc, ss
        rcx, rcy = cc * s0x - ss * s0y, ss * s0x + cc * s0y
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


@_inline
def _closure(k, cuts, ps, cc, res, row):
    """Residual rows row, row + 1 of cut k; caches what its rates need in cc[k]."""
    a, b = cuts.a[k], cuts.b[k]
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


@_inline
def _step_rates(k, steps, sc, rt, slot, qd, vel, qv):
    """Rates in rt[slot] of step k's child from its parent's and the tree variable's rate qd; with
    vel >= 0 they are accelerations, rt[vel] holding the velocities and qv the variable's velocity."""
    parent, child, rel = steps.parent[k], steps.child[k], steps.relative[k]
    wp, vpx, vpy = rt[slot, 0, parent], rt[slot, 1, parent], rt[slot, 2, parent]
    if not steps.prismatic[k]:
        rpx, rpy, rcx, rcy = sc[k, 0], sc[k, 1], sc[k, 2], sc[k, 3]
        wc = qd + wp if rel else qd
        cx = vpx + wp * -rpy - wc * -rcy
        cy = vpy + wp * rpx - wc * rcx
        if vel >= 0:
            Wp, Wc = rt[vel, 0, parent], rt[vel, 0, child]
            cx = cx - (Wp * Wp) * rpx + (Wc * Wc) * rcx
            cy = cy - (Wp * Wp) * rpy + (Wc * Wc) * rcy
        rt[slot, 0, child], rt[slot, 1, child], rt[slot, 2, child] = wc, cx, cy
    else:
        sign, ux, uy, q = steps.carrier[k], sc[k, 0], sc[k, 1], sc[k, 4]
        cx = vpx + sign * (qd * ux + (q * wp) * -uy)
        cy = vpy + sign * (qd * uy + (q * wp) * ux)
        if vel >= 0:
            Wp = rt[vel, 0, parent]
            cx = cx + sign * ((2 * qv * Wp) * -uy - (q * Wp * Wp) * ux)
            cy = cy + sign * ((2 * qv * Wp) * ux - (q * Wp * Wp) * uy)
        rt[slot, 0, child], rt[slot, 1, child], rt[slot, 2, child] = wp, cx, cy


@_inline
def _closure_rates(k, cuts, cc, rt, slot, vel, out, row):
    """Rate rows of cut k from rt[slot] (its Jacobian column when the slot holds sensitivities); with
    vel >= 0 the centripetal and Coriolis terms from the velocities rt[vel]."""
    a, b = cuts.a[k], cuts.b[k]
    rax, ray, rbx, rby = cc[k, 0], cc[k, 1], cc[k, 2], cc[k, 3]
    wa, wb = rt[slot, 0, a], rt[slot, 0, b]
    if not cuts.prismatic[k]:
        ox = rt[slot, 1, a] + wa * -ray - rt[slot, 1, b] - wb * -rby
        oy = rt[slot, 2, a] + wa * rax - rt[slot, 2, b] - wb * rbx
        if vel >= 0:
            Wa, Wb = rt[vel, 0, a], rt[vel, 0, b]
            ox = ox - (Wa * Wa) * rax + (Wb * Wb) * rbx
            oy = oy - (Wa * Wa) * ray + (Wb * Wb) * rby
        out[row], out[row + 1] = ox, oy
    else:  # a carrier, b slider
        nx, ny, dx, dy, pnd = cc[k, 4], cc[k, 5], cc[k, 6], cc[k, 7], cc[k, 8]
        drx = rt[slot, 1, b] + wb * -rby - rt[slot, 1, a] - wa * -ray
        dry = rt[slot, 2, b] + wb * rbx - rt[slot, 2, a] - wa * rax
        o1 = drx * nx + dry * ny + wa * pnd
        if vel >= 0:
            Ws, Wc = rt[vel, 0, b], rt[vel, 0, a]
            dvx = rt[vel, 1, b] + Ws * -rby - rt[vel, 1, a] - Wc * -ray
            dvy = rt[vel, 2, b] + Ws * rbx - rt[vel, 2, a] - Wc * rax
            bx = -(Ws * Ws) * rbx + (Wc * Wc) * rax
            by = -(Ws * Ws) * rby + (Wc * Wc) * ray
            o1 += -(Wc * Wc) * (nx * dx + ny * dy) + 2 * Wc * (-ny * dvx + nx * dvy) + (nx * bx + ny * by)
        out[row], out[row + 1] = wb - wa, o1


@_inline
def _lu(a, m, perm):
    """LU with partial pivoting of a[:m, :m] in place (first largest pivot, as numpy's argmax);
    returns (det, min |pivot| / max |pivot|)."""
    sign = 1.0
    for i in range(m):
        perm[i] = i
    for k in range(m - 1):
        p, big = k, abs(a[k, k])
        for i in range(k + 1, m):
            if abs(a[i, k]) > big:
                p, big = i, abs(a[i, k])
        if p != k:
            for j in range(m):
                a[k, j], a[p, j] = a[p, j], a[k, j]
            perm[k], perm[p] = perm[p], perm[k]
            sign = -sign
        for i in range(k + 1, m):
            a[i, k] /= a[k, k]
            for j in range(k + 1, m):
                a[i, j] -= a[i, k] * a[k, j]
    det, lo, hi = sign, np.inf, 0.0
    for i in range(m):
        det *= a[i, i]
        lo, hi = min(lo, abs(a[i, i])), max(hi, abs(a[i, i]))
    return det, lo / max(hi, 1e-300)


@_inline
def _lu_solve(a, m, perm, b, x):
    """x = A⁻¹ b from the factors of `_lu` (b is left as it was)."""
    for i in range(m):
        x[i] = b[perm[i]]
    for i in range(1, m):
        for j in range(i):
            x[i] -= a[i, j] * x[j]
    for i in range(m - 1, -1, -1):
        for j in range(i + 1, m):
            x[i] -= a[i, j] * x[j]
        x[i] /= a[i, i]


@_inline
def _jacobian(k0, k1, c0, c1, a0, a1, m, var0, steps, cuts, anchors, sc, cc, rt, jac, col):
    """Closure Jacobian (m, m) of a block, and in rt[0 … m − 1] the sensitivities of its links' rates to
    each unknown (the links outside the block stay at 0)."""
    for j in range(m):
        for t in range(a0, a1):  # the links the block reads but does not place are at rest
            for comp in range(3):
                rt[j, comp, anchors[t]] = 0.0
        for k in range(k0, k1):
            _step_rates(k, steps, sc, rt, j, 1.0 if steps.var[k] - var0 == j and steps.var[k] >= 0 else 0.0, -1,
                        0.0)
        for k in range(c0, c1):
            _closure_rates(k, cuts, cc, rt, j, -1, col, 2 * (k - c0))
        for i in range(m):
            jac[i, j] = col[i]


@_inline
def _block_rates(k0, k1, c0, c1, m, var0, steps, cuts, sc, cc, rt, slot, vel, lu, perm, q_in_rate, qd_vel,
                 q_in_vel, rhs, out):
    """A block's link rates into rt[slot] (accelerations with vel >= 0), its unknowns' rates into
    out[:m]; qd_vel, q_in_vel: the unknowns' and the input's velocities (for the Coriolis terms)."""
    for k in range(k0, k1):
        var, sign = steps.var[k], steps.sign[k]
        qd = 0.0 if var >= 0 else sign * q_in_rate
        qv = qd_vel[var - var0] if var >= 0 else sign * q_in_vel
        _step_rates(k, steps, sc, rt, slot, qd, vel, qv)
    if m == 0:
        return
    for k in range(c0, c1):
        _closure_rates(k, cuts, cc, rt, slot, vel, rhs, 2 * (k - c0))
    for i in range(m):
        rhs[i] = -rhs[i]
    _lu_solve(lu, m, perm, rhs, out)
    for k in range(k0, k1):
        link = steps.child[k]
        for j in range(m):
            for comp in range(3):
                rt[slot, comp, link] += rt[j, comp, link] * out[j]
