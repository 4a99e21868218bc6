"""The kernels' tables and bundles: an engine's blocks and joints as named tuples of arrays (numba takes a
named tuple as one argument, and a kernel reads ``steps.parent[k]``), each field documented with its
shape, built here and only here; the kinematics kernel's inputs, outputs and work arrays as named
bundles too (`SweepIn`, `SweepOut`, `SweepWork`).

They describe the engine in arrays and nothing else: a backend is handed these, never the engine
(`engine._backend`). The compiled kernels (`mbplanar.backends`) read them, and so do the same kernels
run as plain Python.

Codes. `REVOLUTE` and `PRISMATIC` name the joint types (`JointLaw.kind` "R", "P"); a table stores the
boolean `prismatic` rather than the code, so that no kernel compares against a constant of another
file (numba would freeze it into its cache, and an edit here would not reach the cached kernels).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ._higher_tables import CURVE_WORK, HIGHER_CACHE, CurveTables, HigherTables, higher_tables

__all__ = ["REVOLUTE", "PRISMATIC", "StepTables", "CutTables", "BlockTables", "JointTables", "SweepTables",
           "AtlasTables", "SweepIn", "SweepOut", "SweepWork", "SweepJob", "FIELDS", "RATE_FIELDS", "CONTACT_FIELDS",
           "RECORD_ORDER",
           "sweep_tables", "atlas_tables", "record_layout", "work_sizes", "DESIGN_STATUS", "DesignTables", "DesignJob",
           "DesignResult", "kernels_decline"]

REVOLUTE, PRISMATIC = "R", "P"                          # JointLaw.kind, Joint.kind


def kernels_decline(mech, job: str = "kinematics") -> str:
    """Why these tables cannot describe the model `mech` for the kernels of `job` ("" where they can):
    the kinematics, kinetostatics and design kernels hold the laws of every pair (`HigherTables` for the
    higher pairs), so nothing is declined here today; the layers that write requests return what this
    says for the backends' `can_run` to answer (`engine._backend.dispatch`)."""
    return ""


class StepTables(NamedTuple):
    """The tree steps of every block, in solving order (S steps)."""

    prismatic: np.ndarray   # (S,) bool: the step's joint is prismatic (else revolute)
    parent: np.ndarray      # (S,) int: link placed from
    child: np.ndarray       # (S,) int: link placed
    relative: np.ndarray    # (S,) bool: a revolute input joint (its value is relative to the parent)
    var: np.ndarray         # (S,) int: the unknown it reads (global index), −1 for an input
    input: np.ndarray       # (S,) int: the input it reads, −1 for an unknown
    sign: np.ndarray        # (S,) float: ±1, the input's sense along the step
    s0: np.ndarray          # (S, 2) float: the joint's point, drawn
    u0: np.ndarray          # (S, 2) float: the guide's direction, drawn (prismatic; else 0)
    carrier: np.ndarray     # (S,) float: +1 when the parent carries the guide, −1 when the child does


class CutTables(NamedTuple):
    """The cut joints of every block (C cuts), each giving two closure rows."""

    prismatic: np.ndarray   # (C,) bool
    a: np.ndarray           # (C,) int: first link (the carrier of a prismatic cut)
    b: np.ndarray           # (C,) int: second link (the slider)
    s0: np.ndarray          # (C, 2) float: the joint's point, drawn
    n0: np.ndarray          # (C, 2) float: the guide's normal, drawn (prismatic; else 0)


class BlockTables(NamedTuple):
    """Where each of the K blocks' steps, cuts, unknowns and anchors start and end (end exclusive)."""

    step0: np.ndarray       # (K,) int
    step1: np.ndarray       # (K,) int
    cut0: np.ndarray        # (K,) int
    cut1: np.ndarray        # (K,) int
    var0: np.ndarray        # (K,) int: first unknown (global index)
    m: np.ndarray           # (K,) int: number of unknowns
    anchor0: np.ndarray     # (K,) int
    anchor1: np.ndarray     # (K,) int
    anchors: np.ndarray     # (A,) int: the links a block reads but does not place (earlier blocks') whose
    #                         sensitivities an earlier block's Jacobian wrote (the rest are still at rest)
    row_scale: np.ndarray   # (M,) float: every block's residual row scales, concatenated
    var_scale: np.ndarray   # (M,) float: every block's unknown scales, concatenated
    linear: np.ndarray      # (K,) float: a block linear in its unknown (`linear_block`): its Jacobian, else 0


