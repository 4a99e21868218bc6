"""Positions, velocities and accelerations of every link: Newton–Raphson on the loop closures of each
block, continuation along the input that never leaves the drawn branch, and located motion limits.

`Engine(mechanism)` compiles a model once: exact drawn pose, topology, joint laws, index maps. It then
solves any batch of input values at once (arrays with a batch axis, no loop over positions):

1. The branch atlas: from the drawn pose the engine walks the input up and down with adaptive steps
   (second-order predictor from the analytic derivatives, Newton corrector). A step is accepted only when
   Newton converges, the corrector stays close to the predictor in positions and in derivatives, and no
   block's Jacobian determinant changes sign; otherwise the step is halved. A sign change with positions
   and derivatives that follow the predictor closely over a short step is a change point (another
   assembly branch crosses this one, e.g. the parallelogram four-bar with its links in line): the walk
   goes through it on the smooth branch, placing two nodes either side (`_bracket`) between which the
   interpolant gives the rates, where the singular Jacobian cannot. A step that cannot be made smaller
   than `H_MIN` marks a
   motion limit (dead point, lock-up, end of assembly). At a fold (the usual dead point: a block's
   Jacobian loses rank one and the branch turns back) the limit's φ and configuration are then solved
   for together, by Newton on the block's closure equations bordered by a singularity condition
   (`_locate_fold`), to the rounding floor (~1e-15 in φ); otherwise the limit is the middle of the
   walk's last bracket, good to ~`H_MIN`. The walked nodes are then filled in, one batch solve, to at
   most `H_DENSE` apart. The atlas is built once per engine and extended on demand; positions between
   its last node and a limit (at most a few `H_MIN`) are left out with the limit.
2. Every requested position is predicted by the quintic Hermite interpolant of the atlas nodes around it
   (within the closure tolerance, so Newton usually only confirms it) and corrected by a batched Newton,
   block by block; the few that fail a check are walked to individually.

Velocities and accelerations come from the same factorised block Jacobians (the analogues are the rates
for dφ/dt = 1, d²φ/dt² = 0).

Inside, arrays carry the batch last (unknowns q (m, B), Jacobians (m, m, B), see `constraints`), so that
every elementwise operation runs over a contiguous batch; `Solution` exposes the usual batch-first views.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ._backend import load as load_backend
from ._linalg import factor
from ..model._assembly import assemble, reference_points
from ._constraints import Pose, Rates, make_law
from ..errors import MotionError
from ..model._model import Mechanism
from ..structure._topology import analyse_topology

__all__ = ["Engine", "Solution", "Limit", "Crossing"]

TOL = 1e-13          # closure residual (lengths relative to the mechanism's size)
TOL_FINE = 1e-14     # while some position still needs a step, the others below TOL are polished to this
MAX_NEWTON = 14
H_START = math.radians(6.0)   # first continuation step (relative to the input's scale)
H_MAX = math.radians(15.0)
H_MIN = 1e-10
H_DENSE = math.radians(1.0)   # widest atlas interval the predictor interpolates over (see _Atlas._densify)
MAX_CORRECTION = 0.05  # largest accepted corrector distance (rad, or lengths / size)
RATE_JUMP = 0.25       # largest accepted change of the unknowns' derivatives against their prediction,
                       # relative to 1 + |q'|: a larger one means the corrector found another branch
H_CROSS = 2e-2         # widest step across a change point (relative to the input's scale); the nodes
                       # that bracket it are half of it away, where the Jacobian is still well enough
                       # conditioned for rates to ~1e-12
CROSS_DIST = 1e-6      # largest corrector distance of a step across a change point
PIVOT_POLISH = 0.05    # below this pivot ratio a converged position gets one more Newton step
PIVOT_CROSS = 1e-9     # nodes on either side of a change point must be at least this far from singular


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
    links: tuple
    steps: list
    cuts: list
    m: int
    row_scale: np.ndarray  # multiplies residual rows so that lengths are relative to the size
    var_scale: np.ndarray  # likewise for the unknowns (angles 1, displacements 1/size)
    group: object = None

    @property
    def joints(self) -> tuple:
        """Names of the block's joints: tree joints, then cuts."""
        return tuple(st.law.name for st in self.steps) + tuple(law.name for law in self.cuts)


@dataclass
class Limit:
    """Where the motion ends along the input: φ (SI), the block at fault, and what happens there.

    At a fold (dead point: the block's Jacobian is singular and the branch turns back) φ is solved for
    together with the configuration there, `q` (every block's unknowns (m,), as in `Solution.blocks`),
    to the rounding floor (see `_locate_fold`). Where that does not converge `q` is None and φ is the
    middle of the bracket the walk left, good to `H_MIN` in the input."""

    phi: np.ndarray  # (n_in,) input values (SI)
    direction: int
    links: tuple
    joints: tuple
    kind: str
    q: list | None = None


@dataclass
class Crossing:
    """A change point on the branch: a block's Jacobian is singular there, but the branch goes on
    smoothly through it (another assembly branch crosses it, e.g. the parallelogram four-bar with all
    links in line). φ (SI) is located by the sign change of the block's determinant; `bracket` holds the
    atlas nodes on either side, whose interpolant gives the rates at and near the change point."""

    phi: np.ndarray  # (n_in,)
    links: tuple
    joints: tuple
    bracket: tuple = (None, None)
    kind: str = ""


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


