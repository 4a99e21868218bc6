"""Seed 001: a guiding crank-slider for a walking machine's foot, synthesised by interpolation.

The seed's 2-DOF chain is a crank AB (length `a`, fixed pivot A) and a rod BE (length `b`, foot point
E). A point C of the rod (|BC| = l, angle γ from BE to BC, clockwise) is guided by a slider on the line
y = k·x + d; the result is a 1-DOF crank-slider whose foot E should follow a D-shaped path: a straight
support segment and a required step height.

At every interpolation node E_i the chain's inverse kinematics (the seed's equation (5), a half-angle
quadratic) gives the crank angle φ1 and the rod angle φ2. With C = E − b·u(φ2) + l·u(φ2 − γ),
u(α) = (cos α, sin α), the condition "C on the line" is written here with the line's unit normal
n(θ) = (−sin θ, cos θ) (θ = atan k) and offset ρ = n·C = d·cos θ:

    −ρ + P2·sin(φ2 − θ) − P3·cos(φ2 − θ) + n(θ)·E − b·sin(φ2 − θ) = 0,   P2 = l cos γ, P3 = l sin γ,

which is the seed's equation (16) multiplied by −k·cos θ (so it also holds for k = 0 and vertical
lines). Its left side is exactly the signed distance of C_i from the line. The three forms:

* (b) θ fixed: linear in (ρ, P2, P3): exact at 3 nodes, least squares or minimax at more; θ scanned;
* (a) γ fixed: the 3×3 determinant in (ρ, l) vanishes: a quadratic in tan θ (the seed's (11)–(14));
* (c) four unknowns (ρ, θ, P2, P3) at 4 nodes: the 4×4 determinant is a cubic in tan θ (the seed's
  (17)–(23)).

Candidates are compared by the seed's objective Δ = Δ1 + Δ2 (15): Δ1 the largest deviation of the foot
from the support line over the support segment, Δ2 the deviation of the path's highest point from the
required height. `foot_paths` evaluates a batch of candidate designs over a batch of crank angles, (D, P),
so that any search can score designs in bulk.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError

__all__ = ["Chain", "SEED001_CHAIN", "WalkingTarget", "Candidates", "chebyshev_nodes", "chain_angles",
           "form_a", "form_b", "form_c", "guiding_poses", "foot_paths", "seed_objective", "node_configurations"]


@dataclass(frozen=True)
class Chain:
    """The seed's 2-DOF chain before a guide is added: a crank and a rod carrying the foot.

    Attributes
    ----------
    a : float
        Crank length AB, m.
    b : float
        Rod length from B to the foot E, m.
    pivot : tuple of float
        The crank's fixed pivot A, (x, y) in m.

    Examples
    --------
    >>> from mbplanar.synthesis import SEED001_CHAIN, Chain
    >>> SEED001_CHAIN.a, SEED001_CHAIN.b          # the seed's crank and rod, m
    (0.6234, 2.5628)
    >>> Chain(0.5, 2.0, (0.0, 0.0)).pivot
    (0.0, 0.0)
    """

    a: float
    b: float
    pivot: tuple[float, float]


SEED001_CHAIN = Chain(0.6234, 2.5628, (-1.00, -0.6668))
"""The chain of seed 001's example (from the first stage of its synthesis)."""