class JointTables(NamedTuple):
    """Every joint of the model (J), for the joint values written per position."""

    prismatic: np.ndarray   # (J,) bool
    a: np.ndarray           # (J,) int: first link (the carrier of a prismatic joint)
    b: np.ndarray           # (J,) int: second link (the slider)
    drawn: np.ndarray       # (J,) float: the joint's value in the drawn pose
    at: np.ndarray          # (J, 2) float: the joint's point, drawn, in the engine's frame (prismatic; else 0)
    u0: np.ndarray          # (J, 2) float: the guide's direction, drawn (prismatic; else 0)


class SweepTables(NamedTuple):
    """An engine as the kinematics kernel reads it (`sweep_tables`): its blocks' steps, cuts and sizes,
    its joints, each link's reference angle `alpha` (L,) in the drawn pose, the input's sense (±1) and
    drawn value (SI), the ground's link index, and the origin `centre` (2,) of the engine's frame
    (`Engine.centre`: the steps', cuts' and joints' points are in that frame; the kernel writes the link
    frames and points in the world's); the higher pairs, whose rows follow their block's cuts, and their
    curves (`higher`, `curves`: `engine._higher_tables`). `cuts` holds the lower pairs only."""

    steps: StepTables
    cuts: CutTables
    blocks: BlockTables
    joints: JointTables
    alpha: np.ndarray
    sense: float
    phi_drawn: float
    ground: int
    centre: np.ndarray
    higher: HigherTables
    curves: CurveTables


class AtlasTables(NamedTuple):
    """The branch atlas of one input with every block's unknowns stacked (`atlas_tables`): the nodes'
    input values `grid` (K,), the quintic Hermite coefficients `coef` (K − 1, 6, M) of every interval
    (t⁰ … t⁵ on t ∈ [0, 1]), each node's determinant signs `signs` (K, n_blocks), `limits` (2,) bool:
    a located motion limit below the first node and above the last, and the change points' brackets
    `brackets` (C, 2), between whose nodes the rates come from the interpolant."""

    grid: np.ndarray
    coef: np.ndarray
    signs: np.ndarray
    limits: np.ndarray
    brackets: np.ndarray


class SweepIn(NamedTuple):
    """What one call of the kinematics kernel solves: input values x (B,) (SI), the input's speed `om`
    and acceleration `ep` (B,); `ep_any`: some ep is not 0; `rates`: the velocities and accelerations
    too; the points on links `p_link` (P,) drawn at `p_at` (P, 2); `offsets` (11,) of the record's
    fields in `RECORD_ORDER` (in float64s; −1: absent)."""

    x: np.ndarray
    om: np.ndarray
    ep: np.ndarray
    ep_any: bool
    rates: bool
    p_link: np.ndarray
    p_at: np.ndarray
    offsets: np.ndarray


class SweepOut(NamedTuple):
    """What the kinematics kernel writes per position b (batch first). An array whose first dimension is
    0 is not written (not asked for). Links (L): angle, w, e (real), wq, eq (analogues: per unit input);
    points (P): xy, v, a (real), vq, aq (analogues), (B, P, 2); joints (J): value, rate, accel (real),
    rate_q, accel_q (analogues); ic (B, L, 2) instantaneous centres (NaN where a link does not turn);
    `rows` (B, R) the per-position record (`FIELDS`, with rates `RATE_FIELDS`, at the offsets of
    `SweepIn.offsets`): the link frames and joints; `valid` (B,): the position is on the branch
    (False: past a located motion limit, nothing written)."""

    angle: np.ndarray
    xy: np.ndarray
    w: np.ndarray
    e: np.ndarray
    v: np.ndarray
    a: np.ndarray
    wq: np.ndarray
    eq: np.ndarray
    vq: np.ndarray
    aq: np.ndarray
    value: np.ndarray
    rate: np.ndarray
    accel: np.ndarray
    rate_q: np.ndarray
    accel_q: np.ndarray
    ic: np.ndarray
    rows: np.ndarray
    valid: np.ndarray


