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

import numpy as np

from ._atlas import Atlas, far_span, solve_along, solve_sequence
from ._backend import check as check_backend
from ._blocks import BlockSolver, Solution
from ._constraints import make_law, world_frames
from ._higher import make_higher_law
from ._singular import Crossing, Limit
from ._tolerances import Tolerances
from ..model import Mechanism, assemble, check_far, frame_origin, reference_points, translated
from ..structure import analyse_topology, check_mobility

__all__ = ["Engine", "Solution", "Limit", "Crossing", "solve_positions", "higher_laws", "wheels"]


def higher_laws(mech: Mechanism, centre=(0.0, 0.0)) -> dict:
    """The joint laws of the higher pairs of an assembled mechanism, checked against its drawing
    (`mbplanar.model._drawn`: a `ModelError` names a pair that does not fit), in the engine's frame
    centred on `centre` (`Engine.centre`)."""
    if not mech.higher:
        return {}
    from ..model import drawn_pairs
    world = drawn_pairs(mech)
    if not any(centre):
        return {name: make_higher_law(g) for name, g in world.items()}
    # the curves placed in the engine's frame before they are evaluated, as the joints' laws are
    local = drawn_pairs(translated(mech, (-centre[0], -centre[1])))
    return {name: make_higher_law(g, local[name]) for name, g in world.items()}


def wheels(mech: Mechanism) -> frozenset:
    """The links that are wheels: every revolute joint, point and gear of theirs at one centre, no other
    pair. A wheel's angle places nothing but itself, so it need not come back to whole turns when the
    rest of the mechanism repeats (a gear train of any ratio)."""
    out = set()
    for name in mech.moving_links:
        joints, pairs = mech.joints_of(name), mech.higher_of(name)
        if not joints or any(j.kind != "R" for j in joints) or any(h.kind not in ("gear", "rack") for h in pairs):
            continue
        if any(h.kind == "rack" and h.links[0] != name for h in pairs):
            continue  # the rack itself slides
        centre = joints[0].at
        spots = [j.at for j in joints] + [p.at for p in mech.points.values() if p.link == name]
        if all(p is not None and math.dist(p, centre) <= 1e-9 * (1 + math.hypot(*centre)) for p in spots):
            out.add(name)
    return frozenset(out)


