"""Kinetostatics: every joint reaction and the balancing moment (or force) at every input, from one
linear system assembled from the joint table, solved for a batch of positions group by group (`_Plan`):
in each block the force rows are eliminated with their constant ±1 pivots in an order fixed once per
engine, only what is left (the moment rows) is factorised with pivoting, all over the batch axis.

Equations: per moving link ΣFx = 0, ΣFy = 0, ΣM = 0 (moments about a fixed point of the model, the mean of
the drawn joints, divided by the model size so that every row is in newtons), with d'Alembert inertia
loads −m·a_S at the centre S and −I_S·ε, gravity and the model's loads; per prismatic pair one more: no
force along its guide. Unknowns: both components of every pair's reaction, the moment in every
prismatic pair and the balancing moment (force, for a prismatic input) the drive applies at each input.
The system is square (3·moving links + P pairs = 2·pairs + P pairs + DOF).

Sign conventions. The unknown of a pair with links (a, b) is the force and moment on b from a, applied at
the joint (for a prismatic pair at the slider's point; the pair's moment is about that point). Reactions
are reported as F_ij = force ON link i FROM link j, the way seed 000 writes them: a pair with the ground
acts on the moving link (F10, F30, F50); a prismatic pair on its slider from its carrier (F23, F45); a
revolute pair between moving links on its row's first link from its second (F12, F34). The other side
is always the opposite (F21 = −F12). Moments are counter-clockwise positive.
The balancing moment at an input acts on the input joint's second link (on its first, the opposite).

Check: the virtual power of all loads (inertia included) plus the balancing power vanishes for any
velocity field the joints allow. `virtual_power_residual` computes it with the velocity analogues
(real velocities with several inputs), independently of the matrix, relative to Σ(|F|·v_max + |M|·ω_max)
over the loads (v_max, ω_max: the largest point speed and angular speed at that position) plus the
balancing power.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError
from ..engine import dispatch, factor
from ..kinematics import Motion, contact_geometry, material_points
from ._loads import (LoadValue, evaluate_loads, guide_direction, guide_force_size, heavy_links, load_power, needs_numpy,
                     real_frames, world_points)

__all__ = ["Reaction", "Kinetostatics", "kinetostatics", "inertia_loads", "plan_of", "solve_blocks", "input_link",
           "reported_on"]


@dataclass(frozen=True, eq=False)
class Reaction:
    """The reaction in one pair over a batch of B positions (`Kinetostatics.reactions`), SI.

    Attributes
    ----------
    joint : str
        The pair.
    on, source : str
        The link the reaction acts on and the link it comes from (`reported_on`).
    fx, fy : ndarray, shape (B,)
        The force (N).
    moment : ndarray, shape (B,)
        A prismatic pair's moment (N·m); 0 for a revolute pair.
    magnitude, direction_deg : ndarray, shape (B,)
        ‖F‖ (N) and its direction (degrees counter-clockwise from +x, in [0, 360)), from fx, fy.

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians([60.0, 150.0]), omega=10.0)
    >>> r = mbplanar.kinetostatics(engine, motion).reactions["O"]
    >>> r.on, r.source, r.magnitude.round(4), r.direction_deg.round(3)
    ('1', '0', array([46.3426,  5.112 ]), array([204.386,  47.289]))
    """

    joint: str
    on: str
    source: str
    fx: np.ndarray
    fy: np.ndarray
    moment: np.ndarray

    @property
    def magnitude(self) -> np.ndarray:
        return np.hypot(self.fx, self.fy)

    @property
    def direction_deg(self) -> np.ndarray:
        """Direction of the force, degrees counter-clockwise from +x in [0, 360)."""
        return np.degrees(np.arctan2(self.fy, self.fx)) % 360.0


@dataclass(frozen=True, eq=False)
class Kinetostatics:
    """Reactions and balancing loads over a batch of B positions (those of `motion`), SI.

    Attributes
    ----------
    motion : Motion
        The positions.
    reactions : dict of str to Reaction
        Joint name → its reaction (as reported: on the moving link for pairs with the ground); a higher
        pair's name → its contact force on its second link from its first.
    balancing : dict of str to ndarray (B,)
        Input joint name → the moment (N·m) or force (N) the drive applies to the input link.
    virtual_power_residual : ndarray (B,)
        Relative residual of the virtual-power balance.
    loads : list of LoadValue
        What acted (the model's loads, gravity, the d'Alembert loads).
    singular : ndarray (B,) of bool
        Positions where the force system is singular (their reactions NaN).
    contact_forces : dict of str to ndarray (B,)
        Higher pair name → the signed size of its force along its direction (N): a cam's or a slot's
        normal force on the second link along the normal out of the first (< 0: it would pull), a
        gear's or a rack's tangential force on the second link along the tangent; empty without higher
        pairs.
    pulling : dict of str to ndarray (B,) of bool
        Cam pair name → where its contact force would pull the follower onto the cam: the contact needs
        force closure there (a spring, a preload, gravity) or the follower leaves the cam.
    success : bool
        No position is singular and no cam's contact force pulls.
    message : str
        "solved", or where the system is singular and where a cam's contact would pull.

    Examples
    --------
    >>> import numpy as np
    >>> import mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> k = mbplanar.kinetostatics(engine, mbplanar.analyse(engine, np.radians([60.0]), omega=10.0))
    >>> reaction = k.reactions["B"]                     # on link 2 from link 3
    >>> reaction.on, reaction.source, round(float(reaction.fx[0]), 4), round(float(reaction.fy[0]), 4)
    ('2', '3', 25.9117, 28.9839)
    """

    motion: Motion
    reactions: dict
    balancing: dict
    virtual_power_residual: np.ndarray
    loads: list = field(default_factory=list)
    singular: np.ndarray | None = None
    contact_forces: dict = field(default_factory=dict)
    pulling: dict = field(default_factory=dict)
    success: bool = True
    message: str = "solved"

    def __repr__(self) -> str:
        return (f"Kinetostatics({len(self.motion.phi)} positions, reactions at {', '.join(self.reactions)}, "
                f"balancing at {', '.join(self.balancing)}, success={self.success}, message={self.message!r})")

    def reaction(self, joint: str) -> Reaction:
        return self.reactions[joint]

    def to_frame(self):
        """A pandas DataFrame, one row per position: the input, then the force columns of `mbplanar sweep`
        (``A.fx[N]``, ``O.balancing[N*m]``, ``virtual_power_residual``). Needs pandas."""
        from ..model import view
        return view("frame", self)

    def _repr_html_(self) -> str:
        from ..model import view
        return view("html", self)


# -- kinematics of the link frames ------------------------------------------------------------------
def _frames_of(motion):
    """The motion's link frames with rates, or ModelError: the forces need them."""
    f = motion.frames
    if f is None or f.w is None:
        raise ModelError("kinetostatics needs the motion's link frames and rates: analyse(engine, phi) with "
                         "rates=True and 'frames' among its outputs (the default)", where="kinetostatics")
    return f