@dataclass(frozen=True)
class WalkingTarget:
    """A D-shaped foot path: a straight support segment and a step height above it.

    The support segment runs from (`x_start`, `y0`) over `length` along +x; the foot moves along it
    in the sense `direction`; the path's top point is `height` above the segment at `top_x`.

    Attributes
    ----------
    x_start, y0 : float
        Start of the support segment, m.
    length : float
        Length of the support segment, m (positive).
    height : float
        Step height: the top point's height above the segment, m (positive).
    direction : int
        +1: the foot moves along +x on the support segment, -1: along -x.
    top_x : float or None
        x of the top point, m; None: above the segment's middle (the seed's equation (3) for equal end
        radii).

    Examples
    --------
    >>> from mbplanar.synthesis import WalkingTarget
    >>> target = WalkingTarget(0.0, -2.6, length=1.0, height=0.2, direction=-1)
    >>> target.top.tolist()                        # the top point, m
    [0.5, -2.4]
    >>> target.nodes(2).round(4).tolist()          # 2 Chebyshev nodes in the foot's order, then the top
    [[0.8536, -2.6], [0.1464, -2.6], [0.5, -2.4]]
    """

    x_start: float
    y0: float
    length: float = 1.0
    height: float = 0.2
    direction: int = -1
    top_x: float | None = None

    @property
    def top(self) -> np.ndarray:
        x = self.x_start + 0.5 * self.length if self.top_x is None else self.top_x
        return np.array([x, self.y0 + self.height])

    def nodes(self, support: int, spacing: str = "chebyshev") -> np.ndarray:
        """(support + 1, 2) interpolation nodes: `support` on the segment in the foot's order, then the
        top point."""
        if support < 2:
            raise ModelError("the support segment needs at least 2 interpolation nodes")
        if spacing not in ("chebyshev", "uniform"):
            raise ModelError(f"node spacing must be 'chebyshev' or 'uniform', got {spacing!r}")
        lo, hi = self.x_start, self.x_start + self.length
        x = chebyshev_nodes(support, lo, hi) if spacing == "chebyshev" else np.linspace(lo, hi, support)
        x = x[::-1] if self.direction < 0 else x
        return np.vstack([np.column_stack([x, np.full(support, self.y0)]), self.top])


def chebyshev_nodes(n: int, lo: float, hi: float) -> np.ndarray:
    """Chebyshev nodes on an interval, ascending.

    x_j = (lo + hi)/2 − (hi − lo)/2·cos((2j − 1)π/(2n)), j = 1..n: the interpolation nodes that keep
    the largest error between them smallest.

    Parameters
    ----------
    n : int
        Number of nodes (n ≥ 1).
    lo, hi : float
        The interval's ends.

    Returns
    -------
    (n,) ndarray
        The nodes, from `lo` towards `hi`.

    Raises
    ------
    ValueError
        When `n` is negative (numpy's `arange`); n = 0 gives an empty array.

    Examples
    --------
    >>> from mbplanar.synthesis import chebyshev_nodes
    >>> chebyshev_nodes(3, 0.0, 1.0).round(6).tolist()
    [0.066987, 0.5, 0.933013]
    """
    j = np.arange(1, n + 1)
    return 0.5 * (lo + hi) - 0.5 * (hi - lo) * np.cos((2 * j - 1) * np.pi / (2 * n))