class Engine:
    """A compiled mechanism, ready to solve batches of positions.

    backend: "numpy" (the reference) or "numba", which runs the kinematics and kinetostatics of
    one-input sweeps through compiled per-position loops (`mbplanar.backends._numba_kinematics`,
    `mbplanar.backends._numba_kinetostatics`; needs the optional extra `fast`) and falls back to numpy wherever
    those loops cannot vouch for a position.
    threads: how many cores the compiled loops split a long batch over (default: the cores available,
    or the environment variable MBPLANAR_THREADS); the answers do not depend on it.
    tol: the `Tolerances` of every solver (default `Tolerances()`); both backends read them.
    centre: the origin (world coordinates, (2,)) of the frame it solves in, on the mechanism
    (`model._scale.frame_origin`; 0 near the world's origin), so that what it judges does not depend on
    where the mechanism is drawn; results are in world coordinates.

    The engine answers through the functions that take it: ``analyse(engine, phi)`` for a batch
    (``rates=False`` for positions alone), ``position(engine, phi)`` for one value.

    Examples
    --------
    >>> import numpy as np
    >>> import mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> engine.topology.structure.formula, engine.inputs[0].joint
    ('I(0,1) → II(2,3)', 'O')
    >>> round(float(np.degrees(engine.phi_drawn[0])), 6)        # the drawn crank angle
    60.0
    """

    def __init__(self, mech: Mechanism, grouped: bool = True, backend: str = "numpy", threads: int | None = None,
                 tol: Tolerances | None = None):
        if tol is None:
            tol = Tolerances()
        if not isinstance(tol, Tolerances):
            raise ValueError(f"tol must be a mbplanar.engine.Tolerances, not {tol!r}")
        self.tol = tol
        if threads is not None and (not isinstance(threads, int) or threads < 1):
            raise ValueError(f"threads must be a positive integer, not {threads!r}")
        check_backend(backend)  # (loaded on first use: `engine._backend.candidates`)
        self.threads = threads
        self.backend = backend
        self.prepared: dict = {}  # tables built on first use, by name (`prepare`)
        check_mobility(mech)
        check_far(mech)
        self.mech = assemble(mech)
        self.topology = analyse_topology(self.mech, grouped)
        mech = self.mech
        self.links = mech.all_links
        self.link_index = {name: k for k, name in enumerate(self.links)}
        self.size = max([math.dist(a.at, b.at) for a in mech.joints.values() for b in mech.joints.values()]
                        + [0.0]) or 1.0  # (no floor: every tolerance is relative to it)
        self.centre = frame_origin([j.at for j in mech.joints.values()] or [(0.0, 0.0)], self.size)
        self.laws = {name: make_law(j, self.centre) for name, j in mech.joints.items()}
        self.laws.update(higher_laws(mech, self.centre))
        self.inputs = mech.inputs
        self.reference_angle = {link: self._drawn_link_angle(link) for link in self.links}
        self.phi_drawn = np.array([self._drawn_phi(inp) for inp in self.inputs])
        self.joint_value_drawn = {name: self._drawn_joint_value(name) for name in mech.joints}
        self.solver = BlockSolver(mech, self.laws, self.topology.blocks, self.links, self.size, self.phi_drawn, tol)
        self.solver.wheels = wheels(mech)
        self.blocks = self.solver.blocks
        self._atlas = None

    def with_dimensions(self, mechanism: Mechanism) -> "Engine":
        """This engine re-dimensioned for `mechanism`, a variant of its model (same links, joints,
        points and inputs; other coordinates, lengths, guides or input zero): the topology and Assur
        groups are kept, the drawn pose, joint laws and solving plans rebuilt (a fraction of a new
        `Engine`'s cost). See `mbplanar.engine._dimensions.with_dimensions`."""
        from ._dimensions import with_dimensions

        return with_dimensions(self, mechanism)

    def prepare(self, name: str, make):
        """The engine's table called `name`, made by `make()` on first use and kept (the output tables,
        the kinetostatic plan, a backend's kernel tables, ...)."""
        table = self.prepared.get(name)
        if table is None:
            table = self.prepared[name] = make()
        return table

    def __getstate__(self) -> dict:
        """Pickled without the tables made on first use (`prepared`: kernels' tables, backends, compiled
        entries), which are made again where it is unpickled."""
        state = dict(self.__dict__)
        state["prepared"] = {}
        return state

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

    # -- the façade: block Newton and rates (`_blocks`), continuation (`_atlas`), limits (`_singular`) ----
    def rates(self, sol: Solution, phi_rate, phi_accel) -> Solution:
        """Fill the velocities and accelerations of every link for input rates (B, n_in) and input
        accelerations (B, n_in). With rate 1 and acceleration 0 these are the analogues. The link frames'
        `v`, `a` are in the world convention (as `Motion.frames`); `sol.pose` stays in the engine's frame
        (`centre`)."""
        self.solver.rates(sol, phi_rate, phi_accel)
        if self.centre.any():  # (else the engine's frame is the world's)
            c, s, r = self._link_frames(sol)
            _, v, a = world_frames(self.centre, c, s, r, sol.w.T, sol.v.T, sol.e.T, sol.a.T)
            sol.v, sol.a = v.T, a.T
        return sol

    def _link_frames(self, sol: Solution):
        """cos θ, sin θ (L, B) and the frame origins r (2, L, B) of every link (`links` order) in the
        engine's frame, centred on `centre`."""
        pose, names = sol.pose, self.links
        c, s = np.empty((len(names), len(sol.phi))), np.empty((len(names), len(sol.phi)))
        r = np.empty((2,) + c.shape)
        for k, n in enumerate(names):
            c[k], s[k], r[:, k] = pose.c[n], pose.s[n], pose.r[n]
        return c, s, r

    def dets(self, sol: Solution) -> np.ndarray:
        """Each block's Jacobian determinant (B, n_blocks); 1 for a block without unknowns."""
        return self.solver.dets(sol)

    def signs(self, sol: Solution) -> np.ndarray:
        """Sign of each block's Jacobian determinant (B, n_blocks)."""
        return self.solver.signs(sol)

    def pivots(self, sol: Solution) -> np.ndarray:
        """Smallest pivot ratio over the blocks (B,): near 0 at a singular position."""
        return self.solver.pivots(sol)

    def atlas(self) -> Atlas:
        """The drawn branch's atlas of one input, built on first use and extended on demand."""
        if self._atlas is None:
            self._atlas = Atlas(self.solver)
        return self._atlas

    def _repr_html_(self) -> str:
        """Jupyter: the diagram in the drawn pose beside the structure (DOF, loops, Assur groups)."""
        from ..model import view
        return view("html", self)

    def period(self) -> float | None:
        """The period (rad) of the drawn branch along a single revolute input: one or two turns when
        the mechanism returns to its configuration (relative angles up to whole turns), else None (a
        rocker, a lock, a prismatic input). Walks up to `FAR_TURNS` turns once, then is cached."""
        if len(self.inputs) != 1:
            return None
        found = self.atlas().period()
        return None if found is None else found[0]

    def within_walk(self, lo: float, hi: float) -> bool:
        """Whether input values lo … hi (SI) of a single input lie within the walk's reach from the
        drawn pose, where no period is needed (`FAR_TURNS`, `FAR_SIZES`)."""
        phi0 = float(self.phi_drawn[0])
        return max(abs(lo - phi0), abs(hi - phi0)) <= far_span(self.solver)

    def reach(self) -> tuple[float, float]:
        """The input range (SI) the walk from the drawn pose can vouch for without a period: up to the
        motion limits, or `FAR_TURNS` turns (`FAR_SIZES` sizes for a slider) either way."""
        phi0, span = float(self.phi_drawn[0]), far_span(self.solver)
        atlas = self.atlas()
        atlas.cover(phi0 - span, phi0 + span)
        ends = {d: float(atlas.limits[d].phi[0]) if atlas.limits[d] is not None else phi0 + d * span
                for d in (-1, +1)}
        return ends[-1], ends[+1]

    def solve_limits(self, limits: list) -> Solution:
        """The configurations at the located motion limits among `limits` (those with `Limit.q`), one
        row each: every block is already converged there, so Newton takes no step (which it could not,
        the block at fault being singular). The rates of such a row are meaningless (infinite)."""
        found = [lim for lim in limits if lim.q is not None]
        phi = np.array([lim.phi for lim in found], float).reshape(len(found), len(self.inputs))
        guesses = [np.stack([lim.q[k] for lim in found], axis=1) if found else np.zeros((bp.m, 0))
                   for k, bp in enumerate(self.blocks)]
        sol = self.solver.solve_batch(phi, guesses)
        sol.limits = found
        return sol