def _virtual_frames(engine, motion):
    """Virtual velocities (w, v) of every link frame: the analogues with one input, else real."""
    f = _frames_of(motion)
    return f.w, f.v


def input_link(engine, inp) -> tuple[str, str]:
    """(input link, the other link) of an input joint: its second link unless that is the ground. The
    balancing load is reported on the input link.

    Parameters
    ----------
    engine : Engine
        The mechanism.
    inp : Input
        One of its inputs (`Engine.inputs`).

    Returns
    -------
    tuple of str
        (the input link, the other link of the input's joint).

    Raises
    ------
    KeyError
        An input of another model.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.forces import input_link
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> input_link(engine, engine.inputs[0])
    ('1', '0')
    """
    j = engine.mech.joints[inp.joint]
    a, b = j.links
    return (a, b) if b == engine.mech.ground else (b, a)


def inertia_loads(engine, motion, input_inertia=0.0) -> list[LoadValue]:
    """d'Alembert loads: −m·a_S at the centre and −I_S·ε on every link with mass or inertia, and
    −J_I·ε (−J_I·a along the guide for a prismatic input) on each input link for `input_inertia` J_I.

    Parameters
    ----------
    engine : Engine
        The mechanism.
    motion : Motion
        Positions with their real rates (batch B).
    input_inertia : float or array_like
        J_I per input (kg·m², or kg for a prismatic input), one value or one per input; 0: none.

    Returns
    -------
    list of LoadValue
        One per link with mass or inertia ("inertia of 2"), then one per input with J_I ("input
        inertia on 1").

    Raises
    ------
    ValueError
        More `input_inertia` values than inputs.

    Examples
    --------
    The coupler of the loaded four-bar (2 kg, 0.015 kg·m²) at 10 rad/s:

    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians([60.0, 150.0]), omega=10.0)
    >>> from mbplanar.forces import inertia_loads
    >>> coupler = inertia_loads(engine, motion)[0]
    >>> coupler.name, coupler.force.round(4), coupler.moment.round(5)
    ('inertia of 2', array([[ 16.2965,   9.7699],
           [-13.6444,   5.5727]]), array([-0.48809, -0.28547]))
    >>> [ld.name for ld in inertia_loads(engine, motion, input_inertia=0.5)]
    ['inertia of 2', 'inertia of 3', 'input inertia on 1']
    """
    mech = engine.mech
    heavy = heavy_links(mech)
    ks = np.array([engine.link_index[name] for name, _, _ in heavy], int)
    out = []
    batch = len(motion.phi)
    if heavy:
        w, v, e, a = real_frames(engine, motion, ks)
        at = np.array([centre for _, _, centre in heavy], float)
        th, r = motion.frames.th[:, ks], motion.frames.r[:, ks]
        xy, _, acc = material_points(th, r, w, v, e, a, np.arange(len(ks)), at)
        for i, ((name, lk, _), k) in enumerate(zip(heavy, ks)):
            out.append(LoadValue(f"inertia of {name}", int(k), -lk.mass * acc[:, i], xy[:, i],
                                 -lk.inertia * e[:, i]))
    inertias = np.broadcast_to(np.asarray(input_inertia, float), (len(engine.inputs),))
    for inp, J in zip(engine.inputs, inertias):
        if not J:
            continue
        link, _ = input_link(engine, inp)
        k = engine.link_index[link]
        jt = mech.joints[inp.joint]
        kj = motion.joint(inp.joint)
        if jt.kind == "R":
            point = world_points(motion, k, np.asarray(jt.at))
            out.append(LoadValue(f"input inertia on {link}", k, np.zeros((batch, 2)), point,
                                 -J * motion.e[:, k]))
        else:
            sign = 1.0 if link == jt.slider else -1.0
            u = guide_direction(engine, motion, inp.joint)
            point = world_points(motion, engine.link_index[jt.slider], np.asarray(jt.at))
            force = -J * sign * motion.accel[:, kj, None] * u
            out.append(LoadValue(f"input inertia on {link}", k, force, point, np.zeros(batch)))
    return out


# -- the assembled system ---------------------------------------------------------------------------
@dataclass
class _Layout:
    """Row and column numbering of the system."""

    rows: dict            # moving link index → first of its 3 rows
    p_rows: dict          # P joint name → its row
    cols: dict            # joint name → first column (fx, fy[, moment])
    in_cols: list         # input k → column
    scale: np.ndarray     # (n,) unknown as reported = x · scale (the sign turns a pair's unknown round
    size: int             # where the reaction is reported on its first link, see `reported_on`)


