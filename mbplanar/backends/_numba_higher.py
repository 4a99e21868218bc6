"""The higher pairs' laws as compiled building blocks: the curves c(u) and their derivatives, each pair's
closure residuals, and their rates (a Jacobian column, the velocity's or the acceleration's right-hand
side), per position as scalar code, for the kernels to call where they call the lower pairs' (`_numba_blocks`).

They are the laws of `engine._higher` and the curves of `model._curves`, written again per position, in
the same order of operations (the tests hold them equal to numpy's to rounding); like `_numba_blocks`,
each is compiled on its own with fastmath off and inlined by LLVM where it is called, and nothing is
allocated here. The tables are `engine._higher_tables`' (`HigherTables` hp, `CurveTables` cv: each
an array of integers and one of reals, their columns named there).

Pose ps (5, L): θ, cos θ, sin θ, r_x, r_y per link; rates rt (slots, 3, L): ω, v_x, v_y per link (as
`_numba_blocks`). The cache hc (H, `HIGHER_CACHE`) holds, per pair, what its rates read from its closure:
a rack ρ_C, ρ_A, d, U; a point on a curve R·c, R·c', R·c'', then ρ_F in columns 8, 9; a flat face
R·c … R·c⁽³⁾, ρ_F, N, d (pairs of columns, x then y). wk (`CURVE_WORK`,) is the Cox–de Boor recursion's
work vector.
"""

from __future__ import annotations

import math

from ._jit import njit
from ..engine import higher_layout as ht  # (the tables' column names)

# compiled as `_numba_blocks._part` is (fastmath set to off: see there)
_part = njit(cache=True, error_model="numpy", nogil=True, _nrt=False, lean=True, fastmath=False)

__all__ = ["_deboor", "_base", "_offset", "_curve_into", "_higher_closure", "_higher_rates"]  # (and parts per kind)


@_part
def _deboor(knots, coefs, k0, k1, c0, k, x, wk):
    """(x, y) of the B-spline of degree k with the knots knots[k0:k1] and coefficients from coefs[c0] on
    at x, as scipy's `BSpline` (extrapolated from the end intervals): the knot interval l with
    t[l] <= x < t[l + 1] (k <= l < n), the k + 1 basis functions there (Cox–de Boor), their sum."""
    if x != x:
        return math.nan, math.nan
    n = k1 - k0 - k - 1
    ell, top = k, n - 1  # (bisection for the last l <= n − 1 with t[l] <= x: scipy's interval, found faster)
    while ell < top:
        mid = (ell + top + 1) // 2
        if knots[k0 + mid] <= x:
            ell = mid
        else:
            top = mid - 1
    h = 0           # h = wk[0 … k], hh = wk[k + 1 … 2k + 1]
    hh = k + 1
    wk[h] = 1.0
    for j in range(1, k + 1):
        for i in range(j):
            wk[hh + i] = wk[h + i]
        wk[h] = 0.0
        for i in range(1, j + 1):
            xb, xa = knots[k0 + ell + i], knots[k0 + ell + i - j]
            if xb == xa:
                wk[h + i] = 0.0
                continue
            w = wk[hh + i - 1] / (xb - xa)
            wk[h + i - 1] += w * (xb - x)
            wk[h + i] = w * (x - xa)
    ox, oy = 0.0, 0.0
    for i in range(k + 1):
        ox += coefs[c0 + ell + i - k, 0] * wk[h + i]
        oy += coefs[c0 + ell + i - k, 1] * wk[h + i]
    return ox, oy


