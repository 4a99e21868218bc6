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
           "DesignResult"]

REVOLUTE, PRISMATIC = "R", "P"                          # JointLaw.kind, Joint.kind


class StepTables(NamedTuple):
    """The tree steps of every block, in solving order (S steps): each places a link from its parent.

    Fields, one entry per step (the comments beside them give each one's shape and meaning); points in
    the engine's frame (`Engine.centre`). Made by `sweep_tables`.

    Examples
    --------
    >>> from mbplanar.engine import Engine, sweep_tables
    >>> from mbplanar.model import read_model
    >>> steps = sweep_tables(Engine(read_model("models/slider_crank.toml"))).steps
    >>> steps.parent.tolist(), steps.child.tolist(), steps.var.tolist(), steps.input.tolist()
    ([0, 1, 2], [1, 2, 3], [-1, 0, 1], [0, -1, -1])
    """

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
    """The lower-pair cut joints of every block (C cuts), each giving two closure rows.

    Fields, one entry per cut (shapes beside them). Made by `sweep_tables`.

    Examples
    --------
    >>> from mbplanar.engine import Engine, sweep_tables
    >>> from mbplanar.model import read_model
    >>> cuts = sweep_tables(Engine(read_model("models/slider_crank.toml"))).cuts   # the slider's guide
    >>> cuts.prismatic.tolist(), cuts.a.tolist(), cuts.b.tolist(), cuts.n0.round(6).tolist()
    ([True], [0], [3], [[-0.0, 1.0]])
    """

    prismatic: np.ndarray   # (C,) bool
    a: np.ndarray           # (C,) int: first link (the carrier of a prismatic cut)
    b: np.ndarray           # (C,) int: second link (the slider)
    s0: np.ndarray          # (C, 2) float: the joint's point, drawn
    n0: np.ndarray          # (C, 2) float: the guide's normal, drawn (prismatic; else 0)