def chain_angles(chain: Chain, foot, elbow=1) -> tuple[np.ndarray, np.ndarray]:
    """Crank angle φ1 and rod angle φ2 (rad) that put the foot at `foot` (N, 2): the seed's (5).

    |E − A − a·u(φ1)| = b gives A'·cos φ1 + B'·sin φ1 + C' = 0 with A' = 2a(x_A − x_E),
    B' = 2a(y_A − y_E), C' = (x_A − x_E)² + (y_A − y_E)² + a² − b²; with t = tan(φ1/2) the quadratic
    (C' − A')t² + 2B't + (C' + A') = 0, whose two roots are the chain's two assembly modes; the one
    with sign(sin(φ2 − φ1)) = `elbow` (±1, the turn from AB to BE; one sign or one per node) is
    returned. The mode changes along a crank turn (twice, where AB and BE line up), so a design's nodes
    may need different modes.
    """
    foot = np.atleast_2d(np.asarray(foot, float))
    dx, dy = chain.pivot[0] - foot[:, 0], chain.pivot[1] - foot[:, 1]
    ca, cb = 2 * chain.a * dx, 2 * chain.a * dy
    cc = dx * dx + dy * dy + chain.a ** 2 - chain.b ** 2
    disc = cb * cb - cc * cc + ca * ca
    if np.any(disc < 0):
        bad = int(np.flatnonzero(disc < 0)[0])
        raise ModelError(f"node {bad + 1} at ({foot[bad, 0]:.6g}, {foot[bad, 1]:.6g}) is out of the chain's "
                         f"reach: |AE| must lie in [b − a, a + b] = [{abs(chain.b - chain.a):.6g}, "
                         f"{chain.a + chain.b:.6g}]")
    best = None
    for root in (1.0, -1.0):
        phi1 = 2 * np.arctan2(-cb + root * np.sqrt(disc), cc - ca)
        bx = foot[:, 0] - chain.pivot[0] - chain.a * np.cos(phi1)
        by = foot[:, 1] - chain.pivot[1] - chain.a * np.sin(phi1)
        phi2 = np.arctan2(by, bx)
        if best is None:
            best = (phi1, phi2)
        else:                       # keep, node by node, the root whose mode sign is `elbow`
            mine = np.sin(best[1] - best[0]) * np.asarray(elbow) >= 0
            best = (np.where(mine, best[0], phi1), np.where(mine, best[1], phi2))
    return best


@dataclass(frozen=True)
class Candidates:
    """A batch of D guiding designs for a `Chain`: where the slider's line lies and where the rod's guided
    point C sits.

    Attributes
    ----------
    theta : (D,) ndarray
        Direction θ of the slider's line, rad (slope k = tan θ).
    rho : (D,) ndarray
        Offset of the line, ρ = n(θ)·C with n(θ) = (−sin θ, cos θ), m.
    p2, p3 : (D,) ndarray
        The rod point C in the rod's frame, P2 = l cos γ and P3 = l sin γ, m (l = |BC|, γ the angle
        from BE to BC, clockwise); the properties `l`, `gamma`, `k` and `d` (the line's intercept) give
        them in the seed's terms.
    elbow : (D, n) ndarray of int
        The chain's assembly mode (+1 or -1) at each of the n nodes (see `guiding.chain_angles`).

    Examples
    --------
    Form (b) of the seed at one line direction, through the nodes of the documented target:

    >>> import numpy as np
    >>> from mbplanar.synthesis import SEED001_CHAIN, WalkingTarget
    >>> from mbplanar.synthesis.guiding import form_b
    >>> nodes = WalkingTarget(0.0, -2.6, 1.0, 0.2, -1).nodes(2)
    >>> c = form_b(SEED001_CHAIN, nodes, np.radians([172.0]), elbow=[-1, -1, 1])
    >>> len(c), round(float(c.l[0]), 4), round(float(np.degrees(c.gamma[0])), 4)
    (1, 2.5527, 11.1615)
    """

    theta: np.ndarray
    rho: np.ndarray
    p2: np.ndarray
    p3: np.ndarray
    elbow: np.ndarray

    @property
    def l(self) -> np.ndarray:
        return np.hypot(self.p2, self.p3)

    @property
    def gamma(self) -> np.ndarray:
        return np.arctan2(self.p3, self.p2)

    @property
    def k(self) -> np.ndarray:
        return np.tan(self.theta)

    @property
    def d(self) -> np.ndarray:
        """Intercept of y = k·x + d (inf for a vertical line)."""
        with np.errstate(divide="ignore"):
            return self.rho / np.cos(self.theta)

    def __len__(self) -> int:
        return len(self.theta)

    def take(self, index) -> "Candidates":
        return Candidates(*(np.atleast_1d(getattr(self, f)[index]) for f in
                            ("theta", "rho", "p2", "p3", "elbow")))

    @staticmethod
    def join(parts: list) -> "Candidates":
        return Candidates(*(np.concatenate([getattr(p, f) for p in parts]) for f in
                            ("theta", "rho", "p2", "p3", "elbow")))