@_part
def _base(cv, j, u, n, wk):
    """(x, y) of dⁿc/duⁿ (n = 0 … 3) of curve j without its offset (`Circle.point`, `Spline.point`)."""
    ci, cr = cv.ints, cv.reals
    if ci[j, ht.C_CIRCLE]:
        r, c, s = cr[j, ht.C_RADIUS], math.cos(u), math.sin(u)
        turn = n % 4      # the n-th derivative of (cos u, sin u) is the vector turned by n·90°
        if turn == 0:   # (n = 0: the point, about the centre)
            return r * c + cr[j, ht.C_CENTRE], r * s + cr[j, ht.C_CENTRE + 1]
        if turn == 1:
            return r * -s, r * c
        if turn == 2:
            return r * -c, r * -s
        return r * s, r * -c
    k0, k1, c0, k = ci[j, ht.C_KNOT0 + n], ci[j, ht.C_KNOT1 + n], ci[j, ht.C_COEF0 + n], ci[j, ht.C_DEGREE] - n
    x = u
    if ci[j, ht.C_CLOSED]:
        lo, period = cr[j, ht.C_LO], cr[j, ht.C_HI] - cr[j, ht.C_LO]
        x = lo + (x - lo) % period                          # Shape.wrap
        first, last = cv.knots[k0 + k], cv.knots[k1 - k - 1]
        x = first + (x - first) % (last - first)            # BSpline's periodic extrapolation
    return _deboor(cv.knots, cv.coefs, k0, k1, c0, k, x, wk)


@_part
def _offset(dist, bx, by, d1x, d1y, d2x, d2y, d3x, d3y, n):
    """(x, y) of the n-th derivative (n = 0 … 2) of the curve moved by `dist` along its left normal,
    from its base's point b and derivatives d1 … d3 (`Offset.point`; n = 0 reads b and d1 only)."""
    if n == 0:
        speed = math.hypot(d1x, d1y)
        return bx + dist * -d1y / speed, by + dist * d1x / speed
    speed2 = d1x * d1x + d1y * d1y                           # model._curves.curvature
    speed3 = speed2 * math.sqrt(speed2)
    cross = d1x * d2y - d1y * d2x
    kappa = cross / speed3
    dot12 = d1x * d2x + d1y * d2y
    dkappa = ((d1x * d3y - d1y * d3x) - 3.0 * cross * (dot12 / speed2)) / speed3
    f = 1.0 - dist * kappa
    if n == 1:
        return d1x * f, d1y * f
    return d2x * f - dist * dkappa * d1x, d2y * f - dist * dkappa * d1y


@_part
def _curve_into(cv, j, u, count, link, ps, wk, hc, h):
    """R(θ_link)·dⁿc/duⁿ of curve j for n = 0 … count − 1 (the curve's derivatives on its link, turned
    with it) into hc[h, 2n], hc[h, 2n + 1]; an offset curve's (count <= 3) from its base's point and
    three derivatives, each evaluated once."""
    c, s = ps[1, link], ps[2, link]
    if not cv.ints[j, ht.C_OFFSET]:
        for n in range(count):
            x, y = _base(cv, j, u, n, wk)
            hc[h, 2 * n], hc[h, 2 * n + 1] = c * x - s * y, s * x + c * y
        return
    bx, by = _base(cv, j, u, 0, wk)
    d1x, d1y = _base(cv, j, u, 1, wk)
    d2x, d2y = _base(cv, j, u, 2, wk)
    d3x, d3y = _base(cv, j, u, 3, wk)
    dist = cv.reals[j, ht.C_DISTANCE]
    for n in range(count):
        x, y = _offset(dist, bx, by, d1x, d1y, d2x, d2y, d3x, d3y, n)
        hc[h, 2 * n], hc[h, 2 * n + 1] = c * x - s * y, s * x + c * y


@_part
def _higher_closure(h, hp, cv, ps, q, hc, wk, res):
    """Residual rows (from its H_ROW on) of higher pair h in its block's residual `res` (`Gear`, `Rack`,
    `PointOnCurve`, `FaceOnCurve`.closure), its contact parameter read from q; caches hc[h]. (One small
    function per kind: LLVM inlines the small ones where the kernel calls this.)"""
    hi = hp.ints
    if hi[h, ht.H_GEAR]:
        _gear_closure(h, hp, ps, res)
    elif hi[h, ht.H_RACK]:
        _rack_closure(h, hp, ps, hc, res)
    else:
        _curve_closure(h, hp, cv, ps, q, hc, wk, res)