class Engine:
    """A compiled mechanism, ready to solve batches of positions.

    backend: "numpy" (the reference) or "numba", which runs the kinematics and kinetostatics of
    one-input sweeps through compiled per-position loops (`mbplanar.backends._numba_kinematics`,
    `mbplanar.backends._numba_kinetostatics`; needs the optional extra `fast`) and falls back to numpy wherever
    those loops cannot vouch for a position.
    threads: how many cores the compiled loops split a long batch over (default: the cores available,
    or the environment variable MBPLANAR_THREADS); the answers do not depend on it."""

    def __init__(self, mech: Mechanism, grouped: bool = True, backend: str = "numpy", threads: int | None = None):
        if threads is not None and (not isinstance(threads, int) or threads < 1):
            raise ValueError(f"threads must be a positive integer, not {threads!r}")
        self.compiled = load_backend(backend)  # None: numpy alone
        self.threads = threads
        self.backend = backend
        self.prepared: dict = {}  # tables built on first use, by name (`prepare`)
        self.mech = assemble(mech)
        self.topology = analyse_topology(self.mech, grouped)
        mech = self.mech
        self.links = mech.all_links
        self.link_index = {name: k for k, name in enumerate(self.links)}
        self.laws = {name: make_law(j) for name, j in mech.joints.items()}
        self.size = max([1e-9] + [math.dist(a.at, b.at) for a in mech.joints.values()
                                  for b in mech.joints.values()])
        self.inputs = mech.inputs
        self.reference_angle = {link: self._drawn_link_angle(link) for link in self.links}
        self.phi_drawn = np.array([self._drawn_phi(inp) for inp in self.inputs])
        self.joint_value_drawn = {name: self._drawn_joint_value(name) for name in mech.joints}
        self.blocks = [self._plan(block) for block in self.topology.blocks]
        self._atlas = None

    def prepare(self, name: str, make):
        """The engine's table called `name`, made by `make()` on first use and kept (the output tables,
        the kinetostatic plan, a backend's kernel tables, ...)."""
        table = self.prepared.get(name)
        if table is None:
            table = self.prepared[name] = make()
        return table

    # -- compile --------------------------------------------------------------------------------
    def _drawn_link_angle(self, link: str) -> float:
        """Direction of the link's reference line in the drawn pose (rad)."""
        if link == self.mech.ground:
            return 0.0
        offset = self.mech.links[link].angle_offset
        ref = reference_points(self.mech, link)
        if ref is not None:
            p, q = (self._drawn_point(link, n) for n in ref)
            return math.atan2(q[1] - p[1], q[0] - p[0]) + offset
        guide = next((j for j in self.mech.joints_of(link) if j.kind == "P"), None)
        return (math.radians(guide.guide_deg) if guide is not None else 0.0) + offset

    def _drawn_point(self, link: str, name: str):
        if name in self.mech.joints:
            return self.mech.joints[name].at
        return self.mech.points[name].at

    def _drawn_phi(self, inp) -> float:
        if inp.drawn_at is not None:
            return inp.to_si(inp.drawn_at)
        j = self.mech.joints[inp.joint]
        if j.kind == "P":
            return -inp.zero * inp.scale / inp.sense
        value = self.reference_angle[j.links[1]] - self.reference_angle[j.links[0]]
        phi = (value - inp.zero * inp.scale) / inp.sense
        lo = inp.to_si(inp.default_sweep()[0])
        return lo + (phi - lo) % (2 * math.pi)

    def _drawn_joint_value(self, name: str) -> float:
        inp = next((k for k, i in enumerate(self.inputs) if i.joint == name), None)
        if inp is not None:
            return float(self.inputs[inp].joint_value(self.phi_drawn[inp]))
        j = self.mech.joints[name]
        if j.kind == "P":
            return 0.0
        return self.reference_angle[j.links[1]] - self.reference_angle[j.links[0]]

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
        var_scale = np.array([1.0 if self.mech.joints[s.law.name].kind == "R" else 1 / self.size
                              for s in steps if s.var is not None])
        return BlockPlan(block.links, steps, cuts, var, np.array(rows), var_scale, block.group)

    # -- one block --------------------------------------------------------------------------------
    def _input_vars(self, phi: np.ndarray) -> np.ndarray:
        """Tree variable of every input joint, (n_in, B): joint value minus its drawn value."""
        senses = np.array([inp.sense for inp in self.inputs])
        return (senses * (phi - self.phi_drawn)).T

    def _block_pose(self, bp: BlockPlan, pose: Pose, q, q_in):
        caches = []
        for st in bp.steps:
            value = q[st.var] if st.var is not None else st.sign * q_in[st.input]
            caches.append(st.law.place(pose, st.parent, st.child, value, st.relative))
        cut_caches, res = [], []
        for law in bp.cuts:
            r, c = law.closure(pose)
            res.append(r)
            cut_caches.append(c)
        res = np.concatenate(res) if res else np.zeros((0, pose.batch))
        return caches, cut_caches, res

    def _block_jacobian(self, bp: BlockPlan, caches, cut_caches, batch):
        """Closure Jacobian (m, m, B) and the sensitivity of the block's link rates to each unknown."""
        sens = Rates(batch, bp.m)
        eye = np.zeros((bp.m, bp.m, batch))
        eye[np.arange(bp.m), np.arange(bp.m)] = 1.0
        zero = np.zeros((bp.m, batch))
        for st, cache in zip(bp.steps, caches):
            qd = eye[st.var] if st.var is not None else zero
            st.law.place_rates(cache, sens, st.parent, st.child, qd, st.relative)
        rows = [law.closure_rates(c, sens) for law, c in zip(bp.cuts, cut_caches)]
        jac = np.concatenate(rows) if rows else np.zeros((0, 0, batch))
        return jac, sens

    def _newton(self, bp: BlockPlan, pose: Pose, q, q_in) -> BlockState:
        batch = pose.batch
        polished = False
        for it in range(MAX_NEWTON + 1):
            caches, cut_caches, res = self._block_pose(bp, pose, q, q_in)
            if bp.m == 0:
                return BlockState(q, None, caches, cut_caches, None, np.ones(batch, bool))
            with np.errstate(invalid="ignore"):
                err = np.max(np.abs(res) * bp.row_scale[:, None], axis=0)
            jac, sens = self._block_jacobian(bp, caches, cut_caches, batch)
            lu = factor(jac)
            ok = err < TOL
            fine = err < TOL_FINE
            if ok.all() and not polished:
                # near a singular position a residual of TOL still leaves an error of TOL / (smallest
                # pivot) along the singular direction: one more step there, to the rounding floor
                polished = True
                fine = (lu.pivot_ratio >= PIVOT_POLISH) | (lu.pivot_ratio < PIVOT_CROSS * 1e3)
                if fine.all():
                    break
            elif ok.all() or it == MAX_NEWTON:
                break
            with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
                step = lu.solve(-res)
            step[:, fine] = 0.0
            step[~np.isfinite(step)] = 0.0
            q = q + step
        ok &= np.isfinite(err)
        return BlockState(q, lu, caches, cut_caches, sens, ok)

    # -- a batch --------------------------------------------------------------------------------
    def _solve_batch(self, phi: np.ndarray, guesses: list) -> Solution:
        batch = len(phi)
        pose = Pose(batch)
        pose.set_ground(self.mech.ground)
        q_in = self._input_vars(phi)
        states, valid = [], np.ones(batch, bool)
        for bp, guess in zip(self.blocks, guesses):
            state = self._newton(bp, pose, guess, q_in)
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
        for link in bp.links:
            w, v = known.get(link)
            sw, sv = state.sens.w[link], state.sens.v[link]
            known.set(link, w + (sw * qd_u).sum(axis=0, keepdims=True),
                      v + (sv * qd_u).sum(axis=1, keepdims=True))
        return qd_u

    # -- continuation ---------------------------------------------------------------------------
    def atlas(self):
        if self._atlas is None:
            self._atlas = _Atlas(self)
        return self._atlas

    def solve(self, phi) -> Solution:
        """Solve positions for input values `phi` (SI): (B,) for one input, (B, n_in) for several.
        Positions past a motion limit are left out (`valid` False, `limits` says where)."""
        phi = np.asarray(phi, dtype=float)
        if phi.ndim == 0:
            phi = phi[None]
        if phi.ndim == 1:
            phi = phi[:, None] if len(self.inputs) == 1 else phi[None, :]
        if phi.shape[1] != len(self.inputs):
            raise ValueError(f"expected {len(self.inputs)} input value(s) per position")
        if not np.all(np.isfinite(phi)):
            raise ValueError("input values must be finite")
        return _solve_along(self, phi)

    def solve_limits(self, limits: list) -> Solution:
        """The configurations at the located motion limits among `limits` (those with `Limit.q`), one
        row each: every block is already converged there, so Newton takes no step (which it could not,
        the block at fault being singular). The rates of such a row are meaningless (infinite)."""
        found = [lim for lim in limits if lim.q is not None]
        phi = np.array([lim.phi for lim in found], float).reshape(len(found), len(self.inputs))
        guesses = [np.stack([lim.q[k] for lim in found], axis=1) if found else np.zeros((bp.m, 0))
                   for k, bp in enumerate(self.blocks)]
        sol = self._solve_batch(phi, guesses)
        sol.limits = found
        return sol