def _rows(chain: Chain, nodes, phi2, theta):
    """Coefficient rows (T, n, 3) of (ρ, P2, P3) and the constant terms (T, n) of the node equations."""
    th = np.asarray(theta, float)[:, None]
    s, c = np.sin(phi2[None, :] - th), np.cos(phi2[None, :] - th)
    m = np.stack([-np.ones_like(s), s, -c], axis=-1)
    const = -np.sin(th) * nodes[None, :, 0] + np.cos(th) * nodes[None, :, 1] - chain.b * s
    return m, const


def form_b(chain: Chain, nodes, theta, elbow: int = 1, fit: str = "exact") -> Candidates:
    """Form (b): at each line direction θ (T,) solve the node equations for (ρ, P2, P3).

    `fit`: "exact" needs 3 nodes; "lsq" minimises the sum of squared distances of the C_i from the
    line; "minimax" their largest absolute value (a linear programme per θ). Returns T candidates
    (NaN where the system is singular).
    """
    nodes = np.asarray(nodes, float)
    _, phi2 = chain_angles(chain, nodes, elbow)
    theta = np.atleast_1d(np.asarray(theta, float))
    m, const = _rows(chain, nodes, phi2, theta)
    n = len(nodes)
    if fit == "exact":
        if n != 3:
            raise ModelError(f"form (b) interpolates exactly at 3 nodes, got {n} (use fit 'lsq' or 'minimax')")
        x = _solve_or_nan(m, -const)
    elif fit == "lsq":
        if n < 3:
            raise ModelError(f"least squares needs at least 3 nodes, got {n}")
        x = np.einsum("tij,tj->ti", np.linalg.pinv(m), -const)
    elif fit == "minimax":
        x = _minimax(m, -const)
    else:
        raise ModelError(f"fit must be 'exact', 'lsq' or 'minimax', got {fit!r}")
    return Candidates(theta, x[:, 0], x[:, 1], x[:, 2], _modes(elbow, len(theta), n))


def _solve_or_nan(m, rhs):
    det = np.linalg.det(m)
    scale = np.prod(np.linalg.norm(m, axis=-1), axis=-1)
    good = np.abs(det) > 1e-12 * scale
    x = np.full(rhs.shape, np.nan)
    if good.any():
        x[good] = np.linalg.solve(m[good], rhs[good][..., None])[..., 0]
    return x


def _minimax(m, rhs):
    """min over x of max_i |m_i·x − rhs_i| per batch row, as a linear programme in (x, t)."""
    from scipy.optimize import linprog
    t_count, n, k = m.shape
    out = np.full((t_count, k), np.nan)
    cost = np.r_[np.zeros(k), 1.0]
    for i in range(t_count):
        a_ub = np.block([[m[i], -np.ones((n, 1))], [-m[i], -np.ones((n, 1))]])
        b_ub = np.r_[rhs[i], -rhs[i]]
        res = linprog(cost, A_ub=a_ub, b_ub=b_ub, bounds=[(None, None)] * (k + 1), method="highs")
        if res.status == 0:
            out[i] = res.x[:k]
    return out


def _angles_of_form(coef: np.ndarray) -> list:
    """Directions θ in [0, π) where the homogeneous form Σ_j coef[j]·cos^(deg−j) θ·sin^j θ vanishes."""
    coef = np.asarray(coef, float)
    big = np.max(np.abs(coef))
    if not np.isfinite(big) or big == 0:
        return []
    out = []
    if abs(coef[-1]) >= abs(coef[0]):          # polynomial in t = tan θ, no root at θ = 90° is lost
        for t in np.roots(coef[::-1]):
            if abs(t.imag) <= 1e-9 * (1 + abs(t)):
                out.append(math.atan(t.real) % math.pi)
    else:                                       # in v = cot θ
        for v in np.roots(coef):
            if abs(v.imag) <= 1e-9 * (1 + abs(v)):
                out.append(math.atan2(1.0, v.real) % math.pi)
    return sorted(out)