@_part
def _gear_closure(h, hp, ps, res):
    """r_a(θ_a − θ_c) ± r_b(θ_b − θ_c) (`Gear.closure`)."""
    hi, hr = hp.ints, hp.reals
    res[hi[h, ht.H_ROW]] = (hr[h, ht.H_COEF] * ps[0, hi[h, ht.H_A]] + hr[h, ht.H_COEF + 1] * ps[0, hi[h, ht.H_B]]
                         + hr[h, ht.H_COEF + 2] * ps[0, hi[h, ht.H_CARRIER]])


@_part
def _rack_closure(h, hp, ps, hc, res):
    """(X_C − X_A)·U + σr·(θ_p − θ_k), a the pinion, b the rack (`Rack.closure`)."""
    hi, hr = hp.ints, hp.reals
    row, a, b = hi[h, ht.H_ROW], hi[h, ht.H_A], hi[h, ht.H_B]
    cx, cy, ax, ay = hr[h, ht.H_CENTRE], hr[h, ht.H_CENTRE + 1], hr[h, ht.H_AT], hr[h, ht.H_AT + 1]
    lx, ly = hr[h, ht.H_AXIS], hr[h, ht.H_AXIS + 1]
    rcx, rcy = ps[1, a] * cx - ps[2, a] * cy, ps[2, a] * cx + ps[1, a] * cy
    rax, ray = ps[1, b] * ax - ps[2, b] * ay, ps[2, b] * ax + ps[1, b] * ay
    dx, dy = ps[3, a] + rcx - ps[3, b] - rax, ps[4, a] + rcy - ps[4, b] - ray
    ux, uy = ps[1, b] * lx - ps[2, b] * ly, ps[2, b] * lx + ps[1, b] * ly
    res[row] = (dx * ux + dy * uy) + hr[h, ht.H_SIGMA_R] * (ps[0, a] - ps[0, b])
    hc[h, 0], hc[h, 1], hc[h, 2], hc[h, 3] = rcx, rcy, rax, ray
    hc[h, 4], hc[h, 5], hc[h, 6], hc[h, 7] = dx, dy, ux, uy


@_part
def _curve_closure(h, hp, cv, ps, q, hc, wk, res):
    """X_F(P) − X_C(c(u)) (a point on the curve, `PointOnCurve.closure`) or N·(X_C(c(u)) − X_F(A)), N·T
    (a flat face, `FaceOnCurve.closure`), a the curve's link, b the follower's."""
    hi, hr = hp.ints, hp.reals
    row, a, b = hi[h, ht.H_ROW], hi[h, ht.H_A], hi[h, ht.H_B]
    j, u = hi[h, ht.H_CURVE], q[hi[h, ht.H_VAR]]
    px, py = hr[h, ht.H_AT], hr[h, ht.H_AT + 1]
    rfx, rfy = ps[1, b] * px - ps[2, b] * py, ps[2, b] * px + ps[1, b] * py
    _curve_into(cv, j, u, 3 if not hi[h, ht.H_FLAT] else 4, a, ps, wk, hc, h)  # (R·c … R·c'', a face's R·c⁽³⁾)
    if not hi[h, ht.H_FLAT]:   # a curve, b point
        res[row] = ps[3, b] + rfx - ps[3, a] - hc[h, 0]
        res[row + 1] = ps[4, b] + rfy - ps[4, a] - hc[h, 1]
        hc[h, 8], hc[h, 9] = rfx, rfy
        return
    # a curve, b face
    ex, ey = hr[h, ht.H_AXIS], hr[h, ht.H_AXIS + 1]
    nx, ny = ps[1, b] * ex - ps[2, b] * ey, ps[2, b] * ex + ps[1, b] * ey
    dx, dy = ps[3, a] + hc[h, 0] - ps[3, b] - rfx, ps[4, a] + hc[h, 1] - ps[4, b] - rfy
    res[row] = nx * dx + ny * dy
    res[row + 1] = nx * hc[h, 2] + ny * hc[h, 3]
    hc[h, 8], hc[h, 9], hc[h, 10], hc[h, 11], hc[h, 12], hc[h, 13] = rfx, rfy, nx, ny, dx, dy