def _layout(engine) -> _Layout:
    mech = engine.mech
    L = engine.size
    rows, p_rows, cols, scale = {}, {}, {}, []
    n = 0
    for name in mech.moving_links:
        rows[engine.link_index[name]] = n
        n += 3
    for j in mech.joints.values():
        if j.kind == "P":
            p_rows[j.name] = n
            n += 1
    c = 0
    for j in mech.joints.values():
        cols[j.name] = c
        sign = 1.0 if reported_on(mech, j)[0] == j.links[1] else -1.0
        scale += [sign, sign] + ([sign * L] if j.kind == "P" else [])
        c += 3 if j.kind == "P" else 2
    for h in mech.higher:  # a higher pair: the size of its force along its direction (`_pair_directions`)
        cols[h] = c
        scale.append(1.0)
        c += 1
    in_cols = []
    for inp in engine.inputs:
        in_cols.append(c)
        scale.append(L if mech.joints[inp.joint].kind == "R" else 1.0)
        c += 1
    return _Layout(rows, p_rows, cols, in_cols, np.array(scale), n)


@dataclass
class _Plan:
    """The structure of the system, computed once per engine.

    Every matrix entry is `coef · feature[f]`, the features being per-position scalars (B, F):
    feature 0 is 1; then, per pair, the lever (point − centre)/L of its force (x, y); per prismatic pair
    its guide direction (x, y); per prismatic input the lever of the guide force, cross(d, u).
    `blocks` lists the `_Block`s in back-substitution order. Solving the blocks of the engine from the
    last group to the input links is exact: a joint's reaction (and an input's balancing load) belongs to
    the later of its two links' blocks, so the system is block triangular; each Assur group is statically
    determinate on its own. If a block is not square, the whole system is one block.
    """

    lay: _Layout
    centre: np.ndarray
    joints: list          # names of the joints whose force point is a feature, in feature order
    guides: list          # prismatic joint names whose guide direction is a feature
    p_inputs: list        # (guide index, joint index) of prismatic inputs (cross feature)
    blocks: list
    higher: list = field(default_factory=list)  # higher pairs: direction (x, y) and lever of their force


def _entries(engine, lay):
    """Every non-zero of the system as (row, col, feature, coef), and the feature tables."""
    mech = engine.mech
    jnames = list(mech.joints)
    jindex = {n: k for k, n in enumerate(jnames)}
    guides = [n for n in jnames if mech.joints[n].kind == "P"]
    gindex = {n: k for k, n in enumerate(guides)}
    nj = len(jnames)
    dx = lambda j: 1 + 2 * jindex[j]  # noqa: E731  (feature of the lever's x; y is the next one)
    ux = lambda j: 1 + 2 * nj + 2 * gindex[j]  # noqa: E731
    p_inputs, out = [], []

    def wrench(link, col, sign, force=None, moment=0.0, joint=None, cross=None):
        """Column `col` as a force (unit x, unit y, or the guide of `force`) at the joint plus a moment."""
        row = lay.rows.get(link)
        if row is None:
            return
        if force == "x":
            out.extend([(row, col, 0, sign), (row + 2, col, dx(joint) + 1, -sign)])
        elif force == "y":
            out.extend([(row + 1, col, 0, sign), (row + 2, col, dx(joint), sign)])
        elif force == "guide":
            out.extend([(row, col, ux(joint), sign), (row + 1, col, ux(joint) + 1, sign),
                        (row + 2, col, cross, sign)])
        if moment:
            out.append((row + 2, col, 0, sign * moment))

    for j in mech.joints.values():
        ia, ib = (engine.link_index[n] for n in j.links)
        c = lay.cols[j.name]
        for link, sign in ((ib, 1.0), (ia, -1.0)):
            wrench(link, c, sign, "x", joint=j.name)
            wrench(link, c + 1, sign, "y", joint=j.name)
            if j.kind == "P":
                wrench(link, c + 2, sign, moment=1.0)
        if j.kind == "P":
            out.extend([(lay.p_rows[j.name], c, ux(j.name), 1.0), (lay.p_rows[j.name], c + 1, ux(j.name) + 1, 1.0)])
    n_features = 1 + 2 * nj + 2 * len(guides)
    n_cross = sum(1 for inp in engine.inputs if mech.joints[inp.joint].kind == "P")
    for k, h in enumerate(mech.higher.values()):
        f = n_features + n_cross + 3 * k  # the force's direction (x, y), its lever about the centre
        c = lay.cols[h.name]
        for link, sign in ((engine.link_index[h.links[1]], 1.0), (engine.link_index[h.links[0]], -1.0)):
            row = lay.rows.get(link)
            if row is not None:
                out.extend([(row, c, f, sign), (row + 1, c, f + 1, sign), (row + 2, c, f + 2, sign)])
    for inp, col in zip(engine.inputs, lay.in_cols):
        j = mech.joints[inp.joint]
        ia, ib = (engine.link_index[n] for n in j.links)
        cross = None
        if j.kind == "P":
            cross = n_features + len(p_inputs)
            p_inputs.append((gindex[j.name], jindex[j.name]))
        for link, sign in ((ib, 1.0), (ia, -1.0)):
            if j.kind == "R":
                wrench(link, col, sign, moment=1.0)
            else:
                wrench(link, col, sign, "guide", joint=j.name, cross=cross)
    assert len({(r, c) for r, c, _, _ in out}) == len(out), "one entry per (row, column)"
    return out, jnames, guides, p_inputs


def _owners(engine, lay):
    """Block of every row and column: a link's rows in its block; a joint's columns (and its prismatic
    row, and the balancing column of an input at it) in the later block of its two links."""
    block_of = {engine.link_index[n]: k for k, b in enumerate(engine.blocks) for n in b.links}
    mech = engine.mech
    row_block, col_block = np.zeros(lay.size, int), np.zeros(lay.size, int)
    for link, row in lay.rows.items():
        row_block[row:row + 3] = block_of[link]
    owner = {}
    for j in mech.joints.values():
        owner[j.name] = max(block_of.get(engine.link_index[n], -1) for n in j.links)
        c = lay.cols[j.name]
        col_block[c:c + (3 if j.kind == "P" else 2)] = owner[j.name]
        if j.kind == "P":
            row_block[lay.p_rows[j.name]] = owner[j.name]
    for h in mech.higher.values():
        col_block[lay.cols[h.name]] = max(block_of.get(engine.link_index[n], -1) for n in h.links)
    for inp, col in zip(engine.inputs, lay.in_cols):
        col_block[col] = owner[inp.joint]
    return row_block, col_block


