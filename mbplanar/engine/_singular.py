"""Singular positions: motion limits (folds, located with their configuration by Newton on a bordered
system, `_locate_fold`), change points (located by regula falsi on a block's determinant), and how the
links line up there (`_limit_kind`). Everything works on a `BlockSolver` and the branch's nodes."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._blocks import BlockPlan, BlockSolver, Solution, factor_scaled
from ._constraints import Pose
from ._nodes import Node, hermite_between
from ._tolerances import Tolerances

__all__ = ["Limit", "Crossing", "limit_after", "locate_crossing", "limit_kind"]


@dataclass(frozen=True, eq=False)
class Limit:
    """Where the motion ends along the input: φ (SI), the block at fault, and what happens there.

    At a fold (dead point: the block's Jacobian is singular and the branch turns back) φ is solved for
    together with the configuration there, `q` (every block's unknowns (m,), as in `Solution.blocks`),
    to the rounding floor (see `_locate_fold`). Where that does not converge `q` is None and φ is the
    middle of the bracket the walk left, good to `H_MIN` in the input.

    Examples
    --------
    >>> import numpy as np
    >>> import mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/crank_slider_rocker_locking.toml"))
    >>> limit = mbplanar.analyse(engine, np.radians(np.arange(0.0, 360.0, 10.0))).limits[0]
    >>> round(float(limit.phi[0]), 6), limit.direction, limit.joints, limit.kind
    (1.799912, 1, ('C', 'B', 'D'), 'stretched at B (C, B, D in line)')
    """

    phi: np.ndarray  # (n_in,) input values (SI)
    direction: int
    links: tuple
    joints: tuple
    kind: str
    q: list | None = None


@dataclass(frozen=True, eq=False)
class Crossing:
    """A change point on the branch: a block's Jacobian is singular there, but the branch goes on
    smoothly through it (another assembly branch crosses it, e.g. the parallelogram four-bar with all
    links in line). φ (SI) is located by the sign change of the block's determinant; `bracket` holds the
    atlas nodes on either side, whose interpolant gives the rates at and near the change point.

    `links` are the block's links, `joints` the joints that line up there, `kind` the words for it.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.engine import Engine
    >>> from mbplanar.model import read_model_text
    >>> parallelogram = read_model_text('''
    ... ground = "0"
    ... links = [{ name = "1" }, { name = "2" }, { name = "3" }]
    ... joints = [{ name = "O", type = "R", links = ["0", "1"], at = [0.0, 0.0] },
    ...           { name = "A", type = "R", links = ["1", "2"], at = [0.0, 1.0] },
    ...           { name = "B", type = "R", links = ["2", "3"], at = [2.0, 1.0] },
    ...           { name = "C", type = "R", links = ["3", "0"], at = [2.0, 0.0] }]
    ... input = { joint = "O" }
    ... ''')
    >>> atlas = Engine(parallelogram).atlas()
    >>> atlas.cover(1.0, 4.0)                                  # every link in line at φ = π
    >>> [(round(float(c.phi[0]), 9), c.joints, c.kind) for c in atlas.crossings]
    [(3.141592654, ('A', 'B', 'C'), 'stretched at B (A, B, C in line)')]
    """

    phi: np.ndarray  # (n_in,)
    links: tuple
    joints: tuple
    bracket: tuple = (None, None)
    kind: str = ""



def _det_at(solver: BlockSolver, k: int, phi: np.ndarray, guesses) -> float:
    """Block k's Jacobian determinant at the positions `guesses` (no Newton step)."""
    pose = Pose(1)
    pose.set_ground(solver.mech.ground)
    q_in = solver.input_vars(phi[None, :])
    for bp, q in zip(solver.blocks[:k + 1], guesses):
        caches, cut_caches, _ = solver.block_pose(bp, pose, q, q_in)
    jac, _ = solver.block_jacobian(solver.blocks[k], caches, cut_caches, 1)
    return float(factor_scaled(solver.blocks[k], jac).det[0])


def locate_crossing(solver: BlockSolver, k: int, a: Node, b: Node, iterations: int = 6) -> np.ndarray:
    """φ of the change point between nodes a and b: regula falsi on block k's determinant, evaluated
    on the branch's interpolant (Newton cannot settle positions this close to a singular Jacobian)."""
    (pa, da), (pb, db) = (a.phi, a.dets[k]), (b.phi, b.dets[k])
    for _ in range(iterations):
        p = pa + (pb - pa) * (da / (da - db))
        d = _det_at(solver, k, p, hermite_between(a, b, p))
        if d == 0 or not np.isfinite(d):
            break
        if np.sign(d) == np.sign(da):
            pa, da = p, d
        else:
            pb, db = p, d
    return p


def limit_after(solver: BlockSolver, node: Node, direction: np.ndarray, h: float) -> Limit:
    """The motion limit just past a node, where the walk could not step on.

    It lies in the block whose Jacobian is nearest to singular there (or where a contact reaches the
    end of its open curve).

    Parameters
    ----------
    solver : BlockSolver
        The engine's solver.
    node : Node
        The walk's last node.
    direction : numpy.ndarray
        dφ/ds of the walk (n_in,): +1 or −1 for one input.
    h : float
        The step that failed.

    Returns
    -------
    Limit
        The fold, located exactly with its configuration (`Limit.q`) when `_locate_fold` finds it at the
        end of the node's branch; else the middle of the walk's bracket, node + direction·h/2 (q None).

    Raises
    ------
    Nothing on a node of the solver's branch.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.engine import Engine, limit_after
    >>> from mbplanar.model import read_model
    >>> engine = Engine(read_model("models/crank_slider_rocker_locking.toml"))
    >>> atlas = engine.atlas()
    >>> atlas.cover(0.0, 2.5)
    >>> limit = limit_after(engine.solver, atlas.nodes[-1], np.array([1.0]), 1e-10)
    >>> round(float(limit.phi[0]), 6), limit.joints, limit.q is not None
    (1.799912, ('C', 'B', 'D'), True)
    """
    sign = int(np.sign(direction[0])) if len(direction) == 1 else 0
    end = _curve_end(solver, node, direction, h)
    if end is not None:
        return end
    sol = solver.solve_batch(node.phi[None, :], [q[:, None] for q in node.q])
    ratios = [float(st.lu.pivot_ratio[0]) if st.lu is not None else math.inf for st in sol.blocks]
    k = int(np.argmin(ratios))
    bp = solver.blocks[k]
    joints = bp.joints
    fold = _locate_fold(solver, k, node, direction) if bp.m else None
    if fold is None:
        return Limit(node.phi + direction * h / 2, sign, bp.links, joints, limit_kind(solver, bp, sol))
    phi, at = fold
    return Limit(phi, sign, bp.links, joints, limit_kind(solver, bp, at), [st.q[:, 0] for st in at.blocks])




def _curve_end(solver: BlockSolver, node: Node, direction: np.ndarray, h: float) -> Limit | None:
    """The motion limit where a contact reaches an end of its open curve (a pin at the end of its slot)
    just past `node`, or None: the input value where its parameter u equals the end, by the secant on
    u(φ) from the node's Taylor step (each solve predicted from the node, the end's side accepted)."""
    sign = int(np.sign(direction[0])) if len(direction) == 1 else 0
    for k, bp in enumerate(solver.blocks):
        for law, idx in bp.params:
            lo, hi = law.param_range
            u, du = float(node.q[k][idx]), float(node.qd[k][idx])
            if not math.isfinite(lo) or du == 0:
                continue
            target = hi if du > 0 else lo
            s = (target - u) / du
            if not 0 <= s <= 4 * h:     # (the walk stopped a few steps short of where u meets the end)
                continue
            s_prev, f_prev = 0.0, u - target
            for _ in range(8):
                guesses = [(q + qd * s + 0.5 * qdd * s * s)[:, None] for q, qd, qdd in zip(node.q, node.qd, node.qdd)]
                got = solver.solve_batch((node.phi + direction * s)[None, :], guesses)
                f = float(got.blocks[k].q[idx, 0]) - target
                if f == f_prev or not math.isfinite(f):
                    break
                s, s_prev, f_prev = s - f * (s - s_prev) / (f - f_prev), s, f
                if abs(s - s_prev) <= 1e-15 * (1.0 + abs(s)):
                    break
            what = "the pin" if law.pair.kind == "slot" else "the contact"
            kind = (f"{what} of '{law.name}' at the end of its {'slot' if law.pair.kind == 'slot' else 'profile'}")
            return Limit(node.phi + direction * s, sign, bp.links, bp.joints, kind)
    return None


def _locate_fold(solver: BlockSolver, k: int, node: Node, direction: np.ndarray):
    """The fold of block k a distance s ahead of `node` along `direction` (the walk stopped a few `H_MIN`
    short of it): Newton from the node on the augmented system F(x) = [block k's scaled closure
    residuals; g] = 0 in x = (scaled q_k, s), g the bordered singularity function (`_bordered`). At a
    simple fold this system is regular (J loses rank one and ∂F/∂s is not in its range: the branch
    turns back), so Newton converges quadratically to the rounding floor, where bisection only gets to
    `H_MIN` in s and the driven unknowns, which move like √(distance) there, to ~1e-5. At a change
    point (rank lost by [J, ∂F/∂s] too) it is singular and `_on_the_branch` rejects what it finds.
    Returns (φ, Solution at φ), or None when it does not converge to the end of the node's branch."""
    bp = solver.blocks[k]
    x = np.append(node.q[k] * bp.var_scale, 0.0)
    border = _border(solver, k, node)
    for _ in range(solver.tol.fold_iterations):
        res, jac = _fold_system(solver, k, node, direction, x, border)
        if res is None:
            return None
        with np.errstate(all="ignore"):
            step = np.linalg.lstsq(jac, -res, rcond=None)[0]
        if not np.all(np.isfinite(step)):
            return None
        x = x + step
        if np.max(np.abs(step)) <= solver.tol.fold_step:
            break
    else:
        return None
    s = float(x[-1])
    if not _on_the_branch(x[:-1] - node.q[k] * bp.var_scale, s, node.qd[k] * bp.var_scale, solver.tol):
        return None
    phi = node.phi + direction * s
    guesses = [q[:, None] for q in node.q]
    guesses[k] = (x[:-1] / bp.var_scale)[:, None]
    sol = solver.solve_batch(phi[None, :], guesses)  # the blocks after k, regular there
    # block k converged already: Newton must leave it at the fold (`Engine.solve_limits` relies on it)
    if not sol.valid[0] or not np.array_equal(sol.blocks[k].q, guesses[k]):
        return None
    return phi, sol


def _on_the_branch(dq: np.ndarray, s: float, qd: np.ndarray, tol: Tolerances) -> bool:
    """Whether a fold found at distance s ≥ 0 ahead of a node, with the unknowns moved by dq, is the end
    of the node's own branch: near a fold the unknowns move like √(s_fold − s), so from the node to the
    fold they move by 2·s·q'(node) up to a relative O(√s) (another branch's fold, or one behind the
    node, fails this). The walk's bracket is not the test: the walk can fail to converge a step short
    of the fold, which then lies up to a few `H_MIN` past the bracket."""
    if not (0.0 <= s <= tol.h_cross) or np.max(np.abs(dq)) > tol.max_correction:
        return False
    return bool(np.max(np.abs(dq - 2 * s * qd)) <= tol.fold_sqrt_law * np.max(np.abs(dq)))


def _border(solver: BlockSolver, k: int, node: Node):
    """Left and right singular vectors (b, c) of block k's scaled Jacobian at `node` for its smallest
    singular value: they border the Jacobian into a matrix that stays regular through the fold."""
    sol = solver.solve_batch(node.phi[None, :], [q[:, None] for q in node.q])
    bp = solver.blocks[k]
    st = sol.blocks[k]
    jac, _ = solver.block_jacobian(bp, st.caches, st.cut_caches, 1)
    u, _, vt = np.linalg.svd(jac[:, :, 0] * bp.row_scale[:, None] / bp.var_scale[None, :])
    return u[:, -1], vt[-1]


def _bordered(jac: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Singularity function g (B,) of a batch of Jacobians (m, m, B): the last component of the
    solution of [[J, b], [cᵀ, 0]]·(v, g) = (0, 1). g = 0 exactly where J is singular (v is then its
    null vector), and near a simple singularity g is a smooth function ≈ ∓σ_min, unlike the
    determinant (which scales with the other pivots) or the smallest pivot (not smooth)."""
    m, batch = jac.shape[0], jac.shape[2]
    big = np.zeros((batch, m + 1, m + 1))
    big[:, :m, :m] = jac.transpose(2, 0, 1)
    big[:, :m, m] = b
    big[:, m, :m] = c
    rhs = np.zeros((batch, m + 1, 1))
    rhs[:, m] = 1.0
    return np.linalg.solve(big, rhs)[:, m, 0]


def _fold_system(solver: BlockSolver, k: int, node: Node, direction: np.ndarray, x: np.ndarray, border):
    """Augmented residual (m + 1,) at x = (scaled q_k, s) and its Jacobian (m + 1, m + 1) by central
    differences, all evaluated in one batch; (None, None) if a block before k does not converge."""
    n = len(x)
    trial = np.repeat(x[:, None], 2 * n + 1, axis=1)
    idx = np.arange(n)
    trial[idx, 1 + 2 * idx] += solver.tol.fold_delta
    trial[idx, 2 + 2 * idx] -= solver.tol.fold_delta
    res = _fold_residual(solver, k, node, direction, trial, border)
    if res is None:
        return None, None
    return res[:, 0], (res[:, 1::2] - res[:, 2::2]) / (2 * solver.tol.fold_delta)


def _fold_residual(solver: BlockSolver, k: int, node: Node, direction: np.ndarray, x: np.ndarray, border):
    """Augmented residual (m + 1, B) at trial points x = (scaled q_k, s) (m + 1, B): block k's scaled
    closure residuals and `_bordered`'s g. The blocks before k, regular here, are solved at
    φ = node.φ + s·direction by Newton from the node; None if one does not converge."""
    bp = solver.blocks[k]
    batch = x.shape[1]
    phi = node.phi[None, :] + x[-1][:, None] * direction[None, :]
    pose = Pose(batch)
    pose.set_ground(solver.mech.ground)
    q_in = solver.input_vars(phi)
    for before, q in zip(solver.blocks[:k], node.q[:k]):
        if not solver.newton(before, pose, np.repeat(q[:, None], batch, axis=1), q_in).ok.all():
            return None
    caches, cut_caches, res = solver.block_pose(bp, pose, x[:-1] / bp.var_scale[:, None], q_in)
    jac, _ = solver.block_jacobian(bp, caches, cut_caches, batch)
    jac = jac * bp.row_scale[:, None, None] / bp.var_scale[None, :, None]
    return np.vstack([res * bp.row_scale[:, None], _bordered(jac, *border)[None]])


def limit_kind(solver: BlockSolver, bp: BlockPlan, sol: Solution) -> str:
    """'stretched' or 'folded' at the revolute joint where two links of the block line up."""
    best = None
    revolute = [j for j in solver.mech.joints.values() if j.kind == "R"]
    for j in revolute:
        a, b = j.links
        if a not in bp.links and b not in bp.links:
            continue
        for ja in (o for o in revolute if a in o.links and o.name != j.name):
            for jb in (o for o in revolute if b in o.links and o.name != j.name):
                pa = _turned(sol.pose, a, ja.at, j.at)
                pb = _turned(sol.pose, b, jb.at, j.at)
                norm = np.linalg.norm(pa) * np.linalg.norm(pb)
                if norm == 0:
                    continue
                cross = abs(pa[0] * pb[1] - pa[1] * pb[0]) / norm
                if best is None or cross < best[0]:
                    shape = "folded" if np.dot(pa, pb) > 0 else "stretched"
                    best = (cross, f"{shape} at {j.name} ({ja.name}, {j.name}, {jb.name} in line)")
    return best[1] if best is not None and best[0] < 1e-3 else "singular position (dead point)"


def _turned(pose: Pose, link: str, p, q) -> np.ndarray:
    """The vector from q to p (drawn points of `link`) in the solved pose: the drawn vector turned
    with the link (a relative vector, whatever the world coordinates)."""
    return pose.rot(link, np.array(p, float) - np.array(q, float))[:, 0]