class _Atlas:
    """Nodes of the drawn branch along a single input, sorted by φ, with q, q', q'' per block."""

    def __init__(self, engine: Engine):
        self.engine = engine
        self.nodes = [_origin(engine, np.ones(1))]
        self.limits = {+1: None, -1: None}
        self.crossings = []

    def cover(self, lo: float, hi: float):
        """Extend the atlas to cover [lo, hi], or up to a motion limit."""
        grown = False
        for direction, target in ((+1, hi), (-1, lo)):
            start = self.nodes[-1] if direction > 0 else self.nodes[0]
            if self.limits[direction] is not None or direction * (target - start.phi[0]) <= 0:
                continue
            new, limit, crossings = _walk(self.engine, start, np.array([target]))
            self.limits[direction] = limit
            self.crossings = sorted(self.crossings + crossings, key=lambda c: c.phi[0])
            self.nodes = self.nodes + new if direction > 0 else new[::-1] + self.nodes
            self._arrays, grown = None, True
        if grown:
            self._densify()

    def _densify(self):
        """Add nodes, solved in one batch, so that no interval is wider than `H_DENSE` input units: the
        predictor's error (~h⁶) then stays below the closure tolerance and Newton needs no step."""
        e = self.engine
        grid = np.array([n.phi[0] for n in self.nodes])
        width = H_DENSE * _input_scale(e)[0]
        parts = np.ceil(np.diff(grid) / width).astype(int)
        x = np.concatenate([grid[i] + (grid[i + 1] - grid[i]) * np.arange(1, k) / k
                            for i, k in enumerate(parts) if k > 1] or [np.zeros(0)])
        x = x[~_in_brackets(self.crossings, x)]  # nothing between the two nodes around a change point
        if not len(x):
            return
        inside = np.ones(len(x), bool)
        left = np.clip(np.searchsorted(grid, x) - 1, 0, len(grid) - 2)
        with np.errstate(invalid="ignore", over="ignore"):
            guesses = _interpolate(grid, self.arrays()[1], x, left, inside)
        sol = e._solve_batch(x[:, None], guesses)
        e.rates(sol, np.ones((len(x), 1)), np.zeros((len(x), 1)))
        dets, pivots = e.dets(sol), e.pivots(sol)
        good = sol.valid & (pivots >= PIVOT_CROSS) & np.all(np.sign(dets) == self.arrays()[2][left], axis=1)
        for state, g, bp in zip(sol.blocks, guesses, e.blocks):
            if bp.m:
                good &= np.max(np.abs(state.q - g) * bp.var_scale[:, None], axis=0) <= MAX_CORRECTION
        one = np.ones(1)
        extra = [_Node(x[i:i + 1], one, [s.q[:, i] for s in sol.blocks], [s.qd[:, i] for s in sol.blocks],
                       [s.qdd[:, i] for s in sol.blocks], dets[i], float(pivots[i]))
                 for i in np.flatnonzero(good)]
        self.nodes = sorted(self.nodes + extra, key=lambda n: n.phi[0])
        self._arrays = None

    _arrays = None

    def arrays(self):
        """φ (K,), per block (q, q', q'') as (m, K) with derivatives along +φ and the quintic Hermite
        coefficients (6, m, K − 1) of every interval, and signs (K, n_blocks); computed once per
        extension of the atlas."""
        if self._arrays is None:
            phi = np.array([n.phi[0] for n in self.nodes])
            h = np.diff(phi)
            derivatives = [n.per_input() for n in self.nodes]
            per_block = []
            for k in range(len(self.engine.blocks)):
                q = np.stack([n.q[k] for n in self.nodes], axis=1)
                qd = np.stack([d[0][k] for d in derivatives], axis=1)
                qdd = np.stack([d[1][k] for d in derivatives], axis=1)
                ends = np.stack([q[:, :-1], q[:, 1:], h * qd[:, :-1], h * qd[:, 1:],
                                 h * h * qdd[:, :-1], h * h * qdd[:, 1:]])  # (6, m, K − 1)
                per_block.append((q, qd, qdd, np.einsum("ce,emk->cmk", _HERMITE5, ends)))
            self._arrays = phi, per_block, np.stack([n.signs for n in self.nodes])
        return self._arrays