def plan_of(engine) -> _Plan:
    """The structure of an engine's equilibrium system, made once per engine and kept on it: the layout
    of rows (three per moving link, one per prismatic pair) and unknowns (per pair its force, a prismatic
    pair's moment too, per higher pair the size of its force, per input its balancing load), the
    features its entries are made of, and its blocks in back-substitution order (the Assur groups, last
    first). It depends on the topology, not on the dimensions: a design batch reuses it (`solve_blocks`).

    Parameters
    ----------
    engine : Engine
        The mechanism.

    Returns
    -------
    _Plan
        A record: `lay` (`rows`: link index → its first row; `cols`: pair → its first unknown; `in_cols`: each
        input's unknown; `scale`: unknown as reported = x · scale; `size`: n), `centre` (2,) the moment
        centre (the mean of the drawn joints), `joints` and `guides` (the pairs whose lever and the
        prismatic pairs whose guide direction are features), `p_inputs`, `blocks`, `higher`.

    Raises
    ------
    Nothing for an `Engine`.

    Examples
    --------
    The four-bar: 9 unknowns (two per pair, one balancing moment) in 9 rows, two blocks (the dyad B
    solved first, then the crank):

    >>> import mbplanar
    >>> from mbplanar.forces import plan_of
    >>> plan = plan_of(mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml")))
    >>> plan.lay.size, plan.lay.rows, plan.lay.in_cols, plan.joints, len(plan.blocks)
    (9, {1: 0, 2: 3, 3: 6}, [8], ['O', 'A', 'B', 'C'], 2)
    """
    return engine.prepare("kinetostatic plan", lambda: _plan(engine))


def _plan(engine) -> _Plan:
    """Layout, features and block order of an engine's system."""
    mech = engine.mech
    lay = _layout(engine)
    entries, jnames, guides, p_inputs = _entries(engine, lay)
    row_block, col_block = _owners(engine, lay)
    ids = sorted(set(row_block))
    square = all(np.sum(row_block == k) == np.sum(col_block == k) for k in ids)
    if not square:
        row_block[:], col_block[:], ids = 0, 0, [0]
    blocks = []
    for k in reversed(ids):
        rows = np.flatnonzero(row_block == k)
        own = np.flatnonzero(col_block == k)
        local_row = {r: i for i, r in enumerate(rows)}
        local_col = {c: i for i, c in enumerate(own)}
        mine = [e for e in entries if e[0] in local_row]
        inside = [(local_row[r], local_col[c], f, coef) for r, c, f, coef in mine if c in local_col]
        later = [(local_row[r], c, f, coef) for r, c, f, coef in mine if c not in local_col]
        blocks.append(_block(rows, own, inside, later))
    centre = np.mean([j.at for j in mech.joints.values()], axis=0)
    return _Plan(lay, centre, jnames, guides, p_inputs, blocks, list(mech.higher))


@dataclass
class _Block:
    """One block of the system: its global rows and (own) columns, the entries (local row, local
    column, feature, coef) among them, the entries on columns solved earlier (local row, global column,
    feature, coef), and the elimination order fixed once per engine: `pivots` (row, column) whose entry
    is a constant (±1 on a force column of a force row), then the rows and columns left (`rest_rows`,
    `rest_cols`, typically the moment rows of a group) solved densely with partial pivoting. `fill`, per
    pivot, the structure its elimination touches: (the live rows that have its column, the other columns
    of its row), fill-in included (the compiled kinetostatics lists its operations from it)."""

    rows: np.ndarray
    own: np.ndarray
    entries: list
    later: list
    pivots: list
    rest_rows: list
    rest_cols: list
    fill: list = field(default_factory=list)


def _block(rows, own, entries, later) -> _Block:
    """Choose the constant pivots of a block (least fill-in first) on its structure: a value is a
    number when the entry is the same at every position, None when it varies."""
    table = [{} for _ in rows]
    for i, j, f, coef in entries:
        table[i][j] = coef if f == 0 else None
    pivots, fill, live = [], [], set(range(len(rows)))
    while True:
        counts = {}
        for i in live:
            for j in table[i]:
                counts[j] = counts.get(j, 0) + 1
        best = min((((len(table[i]) - 1) * (counts[j] - 1), i, j) for i in live for j, v in table[i].items()
                    if v is not None and abs(v) >= 0.5), default=None)
        if best is None:
            break
        _, i, j = best
        live.discard(i)
        fill.append(([k for k in sorted(live) if j in table[k]], [jj for jj in table[i] if jj != j]))
        _eliminate(table, live, i, j, lambda a, m, b: None if None in (a, m, b) else a - m * b)
        pivots.append((i, j))
    done = {j for _, j in pivots}
    rest_cols = [j for j in range(len(own)) if j not in done]
    return _Block(rows, own, entries, later, pivots, sorted(live), rest_cols, fill)


def _eliminate(table, live, i, j, update):
    """Eliminate column j from the live rows of `table` (dicts column → value) with pivot row i; `update`
    (old, multiplier, pivot-row value) → new value. Returns the multipliers {row: m}."""
    pivot, out = table[i][j], {}
    for k in live:
        if j not in table[k]:
            continue
        a = table[k].pop(j)
        m = out[k] = None if a is None or pivot is None else a / pivot
        for jj, v in table[i].items():
            if jj != j:
                table[k][jj] = update(table[k].get(jj, 0.0), m, v)
    return out