@_part
def _turning(w, x, y, pu, d1x, d1y, d2x, d2y, big_w, big_u, accel):
    """Rate (x, y) of a vector V = R·f(u) of a link turning at w (`_higher._turning`): ω·perp(V) + d1·u̇
    (d1 = R·f', u̇ = pu; 0 for a fixed vector), and in an acceleration pass (`accel`, the link's angular
    velocity big_w, the parameter's big_u) −Ω²V + 2ΩU·perp(d1) + U²·d2 (d2 = R·f'')."""
    ox, oy = w * -y + d1x * pu, w * x + d1y * pu
    if accel:
        ww, wu2, uu = big_w * big_w, 2 * big_w * big_u, big_u * big_u
        ox, oy = ox - ww * x + wu2 * -d1y + uu * d2x, oy - ww * y + wu2 * d1x + uu * d2y
    return ox, oy


@_part
def _higher_rates(h, hp, hc, rt, sl, pu, vel, big_u):
    """Rates (r₀, r₁) of higher pair h's residual rows (r₁ = 0 for one row; `_higher`'s `closure_rates`)
    from the link rates in slot sl of rt and its contact parameter's rate pu: a Jacobian column (the
    unknowns' unit rates), the velocity's or (vel >= 0: the velocities in slot vel, the parameter's big_u)
    the acceleration's right-hand side. (One function per kind, as `_higher_closure`.)"""
    hi = hp.ints
    if hi[h, ht.H_GEAR]:
        return _gear_rates(h, hp, rt, sl), 0.0
    if hi[h, ht.H_RACK]:
        return _rack_rates(h, hp, hc, rt, sl, vel), 0.0
    if not hi[h, ht.H_FLAT]:
        return _point_rates(h, hp, hc, rt, sl, pu, vel, big_u)
    return _face_rates(h, hp, hc, rt, sl, pu, vel, big_u)


@_part
def _gear_rates(h, hp, rt, sl):
    """The gear's row's rate (`Gear.closure_rates`: linear in the angles, no acceleration terms)."""
    hi, hr = hp.ints, hp.reals
    return (hr[h, ht.H_COEF] * rt[sl, 0, hi[h, ht.H_A]] + hr[h, ht.H_COEF + 1] * rt[sl, 0, hi[h, ht.H_B]]
            + hr[h, ht.H_COEF + 2] * rt[sl, 0, hi[h, ht.H_CARRIER]])


@_part
def _spins(h, hp, rt, sl, vel):
    """Pair h's links a, b and their angular rates in slot sl, with their angular velocities (slot vel;
    0 when vel < 0: not an acceleration pass)."""
    a, b = hp.ints[h, ht.H_A], hp.ints[h, ht.H_B]
    va, vb = (rt[vel, 0, a], rt[vel, 0, b]) if vel >= 0 else (0.0, 0.0)
    return a, b, rt[sl, 0, a], rt[sl, 0, b], va, vb


@_part
def _rack_rates(h, hp, hc, rt, sl, vel):
    """The rack's row's rate (`Rack.closure_rates`)."""
    a, b, wa, wb, va, vb = _spins(h, hp, rt, sl, vel)
    accel = vel >= 0
    rcx, rcy, rax, ray = hc[h, 0], hc[h, 1], hc[h, 2], hc[h, 3]
    dx, dy, ux, uy = hc[h, 4], hc[h, 5], hc[h, 6], hc[h, 7]
    tcx, tcy = _turning(wa, rcx, rcy, 0.0, 0.0, 0.0, 0.0, 0.0, va, 0.0, accel)
    tax, tay = _turning(wb, rax, ray, 0.0, 0.0, 0.0, 0.0, 0.0, vb, 0.0, accel)
    drx, dry = (rt[sl, 1, a] + tcx) - (rt[sl, 1, b] + tax), (rt[sl, 2, a] + tcy) - (rt[sl, 2, b] + tay)
    urx, ury = _turning(wb, ux, uy, 0.0, 0.0, 0.0, 0.0, 0.0, vb, 0.0, accel)
    out = (drx * ux + dry * uy) + (dx * urx + dy * ury)
    if accel:
        dvx = (rt[vel, 1, a] + va * -rcy) - (rt[vel, 1, b] + vb * -ray)
        dvy = (rt[vel, 2, a] + va * rcx) - (rt[vel, 2, b] + vb * rax)
        out = out + 2 * (dvx * (vb * -uy) + dvy * (vb * ux))
    return out + hp.reals[h, ht.H_SIGMA_R] * (wa - wb)