# coefficients of t⁰ … t⁵ (rows) of the quintic Hermite interpolant on t ∈ [0, 1] from the end values
# (q0, q1, h·q0', h·q1', h²·q0'', h²·q1'') (columns)
_HERMITE5 = np.array([
    [1, 0, 0, 0, 0, 0],
    [0, 0, 1, 0, 0, 0],
    [0, 0, 0, 0, 0.5, 0],
    [-10, 10, -6, -4, -1.5, 0.5],
    [15, -15, 8, 7, 1.5, -1],
    [-6, 6, -3, -3, -0.5, 0.5]], float)


@dataclass
class _Node:
    """A solved position on the branch with the derivatives of its unknowns along `direction`."""

    phi: np.ndarray
    direction: np.ndarray
    q: list
    qd: list
    qdd: list
    dets: np.ndarray
    pivot: float = 1.0

    @property
    def signs(self) -> np.ndarray:
        return np.sign(self.dets)

    def per_input(self, k: int = 0) -> tuple[list, list]:
        """q' and q'' of every block with respect to input k (the walk's are per unit s, dφ/ds =
        direction)."""
        d = self.direction[k]
        return [qd / d for qd in self.qd], [qdd / (d * d) for qdd in self.qdd]


def _node_at(e: Engine, phi: np.ndarray, direction: np.ndarray, guesses) -> _Node | None:
    sol = e._solve_batch(phi[None, :], guesses)
    if not sol.valid[0]:
        return None
    e.rates(sol, direction[None, :], np.zeros((1, len(e.inputs))))
    return _Node(phi.copy(), direction, [s.q[:, 0] for s in sol.blocks], [s.qd[:, 0] for s in sol.blocks],
                 [s.qdd[:, 0] for s in sol.blocks], e.dets(sol)[0], float(e.pivots(sol)[0]))


def _origin(e: Engine, direction) -> _Node:
    node = _node_at(e, e.phi_drawn, direction, [np.zeros((bp.m, 1)) for bp in e.blocks])
    if node is None:
        raise MotionError(f"{e.mech.source}: the drawn pose does not close: it cannot be assembled")
    if node.pivot < PIVOT_CROSS:
        k = int(np.argmin(np.abs(node.dets)))
        raise MotionError(f"{e.mech.source}: the drawn pose is a singular position of the group of links "
                          f"{', '.join(e.blocks[k].links)} (links in line: a dead point or a change "
                          "point), where the assembly branch is ambiguous; draw the mechanism in another "
                          "position")
    return node


def _predict(node: _Node, s: float):
    """Taylor guess of every block's unknowns a distance s along the node's direction."""
    return [(q + qd * s + 0.5 * qdd * s * s)[:, None] for q, qd, qdd in zip(node.q, node.qd, node.qdd)]


def _accept(e: Engine, node: _Node, new: _Node | None, guesses, h: float) -> tuple[str, float]:
    """Verdict on a step of length h from `node`: "ok" when it converged on the same branch, close to
    its prediction in position and in derivatives; "cross" when it went smoothly through a change point
    (a determinant changed sign, but positions and derivatives follow the prediction closely, which the
    other branch crossing there does not, and a dead point has no solution beyond it); else "reject"."""
    if new is None or new.pivot < PIVOT_CROSS:  # no node on a singular position: its rates are unknown
        return "reject", math.inf
    dist = _distance(e, new, guesses)
    if dist > MAX_CORRECTION or _rate_jump(e, node, new, h) > RATE_JUMP:
        return "reject", dist
    if np.array_equal(new.signs, node.signs):
        return "ok", dist
    if h <= H_CROSS and dist <= CROSS_DIST:  # (no node is placed on a singular position)
        return "cross", dist
    return "reject", dist


def _distance(e: Engine, new: _Node, guesses) -> float:
    """Largest distance of the corrector from the predictor (scaled unknowns)."""
    return max([np.max(np.abs(q - g[:, 0]) * bp.var_scale, initial=0.0)
                for q, g, bp in zip(new.q, guesses, e.blocks)] + [0.0])