def _solve_block(blk: _Block, features, b, x, perms: list | None = None):
    """Solve one block into x (n, B) (batch last), the earlier columns known; returns its singularity
    measure (B,): |det| / Π‖row‖ (Hadamard's ratio, 1 for orthogonal rows, 0 when singular). `perms`:
    a list that gets the row order (n, B) its dense part's LU ended with, where it has one."""
    table = [{} for _ in blk.rows]
    for i, j, f, coef in blk.entries:
        table[i][j] = coef if f == 0 else coef * features[f]
    norm2 = 1.0  # Π‖row‖²
    for row in table:
        norm2 = norm2 * sum(v * v for v in row.values())
    rhs = [b[r] for r in blk.rows]
    for i, c, f, coef in blk.later:
        rhs[i] = rhs[i] - (coef if f == 0 else coef * features[f]) * x[c]
    live = set(range(len(blk.rows)))
    det = 1.0
    for i, j in blk.pivots:
        live.discard(i)
        for k, m in _eliminate(table, live, i, j, lambda a, m, v: a - m * v).items():
            rhs[k] = rhs[k] - m * rhs[i]
        det = det * table[i][j]
    own, batch = blk.own, b.shape[1]
    if blk.rest_rows:
        n = len(blk.rest_rows)
        a = np.empty((n, n, batch))
        for p, i in enumerate(blk.rest_rows):
            for q, j in enumerate(blk.rest_cols):
                a[p, q] = table[i].get(j, 0.0)
        f = factor(a)
        if perms is not None and hasattr(f, "perm"):
            perms.append(f.perm)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            x[own[blk.rest_cols]] = f.solve(np.array([rhs[i] for i in blk.rest_rows]))
        det = det * f.det
    for i, j in reversed(blk.pivots):
        acc = rhs[i]
        for jj, v in table[i].items():
            if jj != j:
                acc = acc - v * x[own[jj]]
        x[own[j]] = acc / table[i][j]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.broadcast_to(np.abs(det) / np.sqrt(norm2), (batch,))


def _features(engine, motion, plan, directions: dict | None = None):
    """The per-position scalars (F, B) (batch last) the entries of the system are made of (`directions`:
    the higher pairs' `pair_directions`, when already made)."""
    L = engine.size
    th = motion.frames.th.T  # (L, B) view
    # the joints' points are the motion's own (a revolute pair's point is common to both its links)
    xy = motion.xy[:, [motion.point(name) for name in plan.joints]].transpose(2, 1, 0)  # (2, J, B)
    n_joints, n_guides, batch = xy.shape[1], len(plan.guides), th.shape[1]
    out = np.empty((1 + 2 * n_joints + 2 * n_guides + len(plan.p_inputs) + 3 * len(plan.higher), batch))
    out[0] = 1.0
    lever_x, lever_y = out[1:1 + 2 * n_joints:2], out[2:2 + 2 * n_joints:2]
    lever_x[:] = (xy[0] - plan.centre[0]) / L
    lever_y[:] = (xy[1] - plan.centre[1]) / L
    if n_guides:
        base = 1 + 2 * n_joints
        carriers = np.array([engine.link_index[engine.mech.joints[n].carrier] for n in plan.guides])
        u0 = np.array([engine.laws[n].u0 for n in plan.guides])
        tc = th[carriers]
        c, s = np.cos(tc), np.sin(tc)
        ux, uy = out[base:base + 2 * n_guides:2], out[base + 1:base + 2 * n_guides:2]
        ux[:] = c * u0[:, 0, None] - s * u0[:, 1, None]
        uy[:] = s * u0[:, 0, None] + c * u0[:, 1, None]
        for k, (g, j) in enumerate(plan.p_inputs):
            out[base + 2 * n_guides + k] = lever_x[j] * uy[g] - lever_y[j] * ux[g]
    if plan.higher:
        base = 1 + 2 * n_joints + 2 * n_guides + len(plan.p_inputs)
        for k, (point, d) in enumerate((directions or pair_directions(engine, motion)).values()):
            out[base + 3 * k] = d[:, 0]
            out[base + 3 * k + 1] = d[:, 1]
            out[base + 3 * k + 2] = ((point[:, 0] - plan.centre[0]) * d[:, 1] - (point[:, 1] - plan.centre[1]) * d[:, 0]) / L
    return out


def pair_directions(engine, motion) -> dict:
    """Per higher pair (point (B, 2), unit direction (B, 2)) of the force its unknown stands for: a gear's or
    a rack's tangential force at the pitch point (its radial part follows from it, `_radial_loads`), a cam's
    or a slot's normal force at the contact."""
    return _directions(contact_geometry(engine, motion))


def _directions(geometry: dict) -> dict:
    """`pair_directions` of the contacts' `geometry` (`contact_geometry`)."""
    return {name: (g.point, g.tangent if g.kind in ("gear", "rack") else g.normal) for name, g in geometry.items()}


def pivot_orders(engine, motion) -> dict:
    """Per block whose dense part LU factorises (3 rows or more; index in `plan_of(engine).blocks`): the
    order of its `rest_rows` that partial pivoting ended with at most of the positions of `motion` (a
    tuple; the row of the first pivot first). Pivoting depends on the matrix alone, not on the loads.
    The compiled kinetostatics lists the rows in this order, so that its pivot steps seldom swap rows:
    partial pivoting chooses the same pivots whatever order the rows start in (but for ties), so the
    numbers do not change."""
    plan = plan_of(engine)
    batch = len(motion.phi)
    features, zero = _features(engine, motion, plan), np.zeros((plan.lay.size, batch))
    x, out = np.zeros((plan.lay.size, batch)), {}
    for i, blk in enumerate(plan.blocks):
        perms = []
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            _solve_block(blk, features, zero, x, perms)
        if perms and batch:
            orders, counts = np.unique(perms[0].T, axis=0, return_counts=True)
            out[i] = tuple(int(v) for v in orders[np.argmax(counts)])
    return out


