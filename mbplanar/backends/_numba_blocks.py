"""Per-position building blocks of the compiled kernels: placing a tree step, a cut's closure, LU with
partial pivoting, the grid interval around an input value. Each is a small function that numba compiles
once, on its own, and LLVM inlines where it is called (the compiled `_numba_kinematics._sweep` calls
none of them); the kinematics kernel calls each once, and the kinetostatics and design kernels take them
from here. Not numba's own inlining (``inline="always"``): that types and lowers the body again inside
every caller, which made the kinematics kernel's first compile about 0.5 s (5 %) longer.
"""

from __future__ import annotations

import math

from ._jit import njit
from ..engine import hermite_coefficients, hermite_slope, hermite_value, rate_jump, step_verdict

__all__ = ["_part", "_place", "_closure", "_lu", "_lu_solve", "_pivot_ratio_2", "_interval", "_step_verdict",
           "_rate_jump", "_hermite_coefficients", "_hermite_value", "_hermite_slope"]

# -- kernels ----------------------------------------------------------------------------------------
# Scalar loops over whole arrays indexed in place, compiled without numba's reference counting (its
# atomic increments on every array passed or aliased would cost more than the arithmetic): so nothing is
# allocated here, the caller passes every work array (`_scratch`).
# Pose ps (5, L): θ, cos θ, sin θ, r_x, r_y per link. Rates rt (slots, 3, L): ω, v_x, v_y per link;
# slots 0 … m−1 hold a block's sensitivities to its unknowns, then the velocities, then the accelerations.
# Compiled with numba's pipeline less the passes these kernels have nothing for (`_jit.lean_pipeline`).
# fastmath set (to off) rather than left out: numba lets a function compiled without it inherit its first
# caller's, so the design kernel's (FMA contraction) would otherwise reach the copy every kernel shares
# from numba's cache, and the sweep's results would depend on which kernel was compiled first.
_part = njit(cache=True, error_model="numpy", nogil=True, _nrt=False, lean=True, fastmath=False)


@_part
def _place(k, steps, q, q_in, ps, sc):
    """Place the child of tree step k; caches rho_parent, rho_child (R) or u, q (P) in sc[k]."""
    parent, child, rel, var = steps.parent[k], steps.child[k], steps.relative[k], steps.var[k]
    value = q[var] if var >= 0 else steps.sign[k] * q_in
    cp, sp = ps[1, parent], ps[2, parent]
    if not steps.prismatic[k]:
        s0x, s0y = steps.s0[k, 0], steps.s0[k, 1]
        rpx, rpy = cp * s0x - sp * s0y, sp * s0x + cp * s0y
        t = ps[0, parent] + value if rel else value
        cc, ss = math.cos(t), math.sin(t)
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


@_part
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


@_part
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
    det, lo, hi = sign, math.inf, 0.0
    for i in range(m):
        det *= a[i, i]
        lo, hi = min(lo, abs(a[i, i])), max(hi, abs(a[i, i]))
    return det, lo / max(hi, 1e-300)


@_part
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


@_part
def _pivot_ratio_2(first, det, polish):
    """The pivot ratio of a 2 × 2 Jacobian as `engine._linalg.factor` forms it (p0 = `first`, the larger
    |entry| of its first column; p1 = |det / first|; min(p0, p1) / max(p0, p1, 1e-300)), or `polish`
    itself where the ratio is shown to be at least `polish` without dividing.

    The ratio equals min(f², |det|) / max(f², |det|) (f = first); a margin of 1e-9 over the few roundings
    of either form leaves no doubt on which side of `polish` it lies, within ranges where f² and the
    products neither overflow nor underflow. Its one use, Newton's polish decision (ratio ≥ `polish`, or
    below the crossing threshold), is therefore the same either way; the two divisions in a row it saves
    were a tenth of a four-bar position's time."""
    d = abs(det)
    if 1e-100 < first < 1e100 and d < 1e200 and polish >= 1e-50:
        f2 = first * first
        if min(f2, d) >= (polish * (1.0 + 1e-9)) * max(f2, d):
            return polish
    p0, p1 = first, abs(det / first)
    return min(p0, p1) / max(max(p0, p1), 1e-300)


@_part
def _interval(grid, count, x):
    """i with grid[i] <= x <= grid[i + 1] among the first `count` nodes (bisection)."""
    lo, hi = 0, count - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if grid[mid] < x:
            lo = mid
        else:
            hi = mid
    return lo


# the continuation's rules, written once in `engine._continuation` for numpy and compiled here, as they are,
# for the kernels (the acceptance of a step, the rate jump, the quintic Hermite interpolant)
_step_verdict = _part(step_verdict)
_rate_jump = _part(rate_jump)
_hermite_coefficients = _part(hermite_coefficients)
_hermite_value = _part(hermite_value)
_hermite_slope = _part(hermite_slope)