class SweepWork(NamedTuple):
    """The kinematics kernel's work arrays (`new`): pose `ps` (5, L): θ, cos θ, sin θ, r_x, r_y per link;
    rates `rt` (slots, 3, L): ω, v_x, v_y per link, slots 0 … m−1 a block's sensitivities to its
    unknowns, then the velocities, then the accelerations; step and cut caches `sc` (S, 5), `cc` (C, 9);
    the unknowns `q` and their prediction `guess` (M,); a block's Jacobian `jac` (m, m) with its row
    permutation `perm`; four vectors of a block's size (residual, a Jacobian column, a solution, the
    unknowns' velocities); the higher pairs' caches `hc` (H, `HIGHER_CACHE`) and the curves' work vector
    `wk` (`CURVE_WORK`,) (`backends._numba_higher`)."""

    ps: np.ndarray
    rt: np.ndarray
    sc: np.ndarray
    cc: np.ndarray
    q: np.ndarray
    guess: np.ndarray
    jac: np.ndarray
    perm: np.ndarray
    res: np.ndarray
    col: np.ndarray
    sol: np.ndarray
    qd_u: np.ndarray
    hc: np.ndarray
    wk: np.ndarray

    @classmethod
    def new(cls, sizes: tuple) -> "SweepWork":
        """Work arrays for `work_sizes` (steps, cuts, links, unknowns, the largest block's unknowns, higher
        pairs)."""
        n_steps, n_cuts, n_links, m_all, m_max, n_higher = sizes
        vec = lambda n: np.zeros(max(n, 1))  # noqa: E731
        return cls(np.zeros((5, n_links)), np.zeros((m_max + 2, 3, n_links)), np.zeros((max(n_steps, 1), 5)),
                   np.zeros((max(n_cuts, 1), 9)), vec(m_all), vec(m_all), np.zeros((m_max, m_max)),
                   np.zeros(m_max, np.int64), vec(m_max), vec(m_max), vec(m_max), vec(m_max),
                   np.zeros((max(n_higher, 1), HIGHER_CACHE)), np.zeros(CURVE_WORK))


class SweepJob(NamedTuple):
    """A request of the kinematics job (`engine._backend.dispatch`): the engine's `tables`, the `atlas`
    covering the batch, the tolerances `tol` (`KernelTol`), the inputs `inp` and the outputs `out` to
    write, the threads to split the batch over (None: as many as the machine has), the engine's `store`
    where a backend keeps its work arrays and compiled entry, and the batch's `size`."""

    tables: SweepTables
    atlas: AtlasTables
    tol: object
    inp: SweepIn
    out: SweepOut
    threads: int | None
    store: dict
    size: int


# the record of a position, in this order: (name, per link / joint / higher pair, components); `RATE_FIELDS`
# only with rates, `CONTACT_FIELDS` (the higher pairs' contact parameters) only with higher pairs. The
# kinetostatics kernel reads it by offset.
FIELDS = (("th", "L", 1), ("cos", "L", 1), ("sin", "L", 1), ("r", "L", 2), ("value", "J", 1))
RATE_FIELDS = (("wq", "L", 1), ("eq", "L", 1), ("fv", "L", 2), ("fa", "L", 2), ("rate_q", "J", 1),
               ("accel_q", "J", 1))
CONTACT_FIELDS = (("contact", "H", 1),)
RECORD_ORDER = ("th", "cos", "sin", "r", "value", "wq", "eq", "fv", "fa", "rate_q", "accel_q",
                "contact")  # `SweepIn.offsets`