def _null_solution(m, const):
    """(ρ, P2, P3) of an exactly consistent set of node equations (least squares in the rank-3 case)."""
    x, *_ = np.linalg.lstsq(m, -const, rcond=None)
    return x


def form_a(chain: Chain, nodes, gamma, elbow=1) -> Candidates:
    """Form (a): at each fixed γ (G,), the lines through the 3 nodes' C points for some l.

    Unknowns ρ, θ, l: the rows [−1, sin(φ2 − γ − θ), n(θ)·E − b·sin(φ2 − θ)] have a vanishing
    determinant, a quadratic form α·cos²θ + β·cos θ sin θ + δ·sin²θ = 0, i.e.
    (α + δ)/2 + R·cos(2θ − ψ) = 0 with R·(cos ψ, sin ψ) = ((α − δ)/2, β/2): up to two candidates per γ,
    all γ at once.
    """
    nodes = np.asarray(nodes, float)
    if len(nodes) != 3:
        raise ModelError(f"form (a) interpolates at exactly 3 nodes, got {len(nodes)}")
    _, phi2 = chain_angles(chain, nodes, elbow)
    g = np.atleast_1d(np.asarray(gamma, float))[:, None]                       # (G, 1)
    const_c, const_s = nodes[:, 1] - chain.b * np.sin(phi2), chain.b * np.cos(phi2) - nodes[:, 0]

    def det(c, s):
        col2 = np.sin(phi2 - g) * c - np.cos(phi2 - g) * s
        col3 = np.broadcast_to(c * const_c + s * const_s, col2.shape)
        return np.linalg.det(np.stack([-np.ones_like(col2), col2, col3], axis=-1))
    alpha, delta = det(1.0, 0.0), det(0.0, 1.0)
    beta = det(1.0, 1.0) - alpha - delta
    amp = np.hypot(0.5 * (alpha - delta), 0.5 * beta)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = -0.5 * (alpha + delta) / amp
    psi = np.arctan2(0.5 * beta, 0.5 * (alpha - delta))
    real = np.abs(ratio) <= 1.0
    spread = np.arccos(np.clip(ratio, -1.0, 1.0))
    theta = np.mod(0.5 * np.stack([psi + spread, psi - spread], axis=1), np.pi)     # (G, 2)
    keep = np.stack([real, real & (spread > 0)], axis=1)
    gi = np.broadcast_to(np.arange(len(g))[:, None], keep.shape)[keep]
    th, gg = theta[keep], g[gi, 0]
    m, const = _rows(chain, nodes, phi2, th)                                   # (K, 3, 3), (K, 3)
    along = m[..., 1] * np.cos(gg)[:, None] + m[..., 2] * np.sin(gg)[:, None]  # l's column: P2, P3 ∥ γ
    mm = np.stack([m[..., 0], along], axis=-1)                                 # (K, 3, 2)
    rho_l = np.einsum("kij,kj->ki", np.linalg.pinv(mm), -const)
    return Candidates(th, rho_l[:, 0], rho_l[:, 1] * np.cos(gg), rho_l[:, 1] * np.sin(gg),
                      _modes(elbow, len(th), 3))