def _rate_jump(e: Engine, node: _Node, new: _Node, h: float) -> float:
    """Largest change of the unknowns' derivatives from `node` to `new` against the Taylor prediction,
    relative to 1 + |q'| (scaled unknowns)."""
    worst = 0.0
    for qd, qdd, qd_new, bp in zip(node.qd, node.qdd, new.qd, e.blocks):
        if bp.m:
            err = np.abs(qd_new - qd - qdd * h) * bp.var_scale / (1.0 + np.abs(qd) * bp.var_scale)
            worst = max(worst, float(np.max(err)) if np.all(np.isfinite(err)) else math.inf)
    return worst


def _input_scale(e: Engine) -> np.ndarray:
    """Natural step unit of each input: 1 rad for an angle, the mechanism's size for a slider."""
    return np.array([1.0 if e.mech.joints[i.joint].kind == "R" else e.size for i in e.inputs])


def _walk(e: Engine, start: _Node, target: np.ndarray, overshoot: bool = True):
    """Continuation on the straight segment from `start` to `target` in input space.
    Returns the new nodes (the last at `target` unless a limit stops it, or a little past it when the
    target is a change point and `overshoot`), a `Limit` or None, and the change points passed."""
    span = target - start.phi
    scale = float(np.max(np.abs(span) / _input_scale(e)))
    if scale == 0:
        return [], None, []
    direction = span / scale  # one unit of s moves the inputs by one natural unit at most
    node = start
    if not np.array_equal(node.direction, direction):
        node = _node_at(e, start.phi, direction, [q[:, None] for q in start.q])
    nodes, crossings, s, h = [], [], 0.0, H_START
    while s < scale:
        h_try = min(h, scale - s)
        guesses = _predict(node, h_try)
        phi = start.phi + direction * (s + h_try) if s + h_try < scale else target.astype(float)
        new = _node_at(e, phi, direction, guesses)
        if new is not None and new.pivot < PIVOT_CROSS and s + h_try >= scale and overshoot:
            # the target is a change point itself: go a little past it, so that nodes bracket it
            scale, overshoot = scale + H_CROSS, False
            target = start.phi + direction * scale
            continue
        verdict, dist = _accept(e, node, new, guesses, h_try)
        if verdict == "cross":
            bracket = _bracket(e, start, node, new, direction)
            if bracket is not None:
                crossing, before, after = bracket
                crossings.append(crossing)
                s_before = _along(before, start.phi, direction)
                nodes = [n for n in nodes if _along(n, start.phi, direction) < s_before]
                nodes += [before, after] if before is not start else [after]
                node, s = after, _along(after, start.phi, direction)
                if s > scale:  # the target lay between the bracketing nodes
                    scale, target = s, after.phi.copy()
                continue
            verdict = "reject"
        if verdict == "ok":
            nodes.append(new)
            node, s = new, s + h_try
            if dist < 0.1 * MAX_CORRECTION:
                h = min(h_try * 1.6, H_MAX)
            continue
        h = h_try / 2
        if h < H_MIN:
            return nodes, _limit(e, node, direction, h_try), crossings
    return nodes, None, crossings


def _along(node: _Node, origin: np.ndarray, direction: np.ndarray) -> float:
    """Distance s of a node along a walk from `origin` in `direction`."""
    k = int(np.argmax(np.abs(direction)))
    return float((node.phi[k] - origin[k]) / direction[k])


def _bracket(e: Engine, start: _Node, node: _Node, new: _Node, direction: np.ndarray):
    """Nodes on either side of the change point between `node` and `new`, half of `H_CROSS` away from
    it (so that both are well conditioned and the interpolant between them gives the rates at the
    change point; the walk's start node serves as the first when it is nearer), or None when they do
    not converge on the branch. The change point is located by the secant on the block's determinant,
    linear in φ near a simple change point. Returns (Crossing, before, after)."""
    origin = start.phi
    k = int(np.flatnonzero(node.signs != new.signs)[0])
    s0, s1 = _along(node, origin, direction), _along(new, origin, direction)
    s_c = s0 + (s1 - s0) * node.dets[k] / (node.dets[k] - new.dets[k])
    # half of H_CROSS in the unknowns' own units: a branch that turns fast needs closer nodes
    speed = max([1.0] + [float(np.max(np.abs(qd) * bp.var_scale, initial=0.0)) / abs(direction).max()
                         for qd, bp in zip(node.qd, e.blocks)])
    half = 0.5 * H_CROSS / speed
    sides = []
    for s_side in (s_c - half, s_c + half):
        if s_side <= 0:
            sides.append(start)
            continue
        guesses = _predict(node, s_side - s0)
        side = _node_at(e, origin + direction * s_side, direction, guesses)
        # the crossing branch is |Δq'|·half away; the prediction's own error grows as half³
        if (side is None or side.pivot < PIVOT_CROSS or _distance(e, side, guesses) > 0.01 * half * speed
                or _rate_jump(e, node, side, s_side - s0) > RATE_JUMP):
            return None
        sides.append(side)
    before, after = sides
    if not (np.array_equal(before.signs, node.signs) and np.array_equal(after.signs, new.signs)):
        return None
    bp = e.blocks[k]
    lo, hi = sorted((before.phi[0], after.phi[0]))
    phi_c = _locate_crossing(e, k, before, after)
    kind = _limit_kind(e, bp, e._solve_batch(phi_c[None, :], _hermite_between(before, after, phi_c)))
    return Crossing(phi_c, bp.links, bp.joints, (lo, hi), kind), before, after


