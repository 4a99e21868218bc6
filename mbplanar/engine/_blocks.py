"""Block Newton–Raphson and rates: the solving blocks of an engine (`BlockPlan`), each block's closure
residuals and Jacobian from the joint laws, Newton on a batch, and the velocity and acceleration passes
from the factorised Jacobians.

Inside, arrays carry the batch last (unknowns q (m, B), Jacobians (m, m, B), see `_constraints`), so
that every elementwise operation runs over a contiguous batch; `Solution` exposes the usual batch-first
views. `BlockSolver` is what the continuation (`_atlas`) and the singular positions (`_singular`) work
with; `Engine` is the façade over all three.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ._constraints import Pose, Rates
from ._linalg import factor
from ._tolerances import Tolerances

__all__ = ["Step", "BlockPlan", "BlockState", "Solution", "BlockSolver", "ScaledLU", "factor_scaled"]


@dataclass
class Step:
    """A tree joint in a block: `var` indexes the block's unknowns, `input` the inputs."""

    law: object
    parent: str
    child: str
    relative: bool
    var: int | None
    input: int | None
    sign: float = 1.0


@dataclass
class BlockPlan:
    """A block's solving plan: tree `steps`, the `cuts` (lower pairs, then higher pairs) whose closures are
    its rows, `m` unknowns (the tree variables, then the higher pairs' contact parameters, `params`:
    (law, index of its unknown)); `q0` (m,) the unknowns in the drawn pose, `var_period` (m,) the period
    of each (2π for a relative angle, a closed curve's period for a contact parameter; 0 none)."""

    links: tuple
    steps: list
    cuts: list
    m: int
    row_scale: np.ndarray  # multiplies residual rows so that lengths are relative to the size
    var_scale: np.ndarray  # likewise for the unknowns (angles 1, displacements 1/size)
    group: object = None
    params: list = field(default_factory=list)
    q0: np.ndarray | None = None
    var_period: np.ndarray | None = None

    @property
    def joints(self) -> tuple:
        """Names of the block's joints: tree joints, then cuts."""
        return tuple(st.law.name for st in self.steps) + tuple(law.name for law in self.cuts)


class ScaledLU:
    """The factors of a block's Jacobian J (m, m, B) made dimensionless, J_s = R·J·V⁻¹ (R the rows'
    scale, V the unknowns', see `BlockPlan`): the pivot ratio and the determinant's sign do not depend
    on the mechanism's size or units, and J·x = b is solved as x = V⁻¹·J_s⁻¹·R·b. `det` is J_s's."""

    def __init__(self, lu, row_scale: np.ndarray, var_scale: np.ndarray):
        self.lu, self.row_scale, self.var_scale = lu, row_scale[:, None], var_scale[:, None]

    @property
    def det(self) -> np.ndarray:
        return self.lu.det

    @property
    def pivot_ratio(self) -> np.ndarray:
        return self.lu.pivot_ratio

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self.lu.solve(b * self.row_scale) / self.var_scale


def factor_scaled(bp: BlockPlan, jac: np.ndarray) -> ScaledLU:
    """`ScaledLU` of a block's Jacobian (m, m, B)."""
    return ScaledLU(factor(jac * bp.row_scale[:, None, None] / bp.var_scale[None, :, None]),
                    bp.row_scale, bp.var_scale)


@dataclass
class BlockState:
    """A solved block: unknowns q (m, B), their factorised Jacobian, the joint caches for the rate passes,
    the sensitivities of the links' rates to the unknowns, and (after `rates`) qd, qdd (m, B)."""

    q: np.ndarray
    lu: object
    caches: list
    cut_caches: list
    sens: Rates
    ok: np.ndarray
    qd: np.ndarray | None = None
    qdd: np.ndarray | None = None