def form_c(chain: Chain, nodes, elbow: int = 1) -> Candidates:
    """Form (c): all four unknowns (ρ, θ, P2, P3) from 4 nodes: the 4×4 determinant of the node
    equations is a cubic form in (cos θ, sin θ) (the seed's cubic (23)); up to three candidates."""
    nodes = np.asarray(nodes, float)
    if len(nodes) != 4:
        raise ModelError(f"form (c) interpolates at exactly 4 nodes, got {len(nodes)}")
    _, phi2 = chain_angles(chain, nodes, elbow)

    def det(c, s):
        col2 = np.sin(phi2) * c - np.cos(phi2) * s            # sin(φ2 − θ)·(scale)
        col3 = -(np.cos(phi2) * c + np.sin(phi2) * s)         # −cos(φ2 − θ)
        col4 = c * (nodes[:, 1] - chain.b * np.sin(phi2)) + s * (chain.b * np.cos(phi2) - nodes[:, 0])
        return np.linalg.det(np.column_stack([-np.ones(4), col2, col3, col4]))
    a0, a3 = det(1.0, 0.0), det(0.0, 1.0)
    plus, minus = det(1.0, 1.0) - a0 - a3, det(1.0, -1.0) - a0 + a3   # a1 + a2, a2 − a1
    a1, a2 = 0.5 * (plus - minus), 0.5 * (plus + minus)
    out = []
    for th in _angles_of_form([a0, a1, a2, a3]):
        m, const = _rows(chain, nodes, phi2, [th])
        out.append((th, *_null_solution(m[0], const[0])))
    arr = np.array(out, float).reshape(-1, 4)
    return Candidates(arr[:, 0], arr[:, 1], arr[:, 2], arr[:, 3], _modes(elbow, len(arr), 4))


def _modes(elbow, count: int, n: int) -> np.ndarray:
    return np.broadcast_to(np.asarray(elbow, int), (count, n)).copy()


def node_configurations(chain: Chain, cand: Candidates, nodes) -> dict:
    """The chain's configuration at every node for every candidate: crank angle φ1 (D, n), points B, C
    (C projected onto the line for a least-squares design) and E (D, n, 2), and the slider's assembly
    sign σ (D, n): which side of B's foot on the line C lies, along u(θ)."""
    nodes = np.asarray(nodes, float)
    d_count, n = len(cand), len(nodes)
    phi1, phi2 = np.empty((d_count, n)), np.empty((d_count, n))
    for modes in np.unique(cand.elbow, axis=0):
        pick = np.all(cand.elbow == modes, axis=1)
        phi1[pick], phi2[pick] = chain_angles(chain, nodes, modes)
    u2 = np.stack([np.cos(phi2), np.sin(phi2)], -1)
    w2 = np.stack([np.sin(phi2), -np.cos(phi2)], -1)
    b = np.asarray(chain.pivot) + chain.a * np.stack([np.cos(phi1), np.sin(phi1)], -1)
    c = nodes[None] - chain.b * u2 + cand.p2[:, None, None] * u2 + cand.p3[:, None, None] * w2
    nrm = np.stack([-np.sin(cand.theta), np.cos(cand.theta)], -1)[:, None, :]
    along = np.stack([np.cos(cand.theta), np.sin(cand.theta)], -1)[:, None, :]
    c = c - ((c * nrm).sum(-1) - cand.rho[:, None])[..., None] * nrm
    sigma = np.sign(((c - b) * along).sum(-1))
    return {"phi1": phi1, "B": b, "C": c, "E": np.broadcast_to(nodes, c.shape).copy(), "sigma": sigma}


def guiding_poses(chain: Chain, cand: Candidates, sigma, phi1):
    """Crank joint B, slider point C and foot E, each (D, P, 2), of D candidate designs at P crank
    angles φ1 (rad), the slider assembled on the side `sigma` (D,) or (D, P) of B's foot on the line
    (along u(θ)); `ok` (D, P) is False where the slider dyad cannot be assembled."""
    phi1 = np.atleast_2d(np.asarray(phi1, float))
    bx = chain.pivot[0] + chain.a * np.cos(phi1)
    by = chain.pivot[1] + chain.a * np.sin(phi1)
    th = cand.theta[:, None]
    st, ct = np.sin(th), np.cos(th)
    h = -st * bx + ct * by - cand.rho[:, None]            # signed distance of B from the line
    l2 = (cand.p2 ** 2 + cand.p3 ** 2)[:, None]
    disc = l2 - h * h
    ok = disc >= 0
    sigma = np.asarray(sigma, float)
    root = (sigma[:, None] if sigma.ndim == 1 else sigma) * np.sqrt(np.where(ok, disc, 0.0))
    cx = bx + h * st + root * ct
    cy = by - h * ct + root * st
    psi = np.arctan2(cy - by, cx - bx) + cand.gamma[:, None]    # rod direction φ2 = ψ(BC) + γ
    b = np.stack(np.broadcast_arrays(bx, by), axis=-1)
    e = np.stack([bx + chain.b * np.cos(psi), by + chain.b * np.sin(psi)], axis=-1)
    return b, np.stack([cx, cy], axis=-1), e, ok