def _hermite_between(a: _Node, b: _Node, phi: np.ndarray) -> list:
    """Every block's unknowns (m, 1) at φ between two nodes of a walk, by the quintic Hermite
    interpolant of their q, q', q'' along the segment from a to b."""
    k = int(np.argmax(np.abs(b.phi - a.phi)))
    h = float(b.phi[k] - a.phi[k])
    t = float((phi[k] - a.phi[k]) / h)
    basis = np.array([t ** n for n in range(6)]) @ _HERMITE5
    (qda, qdda), (qdb, qddb) = a.per_input(k), b.per_input(k)
    return [(basis @ np.stack([q0, q1, h * d0, h * d1, h * h * dd0, h * h * dd1]))[:, None]
            for q0, q1, d0, d1, dd0, dd1 in zip(a.q, b.q, qda, qdb, qdda, qddb)]


def _det_at(e: Engine, k: int, phi: np.ndarray, guesses) -> float:
    """Block k's Jacobian determinant at the positions `guesses` (no Newton step)."""
    pose = Pose(1)
    pose.set_ground(e.mech.ground)
    q_in = e._input_vars(phi[None, :])
    for bp, q in zip(e.blocks[:k + 1], guesses):
        caches, cut_caches, _ = e._block_pose(bp, pose, q, q_in)
    jac, _ = e._block_jacobian(e.blocks[k], caches, cut_caches, 1)
    return float(factor(jac).det[0])


def _locate_crossing(e: Engine, k: int, a: _Node, b: _Node, iterations: int = 6) -> np.ndarray:
    """φ of the change point between nodes a and b: regula falsi on block k's determinant, evaluated
    on the branch's interpolant (Newton cannot settle positions this close to a singular Jacobian)."""
    (pa, da), (pb, db) = (a.phi, a.dets[k]), (b.phi, b.dets[k])
    for _ in range(iterations):
        p = pa + (pb - pa) * (da / (da - db))
        d = _det_at(e, k, p, _hermite_between(a, b, p))
        if d == 0 or not np.isfinite(d):
            break
        if np.sign(d) == np.sign(da):
            pa, da = p, d
        else:
            pb, db = p, d
    return p


def _limit(e: Engine, node: _Node, direction: np.ndarray, h: float) -> Limit:
    """The motion limit just past `node` (the walk could not step h from it), in the block whose Jacobian
    is nearest to singular: the fold, located exactly with its configuration, when `_locate_fold`
    finds it at the end of the node's branch; else the middle of the walk's bracket (q None)."""
    sol = e._solve_batch(node.phi[None, :], [q[:, None] for q in node.q])
    ratios = [float(st.lu.pivot_ratio[0]) if st.lu is not None else math.inf for st in sol.blocks]
    k = int(np.argmin(ratios))
    bp = e.blocks[k]
    joints = bp.joints
    sign = int(np.sign(direction[0])) if len(direction) == 1 else 0
    fold = _locate_fold(e, k, node, direction) if bp.m else None
    if fold is None:
        return Limit(node.phi + direction * h / 2, sign, bp.links, joints, _limit_kind(e, bp, sol))
    phi, at = fold
    return Limit(phi, sign, bp.links, joints, _limit_kind(e, bp, at), [st.q[:, 0] for st in at.blocks])


FOLD_ITERATIONS = 8
FOLD_DELTA = 1e-6    # central-difference step of the augmented Jacobian (scaled unknowns, s)
FOLD_STEP = 1e-14    # converged when a Newton step moves no scaled unknown and s by more than this
FOLD_SQRT_LAW = 0.1  # largest relative departure from the square-root law between a node and its fold


def _locate_fold(e: Engine, k: int, node: _Node, direction: np.ndarray):
    """The fold of block k a distance s ahead of `node` along `direction` (the walk stopped a few `H_MIN`
    short of it): Newton from the node on the augmented system F(x) = [block k's scaled closure
    residuals; g] = 0 in x = (scaled q_k, s), g the bordered singularity function (`_bordered`). At a
    simple fold this system is regular (J loses rank one and ∂F/∂s is not in its range: the branch
    turns back), so Newton converges quadratically to the rounding floor, where bisection only gets to
    `H_MIN` in s and the driven unknowns, which move like √(distance) there, to ~1e-5. At a change
    point (rank lost by [J, ∂F/∂s] too) it is singular and `_on_the_branch` rejects what it finds.
    Returns (φ, Solution at φ), or None when it does not converge to the end of the node's branch."""
    bp = e.blocks[k]
    x = np.append(node.q[k] * bp.var_scale, 0.0)
    border = _border(e, k, node)
    for _ in range(FOLD_ITERATIONS):
        res, jac = _fold_system(e, k, node, direction, x, border)
        if res is None:
            return None
        with np.errstate(all="ignore"):
            step = np.linalg.lstsq(jac, -res, rcond=None)[0]
        if not np.all(np.isfinite(step)):
            return None
        x = x + step
        if np.max(np.abs(step)) <= FOLD_STEP:
            break
    else:
        return None
    s = float(x[-1])
    if not _on_the_branch(x[:-1] - node.q[k] * bp.var_scale, s, node.qd[k] * bp.var_scale):
        return None
    phi = node.phi + direction * s
    guesses = [q[:, None] for q in node.q]
    guesses[k] = (x[:-1] / bp.var_scale)[:, None]
    sol = e._solve_batch(phi[None, :], guesses)  # the blocks after k, regular there
    # block k converged already: Newton must leave it at the fold (`Engine.solve_limits` relies on it)
    if not sol.valid[0] or not np.array_equal(sol.blocks[k].q, guesses[k]):
        return None
    return phi, sol


def _on_the_branch(dq: np.ndarray, s: float, qd: np.ndarray) -> bool:
    """Whether a fold found at distance s ≥ 0 ahead of a node, with the unknowns moved by dq, is the end
    of the node's own branch: near a fold the unknowns move like √(s_fold − s), so from the node to the
    fold they move by 2·s·q'(node) up to a relative O(√s) (another branch's fold, or one behind the
    node, fails this). The walk's bracket is not the test: the walk can fail to converge a step short
    of the fold, which then lies up to a few `H_MIN` past the bracket."""
    if not (0.0 <= s <= H_CROSS) or np.max(np.abs(dq)) > MAX_CORRECTION:
        return False
    return bool(np.max(np.abs(dq - 2 * s * qd)) <= FOLD_SQRT_LAW * np.max(np.abs(dq)))