@dataclass
class Solution:
    """Solved positions of a batch, and (after `Engine.rates`) velocities and accelerations.

    phi (B, n_in) in SI; per link (engine.links order): w, e (B, L) angular velocity and acceleration;
    v, a (B, L, 2) frame-origin velocity and acceleration (views of batch-last arrays). `pose` holds the
    placed links (batch last). `valid` (B,) marks the positions solved on the drawn branch.
    `blocks` holds each block's state (its unknowns ``q`` (m, B) and factored Jacobian), `limits` and
    `crossings` the motion limits and change points met, `given_rates` the rates the atlas' interpolant
    gives near change points. The engine layer's working record: users read `Motion` (`analyse`).

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.engine import Engine, solve_positions
    >>> from mbplanar.model import read_model
    >>> engine = Engine(read_model("models/fourbar.toml"))
    >>> sol = engine.rates(solve_positions(engine, np.radians([0.0, 90.0])), np.ones((2, 1)), np.zeros((2, 1)))
    >>> sol.valid.tolist(), sol.w.shape                             # ω of the links 0, 1, 2, 3 (rad/s)
    ([True, True], (2, 4))
    >>> sol.w[0].round(4).tolist()                                   # crank at 1 rad/s, at φ = 0
    [0.0, 1.0, -0.5, -0.5]
    """

    phi: np.ndarray
    pose: Pose
    blocks: list
    valid: np.ndarray
    limits: list = field(default_factory=list)
    crossings: list = field(default_factory=list)
    given_rates: tuple | None = None  # (rows, per block q', q'' (m, R) along +φ) near change points
    w: np.ndarray | None = None
    v: np.ndarray | None = None
    e: np.ndarray | None = None
    a: np.ndarray | None = None