def record_layout(n_links: int, n_joints: int, rates: bool, n_higher: int = 0) -> tuple[np.dtype, np.ndarray]:
    """The structured dtype of the kernel's per-position record and its offsets (`SweepIn.offsets`)."""
    per = {"L": n_links, "J": n_joints, "H": n_higher}
    dtype = np.dtype([(name, float, (per[kind], comp) if comp > 1 else (per[kind],))
                      for name, kind, comp in FIELDS + (RATE_FIELDS if rates else ())
                      + (CONTACT_FIELDS if n_higher else ())])
    offsets = np.array([dtype.fields[n][1] // 8 if n in dtype.names else -1 for n in RECORD_ORDER], np.int64)
    return dtype, offsets


def work_sizes(tables: SweepTables) -> tuple:
    """The sizes `SweepWork.new` takes: steps, cuts, links, unknowns, the largest block's unknowns, higher
    pairs."""
    m = tables.blocks.m
    return (len(tables.steps.parent), len(tables.cuts.a), len(tables.alpha), len(tables.blocks.var_scale),
            max([1] + [int(k) for k in m]), len(tables.higher.ints))


def sweep_tables(engine) -> SweepTables:
    """The engine's `BlockPlan`s, joints and reference angles as the kinematics kernel's tables."""
    idx = engine.link_index
    steps, cuts, blocks, anchors, rows, vars_ = [], [], [], [], [], []
    var0, written = 0, set()
    for bp in engine.blocks:
        placed = {idx[st.child] for st in bp.steps}
        read = ({idx[st.parent] for st in bp.steps} | {idx[n] for law in bp.cuts for n in law.links[:2]}
                | {idx[law.carrier] for law in bp.cuts if law.kind == "gear"})
        mine = sorted((read - placed) & written)
        if bp.m:
            written |= placed
        lower = [law for law in bp.cuts if law.kind in (REVOLUTE, PRISMATIC)]  # (the higher pairs: `higher_tables`)
        blocks.append((len(steps), len(steps) + len(bp.steps), len(cuts), len(cuts) + len(lower), var0, bp.m,
                       len(anchors), len(anchors) + len(mine)))
        anchors += mine
        for st in bp.steps:
            law = st.law
            prismatic = law.kind == PRISMATIC
            steps.append((prismatic, idx[st.parent], idx[st.child], st.relative,
                           -1 if st.var is None else var0 + st.var, -1 if st.input is None else st.input, st.sign,
                           tuple(law.s0), tuple(law.u0) if prismatic else (0.0, 0.0),
                           1.0 if not prismatic or st.parent == law.carrier else -1.0))
        for law in lower:
            prismatic = law.kind == PRISMATIC
            cuts.append((prismatic, idx[law.links[0]], idx[law.links[1]], tuple(law.s0),
                         tuple(law.n0) if prismatic else (0.0, 0.0)))
        rows.extend(bp.row_scale)
        vars_.extend(bp.var_scale)
        var0 += bp.m
    block_cols = [np.array(c, np.int64) for c in zip(*blocks)] if blocks else [np.zeros(0, np.int64)] * 8
    cx, cy = (float(v) for v in engine.centre)  # (the joints' points in the engine's frame, as its laws')
    joints = [(j.kind == PRISMATIC, idx[j.links[0]], idx[j.links[1]], engine.joint_value_drawn[j.name],
               (j.at[0] - cx, j.at[1] - cy) if j.kind == PRISMATIC else (0.0, 0.0),
               tuple(engine.laws[j.name].u0) if j.kind == PRISMATIC else (0.0, 0.0))
              for j in engine.mech.joints.values()]
    alpha = np.array([engine.reference_angle[n] for n in engine.links], float)
    sense = float(engine.inputs[0].sense) if len(engine.inputs) == 1 else 1.0
    return SweepTables(_columns(StepTables, steps), _columns(CutTables, cuts),
                       BlockTables(*block_cols, np.array(anchors, np.int64), np.array(rows, float),
                                   np.array(vars_, float), np.array([linear_block(bp) for bp in engine.blocks], float)),
                       _columns(JointTables, joints), alpha, sense, float(engine.phi_drawn[0]),
                       int(idx[engine.mech.ground]), np.array([cx, cy], float), *higher_tables(engine))


def linear_block(bp) -> float:
    """The Jacobian (unscaled, constant) of a block that is linear in its one unknown, else 0: one tree
    step, a revolute pair's angle, closed by one gear pair (r_a θ_a ± r_b θ_b − (r_a ± r_b) θ_c = 0,
    linear in the angles): the sum of the gear's coefficients of the links that turn with the unknown
    (the step's child). The kinematics kernel solves such a block in one step and its rates without
    sensitivities (`backends._numba_kinematics`)."""
    if bp.m != 1 or len(bp.steps) != 1 or len(bp.cuts) != 1 or bp.cuts[0].kind != "gear":
        return 0.0
    step = bp.steps[0]
    if step.var is None or step.law.kind != REVOLUTE:
        return 0.0
    return float(sum(c for link, c in bp.cuts[0].coef if link == step.child))


def atlas_tables(arrays, limits: tuple, crossings: list) -> AtlasTables:
    """`AtlasTables` of an atlas' `Atlas.arrays()` (grid, per block (q, q', q'', coef), signs), its
    limits' presence (below, above) and its change points."""
    grid, per_block, signs = arrays
    coefs = [coef for _, _, _, coef in per_block if coef.shape[1]]
    coef = (np.ascontiguousarray(np.concatenate(coefs, axis=1).transpose(2, 0, 1)) if coefs
            else np.zeros((max(len(grid) - 1, 0), 6, 0)))
    brackets = np.array([c.bracket for c in crossings], float).reshape(-1, 2)
    return AtlasTables(np.ascontiguousarray(grid, float), coef, np.ascontiguousarray(signs, float),
                       np.array(limits, np.bool_), brackets)


_PAIRS, _FLAGS, _REALS = {"s0", "u0", "n0", "at"}, {"prismatic", "relative"}, {"sign", "carrier", "drawn"}


def _columns(kind, rows: list):
    """A named tuple of contiguous arrays from rows of values in its fields' order: points and directions
    (N, 2) float, flags bool, reals float, indices int64."""
    columns = list(zip(*rows)) if rows else [()] * len(kind._fields)
    out = []
    for name, values in zip(kind._fields, columns):
        if name in _PAIRS:
            out.append(np.array(values, float).reshape(-1, 2))
        else:
            out.append(np.array(values, np.bool_ if name in _FLAGS else float if name in _REALS else np.int64))
    return kind(*out)


# -- the design job (`mbplanar.study`): D designs of one structure × N input values each ---------------
#: per-design status the design kernel returns: analysed, the drawn pose does not close, is singular,
#: the march passes a change point, a position the kernel cannot vouch for (the last two: numpy's)
DESIGN_STATUS = {"ok": 0, "open": 1, "singular": 2, "crossing": 3, "numpy": 4}


class DesignTables(NamedTuple):
    """An engine's kernel tables and, per design (D designs), the constants that differ.

    steps, cuts, blocks: the engine's (`SweepTables`); step_s0, step_u0 (D, S, 2): each tree step's joint
    point and guide direction; cut_s0, cut_n0 (D, C, 2): each cut's point and guide normal; phi0 (D,): the
    drawn input value (SI); reference (D, L): each link's drawn angle; point_at (D, P, 2) and point_link
    (P,): the chosen points, drawn, and their links; link_out (K,): the links whose angle and rates are
    written; higher, curves: the engine's higher pairs and their curves (`SweepTables`; their reals are
    a design's, copied in per design), with per design the pairs' reals higher_reals (D, H, H_REALS),
    the curves' curve_reals (D, K, C_REALS) (`engine._higher_tables.design_reals`) and every unknown's
    drawn value q0 (D, M) (the contact parameters', else 0)."""

    steps: StepTables
    cuts: CutTables
    blocks: BlockTables
    step_s0: np.ndarray
    step_u0: np.ndarray
    cut_s0: np.ndarray
    cut_n0: np.ndarray
    phi0: np.ndarray
    reference: np.ndarray
    point_at: np.ndarray
    point_link: np.ndarray
    link_out: np.ndarray
    higher: HigherTables
    curves: CurveTables
    higher_reals: np.ndarray
    curve_reals: np.ndarray
    q0: np.ndarray


class DesignJob(NamedTuple):
    """A request of the design job (`engine._backend.dispatch`): the designs' `tables`, their input
    values `x` (D, N) (SI), the march parameter's unit `scale` (1 for a revolute input, the mechanism's
    size for a slider), whether the acceleration analogues are wanted, the threads to split the designs
    over, the input's `sense`, the ground's link index, the tolerances (`KernelTol`), per block whether
    its row and unknown scales are uniform, the engine's `store` (a backend's work arrays), and the
    designs' indices in the batch (D,)."""

    tables: DesignTables
    x: np.ndarray
    scale: float
    accelerations: bool
    threads: int | None
    sense: float
    ground: int
    tol: object
    uniform: np.ndarray
    store: dict
    designs: np.ndarray


class DesignResult(NamedTuple):
    """What the design kernel gives per design (D designs × N positions), and the arrays it writes.

    status (D,): `DESIGN_STATUS`; valid (D, N); angle, wq (D, N, K) of the links `link_out`; eq (D, N, K)
    or None (written: (0, 0, K)) without accelerations; xy, vq (D, N, P, 2); aq or None (written: (0, 0,
    P, 2)). Limits per design and direction (index 0: going up, 1:
    going down): limit (D, 2), limit_phi (D, 2) the last node's input value, limit_h (D, 2) the last
    step tried, limit_q, limit_qd, limit_qdd (D, 2, M) the last node's unknowns and their derivatives
    along the march parameter, limit_signs (D, 2, n_blocks)."""

    status: np.ndarray
    valid: np.ndarray
    angle: np.ndarray
    wq: np.ndarray
    eq: np.ndarray | None
    xy: np.ndarray
    vq: np.ndarray
    aq: np.ndarray | None
    limit: np.ndarray
    limit_phi: np.ndarray
    limit_h: np.ndarray
    limit_q: np.ndarray
    limit_qd: np.ndarray
    limit_qdd: np.ndarray
    limit_signs: np.ndarray