def _border(e: Engine, k: int, node: _Node):
    """Left and right singular vectors (b, c) of block k's scaled Jacobian at `node` for its smallest
    singular value: they border the Jacobian into a matrix that stays regular through the fold."""
    sol = e._solve_batch(node.phi[None, :], [q[:, None] for q in node.q])
    bp = e.blocks[k]
    st = sol.blocks[k]
    jac, _ = e._block_jacobian(bp, st.caches, st.cut_caches, 1)
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


def _fold_system(e: Engine, k: int, node: _Node, direction: np.ndarray, x: np.ndarray, border):
    """Augmented residual (m + 1,) at x = (scaled q_k, s) and its Jacobian (m + 1, m + 1) by central
    differences, all evaluated in one batch; (None, None) if a block before k does not converge."""
    n = len(x)
    trial = np.repeat(x[:, None], 2 * n + 1, axis=1)
    idx = np.arange(n)
    trial[idx, 1 + 2 * idx] += FOLD_DELTA
    trial[idx, 2 + 2 * idx] -= FOLD_DELTA
    res = _fold_residual(e, k, node, direction, trial, border)
    if res is None:
        return None, None
    return res[:, 0], (res[:, 1::2] - res[:, 2::2]) / (2 * FOLD_DELTA)


def _fold_residual(e: Engine, k: int, node: _Node, direction: np.ndarray, x: np.ndarray, border):
    """Augmented residual (m + 1, B) at trial points x = (scaled q_k, s) (m + 1, B): block k's scaled
    closure residuals and `_bordered`'s g. The blocks before k, regular here, are solved at
    φ = node.φ + s·direction by Newton from the node; None if one does not converge."""
    bp = e.blocks[k]
    batch = x.shape[1]
    phi = node.phi[None, :] + x[-1][:, None] * direction[None, :]
    pose = Pose(batch)
    pose.set_ground(e.mech.ground)
    q_in = e._input_vars(phi)
    for before, q in zip(e.blocks[:k], node.q[:k]):
        if not e._newton(before, pose, np.repeat(q[:, None], batch, axis=1), q_in).ok.all():
            return None
    caches, cut_caches, res = e._block_pose(bp, pose, x[:-1] / bp.var_scale[:, None], q_in)
    jac, _ = e._block_jacobian(bp, caches, cut_caches, batch)
    jac = jac * bp.row_scale[:, None, None] / bp.var_scale[None, :, None]
    return np.vstack([res * bp.row_scale[:, None], _bordered(jac, *border)[None]])


def _limit_kind(e: Engine, bp: BlockPlan, sol: Solution) -> str:
    """'stretched' or 'folded' at the revolute joint where two links of the block line up."""
    best = None
    revolute = [j for j in e.mech.joints.values() if j.kind == "R"]
    for j in revolute:
        a, b = j.links
        if a not in bp.links and b not in bp.links:
            continue
        for ja in (o for o in revolute if a in o.links and o.name != j.name):
            for jb in (o for o in revolute if b in o.links and o.name != j.name):
                pa = _world(sol.pose, a, ja.at) - _world(sol.pose, a, j.at)
                pb = _world(sol.pose, b, jb.at) - _world(sol.pose, b, j.at)
                norm = np.linalg.norm(pa) * np.linalg.norm(pb)
                if norm == 0:
                    continue
                cross = abs(pa[0] * pb[1] - pa[1] * pb[0]) / norm
                if best is None or cross < best[0]:
                    shape = "folded" if np.dot(pa, pb) > 0 else "stretched"
                    best = (cross, f"{shape} at {j.name} ({ja.name}, {j.name}, {jb.name} in line)")
    return best[1] if best is not None and best[0] < 1e-3 else "singular position (dead point)"


def _world(pose: Pose, link: str, at) -> np.ndarray:
    return pose.r[link][:, 0] + pose.rot(link, np.array(at, float))[:, 0]


def _solve_along(e: Engine, phi: np.ndarray) -> Solution:
    """Batch solve on the drawn branch: predict from the atlas, correct, check, walk the rest."""
    if len(e.inputs) != 1:
        return _solve_sequence(e, phi)
    atlas = e.atlas()
    x = phi[:, 0]
    atlas.cover(float(x.min()), float(x.max()))
    nodes_phi, per_block, node_signs = atlas.arrays()
    inside = np.ones(len(x), bool)
    if atlas.limits[+1] is not None:
        inside &= x <= nodes_phi[-1]
    if atlas.limits[-1] is not None:
        inside &= x >= nodes_phi[0]
    idx = _nearest(nodes_phi, x)
    with np.errstate(invalid="ignore", over="ignore"):
        guesses = _interpolate(nodes_phi, per_block, x, idx, inside)
    sol = e._solve_batch(phi, guesses)
    at_crossing = _in_brackets(atlas.crossings, x) & inside
    good = sol.valid & inside & (np.all(e.signs(sol) == node_signs[idx], axis=1) | at_crossing)
    for state, g, bp in zip(sol.blocks, guesses, e.blocks):
        if bp.m:
            dist = np.max(np.abs(state.q - g) * bp.var_scale[:, None], axis=0)
            good &= (dist <= MAX_CORRECTION) & ((dist <= CROSS_DIST) | ~at_crossing)
    if at_crossing.any():
        rows = np.flatnonzero(at_crossing)
        sol.given_rates = (rows, _hermite_rates(nodes_phi, per_block, x[rows]))
    retry = np.flatnonzero(~good & inside & ~at_crossing)
    if len(retry):
        good[retry] = _repair(e, sol, retry, idx, atlas)
    sol.valid = good
    sol.limits, sol.crossings = met_along(atlas, float(x.min()), float(x.max()))
    return sol