def foot_paths(chain: Chain, cand: Candidates, sigma, phi1) -> tuple[np.ndarray, np.ndarray]:
    """The foot E of a batch of guiding designs at a batch of crank angles, in closed form.

    Parameters
    ----------
    chain : Chain
        The crank and rod the designs share.
    cand : Candidates
        D designs.
    sigma : (D,) or (D, P) array_like
        The slider dyad's assembly sign (+1 or -1): on which side of B's foot on the line C lies, along
        the line's direction.
    phi1 : (P,) or (D, P) array_like
        Crank angles, rad.

    Returns
    -------
    e : (D, P, 2) ndarray
        The foot's positions, m (meaningless where `ok` is False).
    ok : (D, P) ndarray of bool
        False where the slider dyad cannot be assembled.

    Raises
    ------
    ValueError
        When the shapes of `cand`, `sigma` and `phi1` do not broadcast (numpy's error).

    Examples
    --------
    The design of form (b) at θ = 172°, at its nodes' crank angles, puts the foot on the nodes:

    >>> import numpy as np
    >>> from mbplanar.synthesis import SEED001_CHAIN, WalkingTarget, foot_paths
    >>> from mbplanar.synthesis.guiding import form_b, node_configurations
    >>> nodes = WalkingTarget(0.0, -2.6, 1.0, 0.2, -1).nodes(2)
    >>> c = form_b(SEED001_CHAIN, nodes, np.radians([172.0]), elbow=[-1, -1, 1])
    >>> conf = node_configurations(SEED001_CHAIN, c, nodes)
    >>> e, ok = foot_paths(SEED001_CHAIN, c, conf["sigma"], conf["phi1"])
    >>> e.shape, bool(ok.all()), bool(np.abs(e[0] - nodes).max() < 1e-12)
    ((1, 3, 2), True, True)
    """
    _, _, e, ok = guiding_poses(chain, cand, sigma, phi1)
    return e, ok


def seed_objective(target: WalkingTarget, path: np.ndarray, ok=None) -> tuple[np.ndarray, np.ndarray]:
    """The seed's deviations (15) of closed foot paths (D, P, 2) sampled over a full crank turn.

    Δ1: the largest |y − y0| over the support part of the path: its points with x in
    [x_start, x_start + length] below the middle height y0 + height/2. Δ2: |max y − (y0 + height)|.
    Both are inf for a path that does not turn fully (`ok` False somewhere) or whose support part does
    not span the segment to within one sample spacing.
    """
    x, y = path[..., 0], path[..., 1]
    lo, hi = target.x_start, target.x_start + target.length
    support = (x >= lo) & (x <= hi) & (y < target.y0 + 0.5 * target.height)
    dev = np.where(support, np.abs(y - target.y0), -np.inf).max(axis=-1)
    step = np.max(np.hypot(np.diff(x, axis=-1), np.diff(y, axis=-1)), axis=-1)
    xs_min = np.where(support, x, np.inf).min(axis=-1)
    xs_max = np.where(support, x, -np.inf).max(axis=-1)
    spans = (xs_min <= lo + step) & (xs_max >= hi - step)
    d2 = np.abs(y.max(axis=-1) - target.top[1])
    bad = ~spans if ok is None else (~spans | ~np.all(ok, axis=-1))
    return np.where(bad, np.inf, dev), np.where(bad, np.inf, d2)