def solve_blocks(plan, features, b, threshold: float):
    """Back-substitution over the blocks (batch last); returns the scaled unknowns x (n, B) and the
    singular positions (B,): where a block's abs(det) / Π‖row‖ is not above `threshold`.

    Parameters
    ----------
    plan : _Plan
        The system's structure (`plan_of`).
    features : ndarray, shape (F, B)
        The per-position scalars the entries are made of: 1; per pair of `plan.joints` its lever
        (point − centre)/L, x then y; per prismatic pair of `plan.guides` its guide direction (x, y); per
        prismatic input (`plan.p_inputs`) the cross product of its lever and its guide; per higher pair
        its force's direction (x, y) and lever. L is the engine's size.
    b : ndarray, shape (n, B)
        The right side: per moving link minus the loads' force (x, y) and minus their moment about
        `plan.centre` over L.
    threshold : float
        The singularity threshold (`Engine.tol.singular`).

    Returns
    -------
    x : ndarray, shape (n, B)
        The unknowns, scaled (as reported: x · `plan.lay.scale`).
    singular : ndarray, shape (B,), bool
        Where a block is singular (its unknowns there are not meaningful).

    Raises
    ------
    IndexError
        `features` with fewer rows than the plan reads.

    Examples
    --------
    The balancing moment of the loaded four-bar against its −5 N·m on the rocker alone, assembled by
    hand, equals `kinetostatics`' with that load only:

    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians([60.0, 150.0]), omega=10.0)
    >>> from mbplanar.forces import evaluate_loads, plan_of, solve_blocks
    >>> plan = plan_of(engine)
    >>> xy = motion.xy[:, [motion.point(j) for j in plan.joints]]                    # (B, J, 2)
    >>> features = np.vstack([np.ones(2), ((xy - plan.centre) / engine.size).reshape(2, -1).T])
    >>> b = np.zeros((plan.lay.size, 2))
    >>> b[plan.lay.rows[engine.link_index["3"]] + 2] = 5.0 / engine.size             # −(−5 N·m) / L
    >>> x, singular = solve_blocks(plan, features, b, engine.tol.singular)
    >>> q = plan.lay.in_cols[0]
    >>> (x[q] * plan.lay.scale[q]).round(6), singular
    (array([1.087183, 1.774365]), array([False, False]))
    >>> only = evaluate_loads(engine, motion, gravity=False)
    >>> mbplanar.kinetostatics(engine, motion, loads=only, inertia=False).balancing["O"].round(6)
    array([1.087183, 1.774365])
    """
    x = np.zeros(b.shape)
    singular = np.zeros(b.shape[1], bool)
    for blk in plan.blocks:
        singular |= ~(_solve_block(blk, features, b, x) > threshold)
    return x, singular


def _right_side(lay, loads, centre, L, batch):
    """Right-hand side (n, B), batch last: minus the loads' forces and moments per link."""
    b = np.zeros((lay.size, batch))
    for ld in loads:
        row = lay.rows.get(ld.link)
        if row is None:
            continue
        fx, fy = ld.force[:, 0], ld.force[:, 1]
        b[row] -= fx
        b[row + 1] -= fy
        b[row + 2] -= ((ld.point[:, 0] - centre[0]) * fy - (ld.point[:, 1] - centre[1]) * fx + ld.moment) / L
    return b


def _virtual_power(engine, motion, loads, drive):
    """Relative residual (B,) of Σ(F·v + M·ω) over the loads plus Σ Q·(input rate), virtual velocities."""
    w, v = _virtual_frames(engine, motion)
    r = motion.frames.r
    rates = motion.rate_q if motion.rate_q is not None else motion.rate
    total = np.zeros(len(motion.phi))  # Σ of the terms
    scale = np.zeros(len(motion.phi))  # what they could be
    # relative to what the loads could do at this position's largest point speed and angular speed, so
    # that a position where most links stand still (an extreme position) is not judged on round-off
    point_v = motion.vq if motion.vq is not None else motion.v
    vscale = np.hypot(point_v[..., 0], point_v[..., 1]).max(axis=1, initial=0.0)
    if engine.mech.higher:  # and the higher pairs' contacts on both their links (a cam's rim at a dwell)
        for g in contact_geometry(engine, motion).values():
            for link in g.links:
                k = engine.link_index[link]
                d = g.point - r[:, k]
                speed = np.hypot(v[:, k, 0] - w[:, k] * d[:, 1], v[:, k, 1] + w[:, k] * d[:, 0])
                vscale = np.maximum(vscale, speed)
    wscale = np.abs(w).max(axis=1)
    for ld in loads:
        total += load_power(ld, w, v, r)
        scale += np.hypot(ld.force[:, 0], ld.force[:, 1]) * vscale + np.abs(ld.moment) * wscale
    for inp, q in zip(engine.inputs, drive):  # the drive acts on the joint's links (b, a) as (+q, −q)
        term = q * rates[:, motion.joint(inp.joint)]
        total += term
        scale += np.abs(term)
    return np.abs(total) / np.where(scale > 0, scale, 1.0)


def _radial_loads(engine, motion, x, lay) -> list[LoadValue]:
    """The radial part of every gear's and rack's contact force, from its tangential part x[col] (B,):
    tan α·|F_t| along the line of centres at the pitch point, pushing the teeth apart (on the second
    link along the normal out of the first, the opposite on the first). It passes through both gears'
    centres, points of the carrier, so it changes the bearings' reactions and nothing else."""
    out = []
    geometry = contact_geometry(engine, motion)
    for name, g in geometry.items():
        h = engine.mech.higher[name]
        if h.kind not in ("gear", "rack"):
            continue
        size = np.tan(h.pressure_angle) * np.abs(x[lay.cols[name]])
        force = size[:, None] * g.normal
        zero = np.zeros(len(size))
        ka, kb = (engine.link_index[n] for n in h.links)
        out += [LoadValue(f"radial force in {name}", kb, force, g.point, zero),
                LoadValue(f"radial force in {name}", ka, -force, g.point.copy(), zero.copy())]
    return out


def reported_on(mech, j) -> tuple[str, str]:
    """(link the reaction of pair j is reported on, the link it comes from): the moving link for a pair
    with the ground, the slider for a prismatic pair, the row's first link for a revolute pair.

    Parameters
    ----------
    mech : Mechanism
        The model.
    j : Joint
        One of its lower pairs.

    Returns
    -------
    tuple of str
        (on, from).

    Raises
    ------
    AttributeError
        `j` is not a `Joint`.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.forces import reported_on
    >>> mech = mbplanar.read_model("models/slider_crank.toml")
    >>> {name: reported_on(mech, j) for name, j in mech.joints.items()}
    {'O': ('1', '0'), 'A': ('1', '2'), 'B': ('2', '3'), 'Bp': ('3', '0')}
    """
    a, b = j.links
    return (a, b) if b == mech.ground or (j.kind == "R" and a != mech.ground) else (b, a)