def solve_positions(engine: Engine, phi) -> Solution:
    """The engine layer's own positions at a batch of input values, on the drawn branch.

    Numpy only, no rates, no backend: the layers above use it where they need a `Solution`. Users ask
    ``analyse(engine, phi, rates=False)``, which goes through the backend seam.

    Parameters
    ----------
    engine : Engine
        The compiled mechanism.
    phi : array_like
        Input values, SI (rad, or m for a prismatic input): a number, (B,) for one input, (B, n_in) for
        several (or (n_in,), one position).

    Returns
    -------
    Solution
        Positions past a motion limit are left out (`valid` False, `limits` says where).

    Raises
    ------
    ValueError
        The wrong number of values per position, or a value that is not finite.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.engine import Engine, solve_positions
    >>> from mbplanar.model import read_model
    >>> engine = Engine(read_model("models/fourbar.toml"))
    >>> sol = solve_positions(engine, np.radians([0.0, 90.0]))
    >>> sol.valid.tolist(), np.degrees(sol.pose.th["1"]).round(6).tolist()   # crank turned from 60°
    ([True, True], [-60.0, 30.0])
    >>> solve_positions(engine, [np.nan])
    Traceback (most recent call last):
    ValueError: input values must be finite
    """
    phi = np.asarray(phi, dtype=float)
    if phi.ndim == 0:
        phi = phi[None]
    if phi.ndim == 1:
        phi = phi[:, None] if len(engine.inputs) == 1 else phi[None, :]
    if phi.shape[1] != len(engine.inputs):
        raise ValueError(f"expected {len(engine.inputs)} input value(s) per position")
    if not np.all(np.isfinite(phi)):
        raise ValueError("input values must be finite")
    if len(engine.inputs) != 1:
        return solve_sequence(engine.solver, phi)
    return solve_along(engine.atlas(), phi)