class BlockTables(NamedTuple):
    """Where each of the K blocks' steps, cuts, unknowns and anchors start and end (end exclusive).

    Block k's steps are ``steps[step0[k]:step1[k]]``, its cuts ``cuts[cut0[k]:cut1[k]]``, its `m[k]`
    unknowns start at `var0[k]`; `row_scale` and `var_scale` (M,) make its rows and unknowns
    dimensionless. Made by `sweep_tables`.

    Examples
    --------
    >>> from mbplanar.engine import Engine, sweep_tables
    >>> from mbplanar.model import read_model
    >>> blocks = sweep_tables(Engine(read_model("models/slider_crank.toml"))).blocks
    >>> blocks.step0.tolist(), blocks.step1.tolist(), blocks.m.tolist()    # the crank; the dyad, 2 unknowns
    ([0, 1], [1, 3], [0, 2])
    """

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
    """Every joint of the model (J), for the joint values written per position.

    A revolute joint's value is the relative angle of its links (b from a), a prismatic joint's the
    slider's displacement along the guide; `drawn` is the value in the drawn pose. Made by
    `sweep_tables`, in the model's joint order.

    Examples
    --------
    >>> from mbplanar.engine import Engine, sweep_tables
    >>> from mbplanar.model import read_model
    >>> joints = sweep_tables(Engine(read_model("models/slider_crank.toml"))).joints
    >>> joints.prismatic.tolist(), joints.u0[-1].tolist()              # O, A, B and the slider's Bp
    ([False, False, False, True], [1.0, 0.0])
    """

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
    too; the points on links `p_link` (P,) drawn at `p_at` (P, 2); `offsets` (12,) of the record's
    fields in `RECORD_ORDER` (in float64s; −1: absent).

    Examples
    --------
    Two positions of a four-bar (4 links, 4 joints) at 2 rad/s, with rates, for one point on link 2 drawn
    at (0.2, 0.2) (`SweepJob` shows the one `analyse` makes):

    >>> import numpy as np
    >>> from mbplanar.engine import SweepIn, record_layout
    >>> _, offsets = record_layout(4, 4, rates=True)
    >>> inp = SweepIn(np.radians([10.0, 20.0]), np.full(2, 2.0), np.zeros(2), False, True,
    ...               np.array([2]), np.array([[0.2, 0.2]]), offsets)
    >>> len(inp.x), inp.rates, int(inp.offsets[5])                      # wq starts at float 24
    (2, True, 24)
    """

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
    (False: past a located motion limit, nothing written).

    Examples
    --------
    An output not asked for has a first dimension of 0 (`SweepJob` shows the outputs `analyse` asks for):

    >>> import numpy as np
    >>> from mbplanar.engine import SweepOut
    >>> B, L, P, J = 3, 4, 5, 4                                   # positions, links, points, joints
    >>> shapes = {"angle": (B, L), "xy": (B, P, 2), "rows": (B, 0), "valid": (B,)}
    >>> out = SweepOut(*(np.zeros(shapes.get(name, (0, 1))) for name in SweepOut._fields))
    >>> [name for name in SweepOut._fields if len(getattr(out, name))]      # what the kernel writes here
    ['angle', 'xy', 'rows', 'valid']
    """

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
    `wk` (`CURVE_WORK`,) (`backends._numba_higher`). A backend keeps one per thread.

    Examples
    --------
    >>> from mbplanar.engine import Engine, SweepWork, sweep_tables, work_sizes
    >>> from mbplanar.model import read_model
    >>> work = SweepWork.new(work_sizes(sweep_tables(Engine(read_model("models/slider_crank.toml")))))
    >>> work.ps.shape, work.rt.shape, work.jac.shape                 # 4 links; blocks of at most 2 unknowns
    ((5, 4), (4, 3, 4), (2, 2))
    """

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
    where a backend keeps its work arrays and compiled entry, and the batch's `size`.

    Examples
    --------
    What `analyse` hands a backend, seen by a backend that only looks (numpy then computes the batch):

    >>> import numpy as np
    >>> from mbplanar import analyse
    >>> from mbplanar.engine import Engine
    >>> from mbplanar.model import read_model
    >>> class Look:
    ...     name, seen = "look", []
    ...     def should_run(self, job, size): return True
    ...     def can_run(self, job, request): self.seen.append(request); return "only looking"
    ...     def run(self, job, request): pass
    >>> engine = Engine(read_model("models/fourbar.toml"))
    >>> engine.prepared["backends"] = [Look()]
    >>> motion = analyse(engine, np.radians([10.0, 20.0, 30.0]))
    >>> job = Look.seen[0]
    >>> type(job).__name__, job.size, job.tables.steps.child.tolist(), bool(job.atlas.grid[-1] >= job.inp.x[-1])
    ('SweepJob', 3, [1, 2, 3], True)
    >>> np.degrees(job.inp.x).round(6).tolist(), job.inp.rates              # the inputs (`SweepIn`)
    ([10.0, 20.0, 30.0], True)
    >>> job.out.xy.shape, job.out.wq.shape                  # the outputs (`SweepOut`): wq not asked for here
    ((3, 5, 2), (0, 4))
    """

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
    """The layout of the kinematics kernel's per-position record, which the kinetostatics kernel reads.

    Parameters
    ----------
    n_links, n_joints : int
        L links, J joints.
    rates : bool
        With the rate fields (`RATE_FIELDS`).
    n_higher : int, optional
        H higher pairs (their contact parameters, `CONTACT_FIELDS`).

    Returns
    -------
    dtype : numpy.dtype
        The structured record, float fields in `FIELDS` order.
    offsets : numpy.ndarray
        (12,) int64: each field of `RECORD_ORDER`'s offset in float64s, −1 where absent
        (`SweepIn.offsets`).

    Raises
    ------
    ValueError
        A negative count.

    Examples
    --------
    >>> from mbplanar.engine import record_layout
    >>> dtype, offsets = record_layout(4, 4, rates=False)            # a four-bar: 4 links, 4 joints
    >>> dtype.names, dtype.itemsize // 8
    (('th', 'cos', 'sin', 'r', 'value'), 24)
    >>> offsets.tolist()[:6]                                         # th, cos, sin, r, value; no wq
    [0, 4, 8, 12, 20, -1]
    """
    per = {"L": n_links, "J": n_joints, "H": n_higher}
    dtype = np.dtype([(name, float, (per[kind], comp) if comp > 1 else (per[kind],))
                      for name, kind, comp in FIELDS + (RATE_FIELDS if rates else ())
                      + (CONTACT_FIELDS if n_higher else ())])
    offsets = np.array([dtype.fields[n][1] // 8 if n in dtype.names else -1 for n in RECORD_ORDER], np.int64)
    return dtype, offsets


def work_sizes(tables: SweepTables) -> tuple:
    """The sizes of an engine's kernel work arrays (what `SweepWork.new` takes).

    Parameters
    ----------
    tables : SweepTables
        The engine's tables (`sweep_tables`).

    Returns
    -------
    tuple of 6 int
        Steps, cuts, links, unknowns, the largest block's unknowns (at least 1), higher pairs.

    Raises
    ------
    AttributeError
        Something other than a `SweepTables`.

    Examples
    --------
    >>> from mbplanar.engine import Engine, sweep_tables, work_sizes
    >>> from mbplanar.model import read_model
    >>> work_sizes(sweep_tables(Engine(read_model("models/slider_crank.toml"))))
    (3, 1, 4, 2, 2, 0)
    """
    m = tables.blocks.m
    return (len(tables.steps.parent), len(tables.cuts.a), len(tables.alpha), len(tables.blocks.var_scale),
            max([1] + [int(k) for k in m]), len(tables.higher.ints))


def sweep_tables(engine) -> SweepTables:
    """An engine as the kernels read it: its blocks, joints and reference angles as arrays.

    Parameters
    ----------
    engine : Engine
        The compiled mechanism.

    Returns
    -------
    SweepTables
        ``steps`` (`StepTables`), ``cuts`` (`CutTables`), ``blocks`` (`BlockTables`), ``joints``
        (`JointTables`), each link's reference angle ``alpha`` (L,), the input's ``sense`` and
        ``phi_drawn``, the ``ground``'s index, the engine's ``centre`` (2,) and the higher pairs'
        ``higher`` and ``curves`` (`higher_layout`).

    Raises
    ------
    Nothing on an `Engine`.

    Examples
    --------
    >>> from mbplanar.engine import Engine, sweep_tables
    >>> from mbplanar.model import read_model
    >>> tables = sweep_tables(Engine(read_model("models/slider_crank.toml")))
    >>> len(tables.alpha), tables.ground, tables.centre.tolist(), tables.higher.ints.shape[0]
    (4, 0, [0.0, 0.0], 0)
    """
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
    """The branch atlas as the kernels read it: its nodes and every block's interpolant stacked.

    Parameters
    ----------
    arrays : tuple
        An atlas' `Atlas.arrays()`: grid (K,), per block (q, q', q'', coef), signs (K, n_blocks).
    limits : tuple of 2 bool
        A located motion limit below the first node, above the last.
    crossings : list of Crossing
        The change points (their brackets).

    Returns
    -------
    AtlasTables
        ``grid`` (K,), ``coef`` (K − 1, 6, M), ``signs`` (K, n_blocks), ``limits`` (2,), ``brackets`` (C, 2).

    Raises
    ------
    ValueError
        Arrays of another atlas' layout (numpy's concatenation refuses them).

    Examples
    --------
    >>> from mbplanar.engine import Engine, atlas_tables
    >>> from mbplanar.model import read_model
    >>> atlas = Engine(read_model("models/slider_crank.toml")).atlas()
    >>> atlas.cover(0.0, 1.0)
    >>> tables = atlas_tables(atlas.arrays(), (False, False), atlas.crossings)
    >>> K = len(tables.grid)
    >>> tables.coef.shape == (K - 1, 6, 2), tables.signs.shape == (K, 2), tables.brackets.shape
    (True, True, (0, 2))
    """
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
    the curves' curve_reals (D, K, C_REALS) (`higher_layout.design_reals`) and every unknown's drawn
    value q0 (D, M) (the contact parameters', else 0).

    Examples
    --------
    Every design shares the engine's steps, cuts and blocks and has its own points, guides and drawn input
    (`DesignJob` shows the tables a design batch makes):

    >>> from mbplanar.engine import DesignTables, Engine, sweep_tables
    >>> from mbplanar.model import read_model
    >>> DesignTables._fields[:3] == sweep_tables(Engine(read_model("models/fourbar.toml")))._fields[:3]
    True
    >>> DesignTables._fields[3:8]
    ('step_s0', 'step_u0', 'cut_s0', 'cut_n0', 'phi0')
    """

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
    designs' indices in the batch (D,).

    Examples
    --------
    What a design batch hands a backend, seen by a backend that only looks (numpy then solves it):

    >>> import numpy as np
    >>> from mbplanar.study import design_batch
    >>> class Look:
    ...     name, seen = "look", []
    ...     def should_run(self, job, size): return True
    ...     def can_run(self, job, request): self.seen.append(request); return "only looking"
    ...     def run(self, job, request): pass
    >>> batch = design_batch("models/fourbar_design.toml", {"a": np.array([0.09, 0.10, 0.11])})
    >>> batch.engine.prepared["backends"] = [Look()]
    >>> motion = batch.solve(batch.geometry.phi0[:, None] + np.linspace(0.0, 0.5, 4))
    >>> job = Look.seen[0]
    >>> type(job).__name__, job.x.shape, job.designs.tolist(), job.accelerations
    ('DesignJob', (3, 4), [0, 1, 2], True)
    >>> job.tables.step_s0.shape, np.degrees(job.tables.phi0).round(6).tolist()   # 3 designs, 3 steps each
    ((3, 3, 2), [60.0, 60.0, 60.0])
    """

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
    along the march parameter, limit_signs (D, 2, n_blocks).

    Only the compiled design kernel makes one (``mbplanar[fast]``); the design batch turns it into a
    `DesignMotion`, solving the designs whose status is not "ok" with numpy.

    Examples
    --------
    >>> from mbplanar.engine import DESIGN_STATUS, DesignResult
    >>> DesignResult._fields[:4]
    ('status', 'valid', 'angle', 'wq')
    >>> {code: name for name, code in DESIGN_STATUS.items()}[3]     # a status of 3: a change point passed
    'crossing'
    """

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