def _report(engine, lay, x, contact: dict | None = None) -> dict:
    """Reactions as reported, from the unknowns x (n, B) (already turned round by `_Layout.scale`); a
    higher pair's on its second link from its first, its force `contact` (name → (B, 2))."""
    out = {}
    for j in engine.mech.joints.values():
        c = lay.cols[j.name]
        m = x[c + 2] if j.kind == "P" else np.zeros(x.shape[1])
        out[j.name] = Reaction(j.name, *reported_on(engine.mech, j), x[c], x[c + 1], m)
    for name, force in (contact or {}).items():
        a, b = engine.mech.higher[name].links
        out[name] = Reaction(name, b, a, force[:, 0], force[:, 1], np.zeros(x.shape[1]))
    return out


def kinetostatics(engine, motion, input_inertia=0.0, loads: list[LoadValue] | None = None,
                  inertia: bool = True) -> Kinetostatics:
    """Reactions in every pair and the balancing load at every input over the positions of `motion`.

    The engine's compiled backend takes the batch where it can (`engine._backend.dispatch`); numpy, the
    reference, does the rest.

    Parameters
    ----------
    engine : Engine
        The mechanism `motion` was computed on.
    motion : Motion
        Positions with their rates (`analyse` with ``rates=True`` and every joint).
    input_inertia : float or sequence of float
        J_I (kg·m², or kg for a prismatic input) on each input link, one value or one per input.
    loads : list of LoadValue, optional
        Evaluated external loads (default: the model's loads and gravity, `evaluate_loads`).
    inertia : bool
        Include the d'Alembert loads of the links (and J_I).

    Returns
    -------
    Kinetostatics
        `reactions` {joint: `Reaction` (fx, fy, moment: (B,) each, N and N·m)}, `balancing` {input
        joint: (B,)} and the virtual-power check of every position.

    Raises
    ------
    ModelError
        An `input_inertia` that is not finite and >= 0.

    Examples
    --------
    >>> import numpy as np
    >>> import mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians([60.0]), omega=10.0)
    >>> k = mbplanar.kinetostatics(engine, motion)
    >>> round(float(k.balancing["O"][0]), 5)            # the balancing moment on the crank, N·m
    2.69865
    >>> bool(k.virtual_power_residual[0] < 1e-12)       # the balancing moment's power equals the loads'
    True
    """
    _check_input_inertia(engine, input_inertia)
    _frames_of(motion)
    return dispatch(engine, "kinetostatics", len(motion.phi),
                    lambda: _reference(engine, motion, input_inertia, loads, inertia),
                    lambda: _program_request(engine, motion, inertia, loads, input_inertia),
                    lambda job, out: _program_result(engine, motion, job, out))


@dataclass(frozen=True)
class KinetostaticsJob:
    """A request of the kinetostatics job (`engine._backend.dispatch`): the `program` of the engine's
    system and loads (`forces._program.Program`; None where the program cannot express the call,
    `why` says why), the motion's `records` (B,) it reads (the compiled kinematics' record layout), its
    `inputs` (2 + G + 7·H, B): ω, ε, the sizes of the G guide loads (`guide_force_size`) and the H higher
    pairs' geometry (`_program.pair_inputs`), and the `threads` to split the positions over (None: the
    machine's cores); `directions` the higher pairs' (`pair_directions`, for their contact forces). A
    backend answers the program's outputs (`Program.outputs_rows`, B)."""

    program: object
    why: str
    records: np.ndarray | None
    inputs: np.ndarray | None
    threads: int | None
    directions: dict | None = None


def _program_request(engine, motion, inertia, loads, input_inertia) -> KinetostaticsJob:
    """The request of the program (`forces._program`), written where it can express the call: one input,
    the model's own loads (no springs, dampers, torques or switched rows) with or without the
    d'Alembert loads, no input inertia, and a motion with the compiled kinematics' records holding its
    frames."""
    why = _unwritable(engine, motion, loads, input_inertia)
    if why:
        return KinetostaticsJob(None, why, None, None, engine.threads)
    from ._program import PAIR_INPUTS, pair_inputs, program_for  # (for a compiled backend only)
    rows = motion.records
    plan = plan_of(engine)
    program = program_for(engine, plan, motion, inertia)
    guides = len(program.guide_loads)
    inputs = np.empty((2 + guides + PAIR_INPUTS * len(plan.higher), len(rows)))
    inputs[0], inputs[1] = motion.omega[:, 0], motion.epsilon[:, 0]
    for g, load in enumerate(program.guide_loads):
        inputs[2 + g] = guide_force_size(engine, motion, load)
    directions = None
    if plan.higher:
        geometry = contact_geometry(engine, motion)
        directions = _directions(geometry)
        inputs[2 + guides:] = pair_inputs(engine, plan, directions, geometry, len(rows))
    return KinetostaticsJob(program, "", rows, inputs, engine.threads, directions)


def _unwritable(engine, motion, loads, input_inertia) -> str:
    """Why the program cannot express a call ("" where it can)."""
    if len(engine.inputs) != 1:
        return "several inputs"
    if loads is not None:
        return "loads given by the caller"
    if not _no_input_inertia(input_inertia):
        return "input inertia"
    if needs_numpy(engine.mech):
        return "springs, dampers, torques or switched loads (numpy evaluates them)"
    rows = motion.records
    if rows is None or not len(rows) or rows.dtype.names is None or "fa" not in rows.dtype.names:
        return "a motion without the compiled kinematics' records with rates (numpy's, or outputs= without 'frames')"
    if not np.may_share_memory(rows, motion.frames.w):
        return "records that do not hold the motion's frames"
    return ""