def met_along(atlas: _Atlas, lo: float, hi: float) -> tuple[list, list]:
    """The limits and change points of the atlas that a batch of one input from lo to hi runs into."""
    # only the limits this batch ran into: a row past the atlas' last node towards a limit is left out
    # because of it, even a row short of the located limit (the walk's last node can be a few H_MIN
    # short of a fold); the atlas may know limits beyond the range asked for
    grid = atlas.arrays()[0]
    past = {-1: lo < grid[0], +1: hi > grid[-1]}
    limits = [atlas.limits[d] for d in (-1, +1) if atlas.limits[d] is not None and past[d]]
    return limits, [c for c in atlas.crossings if lo <= c.phi[0] <= hi]


def _in_brackets(crossings: list, x: np.ndarray) -> np.ndarray:
    """Which of x (B,) lie between the atlas nodes on either side of a change point."""
    out = np.zeros(len(x), bool)
    for c in crossings:
        out |= (x >= c.bracket[0]) & (x <= c.bracket[1])
    return out


def _hermite_rates(grid, per_block, x):
    """q' and q'' (m, R) of every block at x from the derivatives of the atlas' quintic Hermite
    interpolant: the rates at and near a change point, where the Jacobian is singular. The nodes on
    either side are at most `H_CROSS` apart, so the interpolant's error there is ~1e-15."""
    lo = np.clip(np.searchsorted(grid, x) - 1, 0, len(grid) - 2)
    width = grid[lo + 1] - grid[lo]
    t = (x - grid[lo]) / width
    out = []
    for _, _, _, coef in per_block:
        c = coef.take(lo, axis=2)  # (6, m, R)
        d1 = sum(k * c[k] * t ** (k - 1) for k in range(1, 6)) / width
        d2 = sum(k * (k - 1) * c[k] * t ** (k - 2) for k in range(2, 6)) / (width * width)
        out.append((d1, d2))
    return out


def _interpolate(grid, per_block, x, idx, inside):
    """Guess (m, B) of every block's unknowns at x: the quintic Hermite interpolant of q, q', q'' between
    the two atlas nodes around x (error ~ h⁶, below the tolerance on the filled-in atlas), evaluated by
    Horner's rule from the interval's coefficients, or the Taylor expansion about the nearest node where
    x is past the last node."""
    if len(grid) == 1:
        between = np.zeros(len(x), bool)
        lo, t = np.zeros(len(x), int), np.zeros(len(x))
    else:
        lo = np.clip(np.searchsorted(grid, x) - 1, 0, len(grid) - 2)
        left = grid[lo]
        between = inside & (x >= left) & (x <= grid[lo + 1])
        t = np.where(between, (x - left) / (grid[lo + 1] - left), 0.0)
    every = between.all()
    if not every:
        dphi = np.where(inside, x - grid[idx], 0.0)
    out = []
    for q, qd, qdd, coef in per_block:
        if len(grid) > 1:
            c = coef.take(lo, axis=2)  # (6, m, B)
            inner = c[5]
            for k in range(4, -1, -1):
                inner = inner * t + c[k]
        else:
            inner = q.take(lo, axis=1)
        if not every:
            taylor = (q.take(idx, axis=1) + qd.take(idx, axis=1) * dphi
                      + 0.5 * qdd.take(idx, axis=1) * (dphi * dphi))
            inner = np.where(between, inner, taylor)
        out.append(inner)
    return out


def _nearest(grid: np.ndarray, x: np.ndarray) -> np.ndarray:
    if len(grid) == 1:
        return np.zeros(len(x), int)
    idx = np.clip(np.searchsorted(grid, x), 1, len(grid) - 1)
    left = idx - 1
    return np.where(np.abs(x - grid[left]) <= np.abs(x - grid[idx]), left, idx)


def _repair(e: Engine, sol: Solution, rows, idx, atlas) -> np.ndarray:
    """Walk individually to the positions the batch corrector could not trust; returns their validity."""
    ok = np.zeros(len(rows), bool)
    for k, row in enumerate(rows):
        near = int(idx[row])
        other = near + (1 if sol.phi[row, 0] > atlas.nodes[near].phi[0] else -1)
        for start in (near, other):  # from the nearest node, else from the one on x's other side
            if not 0 <= start < len(atlas.nodes):
                continue
            nodes, limit, _ = _walk(e, atlas.nodes[start], sol.phi[row], overshoot=False)
            if limit is None and nodes:
                for state, q in zip(sol.blocks, nodes[-1].q):
                    state.q[:, row] = q
                ok[k] = True
                break
    fixed = e._solve_batch(sol.phi, [s.q for s in sol.blocks])
    sol.pose, sol.blocks = fixed.pose, fixed.blocks
    return ok & fixed.valid[rows]


def _solve_sequence(e: Engine, phi: np.ndarray) -> Solution:
    """Several inputs: walk from the drawn pose through the requested positions in their order."""
    node = _origin(e, np.ones(len(e.inputs)))
    q = [np.zeros((bp.m, len(phi))) for bp in e.blocks]
    reached, limits, passed = np.zeros(len(phi), bool), [], []
    for row, target in enumerate(phi):
        nodes, limit, crossings = _walk(e, node, target, overshoot=False)
        passed += crossings
        if limit is not None:
            limits.append(limit)
            break
        node = nodes[-1] if nodes else node
        for k, qk in enumerate(node.q):
            q[k][:, row] = qk
        reached[row] = True
    sol = e._solve_batch(phi, q)
    sol.valid &= reached
    sol.limits, sol.crossings = limits, passed
    return sol