class BlockSolver:
    """The numerical core of an engine: its blocks, solved and differentiated over a batch.

    mech: the assembled mechanism; laws: joint name → joint law; blocks: the topology's solving blocks;
    links: every link (rates are gathered in this order); size: the mechanism's size (lengths are
    relative to it); phi_drawn (n_in,): the input values of the drawn pose; tol: its `Tolerances`.

    Its `blocks` are the solving plans (`BlockPlan`: tree steps, cut joints, unknowns); `newton`
    corrects a block's unknowns over a batch, `solve_batch` solves every block in order from guesses,
    `rates` fills velocities and accelerations, `dets`, `signs`, `pivots` describe the Jacobians.
    Every `Engine` has one (`Engine.solver`).

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.engine import Engine
    >>> from mbplanar.model import read_model
    >>> solver = Engine(read_model("models/fourbar.toml")).solver
    >>> [(plan.joints, plan.m) for plan in solver.blocks]       # the crank, then the dyad and its 2 angles
    [(('O',), 0), (('A', 'B', 'C'), 2)]
    >>> sol = solver.solve_batch(np.radians([[60.0]]), [plan.q0[:, None] for plan in solver.blocks])
    >>> bool(sol.valid[0]), solver.signs(sol).tolist()            # the drawn pose, solved where it was
    (True, [[1.0, -1.0]])
    """

    def __init__(self, mech, laws: dict, blocks, links: list, size: float, phi_drawn: np.ndarray,
                 tol: Tolerances):
        self.mech = mech
        self.tol = tol
        self.laws = laws
        self.links = links
        self.size = size
        self.inputs = mech.inputs
        self.phi_drawn = phi_drawn
        self.blocks = [self._plan(block) for block in blocks]

    def _plan(self, block) -> BlockPlan:
        steps, var = [], 0
        for t in block.tree:
            law = self.laws[t.joint]
            joint = self.mech.joints[t.joint]
            relative = t.input is not None and joint.kind == "R"
            sign = 1.0
            if relative and t.parent != joint.links[0]:
                sign = -1.0
            steps.append(Step(law, t.parent, t.child, relative, None if t.input is not None else var,
                              t.input, sign))
            if t.input is None:
                var += 1
        cuts = [self.laws[name] for name in block.cuts]
        rows = []
        for name in block.cuts:
            rows += [1 / self.size, 1 / self.size] if self.mech.joints[name].kind == "R" else [1.0, 1 / self.size]
        angle = [self.mech.joints[s.law.name].kind == "R" for s in steps if s.var is not None]
        var_scale = [1.0 if a else 1 / self.size for a in angle]
        q0, period, params = [0.0] * var, [2 * np.pi if a else 0.0 for a in angle], []
        for name in getattr(block, "higher", ()):
            law = self.laws[name]
            cuts.append(law)
            rows += law.row_scale(self.size)
            if law.parameters:
                params.append((law, var))
                var_scale.append(law.param_scale(self.size))
                q0.append(law.param0)
                period.append(law.param_period)
                var += 1
        return BlockPlan(block.links, steps, cuts, var, np.array(rows), np.array(var_scale), block.group, params,
                         np.array(q0), np.array(period))

    # -- one block --------------------------------------------------------------------------------
    def input_vars(self, phi: np.ndarray) -> np.ndarray:
        """Tree variable of every input joint, (n_in, B): joint value minus its drawn value."""
        senses = np.array([inp.sense for inp in self.inputs])
        return (senses * (phi - self.phi_drawn)).T

    def block_pose(self, bp: BlockPlan, pose: Pose, q, q_in):
        caches = []
        for st in bp.steps:
            value = q[st.var] if st.var is not None else st.sign * q_in[st.input]
            caches.append(st.law.place(pose, st.parent, st.child, value, st.relative))
        for law, k in bp.params:
            pose.u[law.name] = q[k]
        cut_caches, res = [], []
        for law in bp.cuts:
            r, c = law.closure(pose)
            res.append(r)
            cut_caches.append(c)
        res = np.concatenate(res) if res else np.zeros((0, pose.batch))
        return caches, cut_caches, res

    def block_jacobian(self, bp: BlockPlan, caches, cut_caches, batch):
        """Closure Jacobian (m, m, B) and the sensitivity of the block's link rates to each unknown."""
        sens = Rates(batch, bp.m)
        eye = np.zeros((bp.m, bp.m, batch))
        eye[np.arange(bp.m), np.arange(bp.m)] = 1.0
        zero = np.zeros((bp.m, batch))
        for st, cache in zip(bp.steps, caches):
            qd = eye[st.var] if st.var is not None else zero
            st.law.place_rates(cache, sens, st.parent, st.child, qd, st.relative)
        for law, k in bp.params:
            sens.set_param(law.name, eye[k])
        rows = [law.closure_rates(c, sens) for law, c in zip(bp.cuts, cut_caches)]
        jac = np.concatenate(rows) if rows else np.zeros((0, 0, batch))
        return jac, sens

    def newton(self, bp: BlockPlan, pose: Pose, q, q_in) -> BlockState:
        batch = pose.batch
        polished = False
        for it in range(self.tol.max_newton + 1):
            caches, cut_caches, res = self.block_pose(bp, pose, q, q_in)
            if bp.m == 0:
                return BlockState(q, None, caches, cut_caches, None, np.ones(batch, bool))
            with np.errstate(invalid="ignore"):
                err = np.max(np.abs(res) * bp.row_scale[:, None], axis=0)
            jac, sens = self.block_jacobian(bp, caches, cut_caches, batch)
            lu = factor_scaled(bp, jac)
            ok = err < self.tol.closure
            fine = err < self.tol.polish
            if ok.all() and not polished:
                # near a singular position a residual of TOL still leaves an error of TOL / (smallest
                # pivot) along the singular direction: one more step there, to the rounding floor
                polished = True
                fine = (lu.pivot_ratio >= self.tol.pivot_polish) | (lu.pivot_ratio < self.tol.pivot_cross * 1e3)
                if fine.all():
                    break
            elif ok.all() or it == self.tol.max_newton:
                break
            with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
                step = lu.solve(-res)
            step[:, fine] = 0.0
            step[~np.isfinite(step)] = 0.0
            q = q + step
        ok &= np.isfinite(err)
        for law, k in bp.params:  # a contact past an open curve's end (a pin at the end of its slot)
            ok &= law.inside(q[k])
        return BlockState(q, lu, caches, cut_caches, sens, ok)

    # -- a batch --------------------------------------------------------------------------------
    def solve_batch(self, phi: np.ndarray, guesses: list) -> Solution:
        batch = len(phi)
        pose = Pose(batch)
        pose.set_ground(self.mech.ground)
        q_in = self.input_vars(phi)
        states, valid = [], np.ones(batch, bool)
        for bp, guess in zip(self.blocks, guesses):
            state = self.newton(bp, pose, guess, q_in)
            states.append(state)
            valid &= state.ok
        return Solution(phi, pose, states, valid)

    def dets(self, sol: Solution) -> np.ndarray:
        """Each block's Jacobian determinant (B, n_blocks); 1 for a block without unknowns."""
        out = np.ones((len(sol.phi), len(self.blocks)))
        for k, state in enumerate(sol.blocks):
            if state.lu is not None:
                out[:, k] = state.lu.det
        return out

    def signs(self, sol: Solution) -> np.ndarray:
        """Sign of each block's Jacobian determinant (B, n_blocks): constant along a branch, except
        across a change point."""
        return np.sign(self.dets(sol))

    def pivots(self, sol: Solution) -> np.ndarray:
        """Smallest pivot ratio over the blocks (B,): near 0 at a singular position."""
        out = np.ones(len(sol.phi))
        for state in sol.blocks:
            if state.lu is not None:
                out = np.minimum(out, state.lu.pivot_ratio)
        return out

    def rates(self, sol: Solution, phi_rate, phi_accel) -> Solution:
        """Fill the velocities and accelerations of every link for input rates (B, n_in) and input
        accelerations (B, n_in). With rate 1 and acceleration 0 these are the analogues."""
        batch = len(sol.phi)
        senses = np.array([inp.sense for inp in self.inputs])[:, None]
        qd_in = senses * np.broadcast_to(phi_rate, (batch, len(self.inputs))).T
        qdd_in = senses * np.broadcast_to(phi_accel, (batch, len(self.inputs))).T
        vel, acc = Rates(batch, 1), Rates(batch, 1)
        given = [(None, None)] * len(self.blocks)
        if sol.given_rates is not None:  # at a change point the Jacobian cannot give the rates
            rows, per_block = sol.given_rates
            om = np.broadcast_to(phi_rate, (batch, len(self.inputs)))[rows, 0]
            ep = np.broadcast_to(phi_accel, (batch, len(self.inputs)))[rows, 0]
            given = [((rows, qd * om), (rows, qdd * (om * om) + qd * ep)) for qd, qdd in per_block]
        for bp, state, (g_vel, g_acc) in zip(self.blocks, sol.blocks, given):
            state.qd = self._block_rates(bp, state, vel, qd_in, given=g_vel)
            state.qdd = self._block_rates(bp, state, acc, qdd_in, vel, state.qd, qd_in, given=g_acc)
        sol.w, sol.v = self._gather_rates(vel, batch)
        sol.e, sol.a = self._gather_rates(acc, batch)
        return sol

    def _gather_rates(self, rates: Rates, batch):
        """w (B, L) and v (B, L, 2) of every link, views of arrays (L, B) and (2, L, B) filled row by row
        (cheaper than np.stack for a small batch)."""
        w, v = np.empty((len(self.links), batch)), np.empty((2, len(self.links), batch))
        for k, n in enumerate(self.links):
            wk, vk = rates.get(n)
            w[k], v[:, k] = wk[0], vk[:, 0]
        return w.T, v.T

    def _block_rates(self, bp, state, known: Rates, q_in_rate, vel=None, qd_vel=None, q_in_vel=None,
                     given=None):
        """Rates of a block's links into `known`: a pass with the unknown rates at zero, then the
        Jacobian solve and the correction by the sensitivities. With `vel` (the velocities, and the tree
        variables' velocities qd_vel, q_in_vel) it computes accelerations. `given` = (rows, values (m, R))
        replaces the solve at those rows. Returns the unknowns' rates."""
        batch = q_in_rate.shape[1]
        zero = np.zeros((1, batch))
        for st, cache in zip(bp.steps, state.caches):
            if st.var is not None:
                qd = zero
                qv = None if qd_vel is None else qd_vel[st.var:st.var + 1]
            else:
                qd = st.sign * q_in_rate[st.input:st.input + 1]
                qv = None if q_in_vel is None else st.sign * q_in_vel[st.input:st.input + 1]
            st.law.place_rates(cache, known, st.parent, st.child, qd, st.relative, vel, qv)
        if bp.m == 0:
            return np.zeros((0, batch))
        rhs = np.concatenate([law.closure_rates(c, known, vel)[:, 0] for law, c in
                              zip(bp.cuts, state.cut_caches)])
        with np.errstate(invalid="ignore", divide="ignore"):
            qd_u = state.lu.solve(-rhs)
        if given is not None and len(given[0]):
            qd_u[:, given[0]] = given[1]
        for law, k in bp.params:
            known.set_param(law.name, qd_u[k:k + 1])
        for link in bp.links:
            w, v = known.get(link)
            sw, sv = state.sens.w[link], state.sens.v[link]
            known.set(link, w + (sw * qd_u).sum(axis=0, keepdims=True),
                      v + (sv * qd_u).sum(axis=1, keepdims=True))
        return qd_u