def _program_result(engine, motion, job, out) -> Kinetostatics:
    """The `Kinetostatics` of a program's outputs `out` (O, B): the unknowns, the loads' values (views of
    `out`), the virtual-power residual and the singular flag; the higher pairs' contact forces from their
    unknowns (`_contact_forces`)."""
    program = job.program
    values = [LoadValue(name, k, out[f:f + 2].T, out[p:p + 2].T, out[m])
              for name, k, (f, p, m) in zip(program.names, program.links, program.sources)]
    x, residual, singular = out[:program.size], out[-2], out[-1] != 0.0
    if singular.any():
        x[:, singular] = np.nan  # (the residual is NaN there too, as numpy's, whose drive is NaN there)
        residual[singular] = np.nan
    lay = plan_of(engine).lay
    contact = None
    if job.directions is not None:
        contact = _contact_forces(engine, lay, x, job.directions, _radial_loads(engine, motion, x, lay))
    return result(engine, motion, lay, x, singular, residual, values, contact)


def _no_input_inertia(input_inertia) -> bool:
    """Whether `input_inertia` is 0 (the default 0 recognised without np.any, ~4 µs a call)."""
    return input_inertia == 0 if type(input_inertia) in (int, float) else not np.any(input_inertia)


def _check_input_inertia(engine, input_inertia):
    if type(input_inertia) in (int, float) and input_inertia == 0:  # the default, at once
        return
    try:
        values = np.asarray(input_inertia, float)
    except (TypeError, ValueError):
        values = np.array([np.nan])
    if not np.all(np.isfinite(values) & (values >= 0)) or values.ndim > 1 or values.size not in (1, len(engine.inputs)):
        raise ModelError(f"input_inertia must be a finite number >= 0 (kg·m², or kg for a prismatic input), "
                         f"one or one per input, got {input_inertia!r}", source=engine.mech.source,
                         where="kinetostatics")


def _reference(engine, motion, input_inertia, loads, inertia) -> Kinetostatics:
    """`kinetostatics` by numpy."""
    batch = len(motion.phi)
    plan = plan_of(engine)
    lay = plan.lay
    loads = list(evaluate_loads(engine, motion) if loads is None else loads)
    if inertia:
        loads += inertia_loads(engine, motion, input_inertia)
    b = _right_side(lay, loads, plan.centre, engine.size, batch)
    contact = None
    if batch:
        directions = pair_directions(engine, motion) if plan.higher else None
        features = _features(engine, motion, plan, directions)
        x, singular = solve_blocks(plan, features, b, engine.tol.singular)
        radial = _radial_loads(engine, motion, x, lay) if plan.higher else []
        if radial:  # (the tangential forces stay as they are: the radial pairs pass through the centres)
            b = b + _right_side(lay, radial, plan.centre, engine.size, batch)
            x, singular = solve_blocks(plan, features, b, engine.tol.singular)
        x *= lay.scale[:, None]
        singular |= ~np.all(np.isfinite(x), axis=0)
        x[:, singular] = np.nan
        if plan.higher:
            contact = _contact_forces(engine, lay, x, directions, radial)
    else:
        x, singular = np.zeros((lay.size, 0)), np.zeros(0, bool)
        if plan.higher:
            contact = {name: np.zeros((0, 2)) for name in plan.higher}
    residual = _virtual_power(engine, motion, loads, [x[c] for c in lay.in_cols])
    return result(engine, motion, lay, x, singular, residual, loads, contact)


def _contact_forces(engine, lay, x, directions: dict, radial: list) -> dict:
    """Each higher pair's contact force on its second link (B, 2): its unknown along its direction, and a
    gear's or a rack's radial part."""
    out = {name: x[lay.cols[name], :, None] * d for name, (_, d) in directions.items()}
    k_of = {name: engine.link_index[engine.mech.higher[name].links[1]] for name in out}
    for ld in radial:
        name = ld.name.removeprefix("radial force in ")
        if ld.link == k_of[name]:
            out[name] = out[name] + ld.force
    return out


def result(engine, motion, lay, x, singular, residual, loads, contact: dict | None = None) -> Kinetostatics:
    """The reported reactions and balancing loads from the unknowns x (n, B) (also the compiled backend's);
    `contact` the higher pairs' contact forces (`_contact_forces`)."""
    mech = engine.mech
    drive = [x[c] for c in lay.in_cols]  # on each input joint's second link
    balancing = {inp.joint: q if input_link(engine, inp)[0] == mech.joints[inp.joint].links[1] else -q
                 for inp, q in zip(engine.inputs, drive)}
    contact_forces = {name: x[lay.cols[name]] for name in mech.higher}
    pulling = {name: np.asarray(f) < 0 for name, f in contact_forces.items() if mech.higher[name].kind == "cam"}
    words = []
    if np.any(singular):
        words.append(_singular_message(engine, motion, singular))
    for name, pull in pulling.items():
        if np.any(pull):
            bad = np.flatnonzero(pull)
            words.append(f"cam '{name}': the contact force would pull at {len(bad)} position(s) "
                         f"({_where(engine, motion, bad)}): the follower leaves the cam there unless a spring or "
                         "a preload holds it on")
    return Kinetostatics(motion=motion, reactions=_report(engine, lay, x, contact), balancing=balancing,
                         virtual_power_residual=residual, loads=loads, singular=singular,
                         contact_forces=contact_forces, pulling=pulling, success=not words,
                         message="; ".join(words) or "solved")


def _where(engine, motion, bad) -> str:
    """"φ = 10, 20, ..." of the positions `bad` (at most five named)."""
    inp = engine.inputs[0]
    return (f"{inp.name} = " + ", ".join(f"{inp.from_si(motion.phi[k, 0]):.6g}" for k in bad[:5])
            + (", ..." if len(bad) > 5 else ""))


def _singular_message(engine, motion, singular) -> str:
    """What `Kinetostatics.message` says where the force system is singular."""
    bad = np.flatnonzero(singular)
    return (f"the force system is singular at {len(bad)} position(s) ({_where(engine, motion, bad)}): links in "
            "line at a dead point, where the drive cannot balance the loads, or at a change point, where the "
            "reactions are statically indeterminate")