@_part
def _point_rates(h, hp, hc, rt, sl, pu, vel, big_u):
    """The rates of X_F(P) − X_C(c(u)), a the curve's link, b the point's (`PointOnCurve.closure_rates`)."""
    a, b, wa, wb, va, vb = _spins(h, hp, rt, sl, vel)
    accel = vel >= 0
    tfx, tfy = _turning(wb, hc[h, 8], hc[h, 9], 0.0, 0.0, 0.0, 0.0, 0.0, vb, 0.0, accel)
    tcx, tcy = _turning(wa, hc[h, 0], hc[h, 1], pu, hc[h, 2], hc[h, 3], hc[h, 4], hc[h, 5], va, big_u, accel)
    return (rt[sl, 1, b] + tfx) - (rt[sl, 1, a] + tcx), (rt[sl, 2, b] + tfy) - (rt[sl, 2, a] + tcy)


@_part
def _face_rates(h, hp, hc, rt, sl, pu, vel, big_u):
    """The rates of N·(X_C(c(u)) − X_F(A)) and N·T, a the curve's link, b the face's
    (`FaceOnCurve.closure_rates`)."""
    a, b, wa, wb, va, vb = _spins(h, hp, rt, sl, vel)
    accel = vel >= 0
    o0x, o0y, o1x, o1y = hc[h, 0], hc[h, 1], hc[h, 2], hc[h, 3]
    o2x, o2y, o3x, o3y = hc[h, 4], hc[h, 5], hc[h, 6], hc[h, 7]
    rfx, rfy, nx, ny, dx, dy = hc[h, 8], hc[h, 9], hc[h, 10], hc[h, 11], hc[h, 12], hc[h, 13]
    tcx, tcy = _turning(wa, o0x, o0y, pu, o1x, o1y, o2x, o2y, va, big_u, accel)
    tfx, tfy = _turning(wb, rfx, rfy, 0.0, 0.0, 0.0, 0.0, 0.0, vb, 0.0, accel)
    drx, dry = (rt[sl, 1, a] + tcx) - (rt[sl, 1, b] + tfx), (rt[sl, 2, a] + tcy) - (rt[sl, 2, b] + tfy)
    nrx, nry = _turning(wb, nx, ny, 0.0, 0.0, 0.0, 0.0, 0.0, vb, 0.0, accel)
    trx, try_ = _turning(wa, o1x, o1y, pu, o2x, o2y, o3x, o3y, va, big_u, accel)
    out0 = (nrx * dx + nry * dy) + (nx * drx + ny * dry)
    out1 = (nrx * o1x + nry * o1y) + (nx * trx + ny * try_)
    if accel:   # 2·Ṅ·ḋ and 2·Ṅ·Ṫ from the velocities
        vcx, vcy = _turning(va, o0x, o0y, big_u, o1x, o1y, 0.0, 0.0, 0.0, 0.0, False)
        vfx, vfy = _turning(vb, rfx, rfy, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, False)
        dvx, dvy = (rt[vel, 1, a] + vcx) - (rt[vel, 1, b] + vfx), (rt[vel, 2, a] + vcy) - (rt[vel, 2, b] + vfy)
        nvx, nvy = vb * -ny, vb * nx
        tvx, tvy = _turning(va, o1x, o1y, big_u, o2x, o2y, 0.0, 0.0, 0.0, 0.0, False)
        out0 = out0 + 2 * (nvx * dvx + nvy * dvy)
        out1 = out1 + 2 * (nvx * tvx + nvy * tvy)
    return out0, out1
