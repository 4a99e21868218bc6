"""The compiled kernels' tables: an engine's blocks, joints and loads as named tuples of arrays (numba
takes a named tuple of arrays as one argument), each field documented with its shape, built here
and only here.

Codes. `REVOLUTE` and `PRISMATIC` name the joint types (`JointLaw.kind` "R", "P"); a table stores the
boolean `prismatic` rather than the code, and a load its `guide` row (or −1) and the boolean `inertia`,
so that no kernel compares against a constant of another file (numba would freeze it into its cache,
and an edit here would not reach the cached kernels).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["REVOLUTE", "PRISMATIC", "LOAD_FIXED", "LOAD_GUIDE", "LOAD_INERTIA", "StepTables", "CutTables",
           "BlockTables", "JointTables", "LoadTables", "kinematics_tables", "load_tables"]

REVOLUTE, PRISMATIC = "R", "P"                          # JointLaw.kind, Joint.kind
LOAD_FIXED, LOAD_GUIDE, LOAD_INERTIA = "fixed", "guide", "inertia"   # the three kinds of load a kernel adds


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


class JointTables(NamedTuple):
    """Every joint of the model (J), for the joint values written per position."""

    prismatic: np.ndarray   # (J,) bool
    a: np.ndarray           # (J,) int: first link (the carrier of a prismatic joint)
    b: np.ndarray           # (J,) int: second link (the slider)
    drawn: np.ndarray       # (J,) float: the joint's value in the drawn pose
    at: np.ndarray          # (J, 2) float: the joint's point, drawn (prismatic; else 0)
    u0: np.ndarray          # (J, 2) float: the guide's direction, drawn (prismatic; else 0)


class LoadTables(NamedTuple):
    """The N loads the kinetostatics kernel adds at every position, in numpy's order."""

    link: np.ndarray               # (N,) int: the link loaded
    guide: np.ndarray              # (N,) int: a force along a guide: its row of guide-force sizes; else −1
    inertia: np.ndarray            # (N,) bool: a d'Alembert load (−m·a at the centre, −I·ε)
    carrier: np.ndarray            # (N,) int: the guide's carrier (guide loads; else 0)
    at: np.ndarray                 # (N, 2) float: the point of application, drawn
    force: np.ndarray              # (N, 2) float: a fixed force (else 0)
    moment: np.ndarray             # (N,) float: a fixed moment
    u0: np.ndarray                 # (N, 2) float: the guide's direction, drawn (guide loads; else 0)
    mass: np.ndarray               # (N,) float: inertia loads: the link's mass (else 0)
    moment_of_inertia: np.ndarray  # (N,) float: inertia loads: the link's I_S (else 0)


def load_tables(rows: list) -> LoadTables:
    """`LoadTables` from rows (kind, link, guide row, carrier, at, force or (mass, I_S), moment, u0), kind
    `LOAD_FIXED`, `LOAD_GUIDE` or `LOAD_INERTIA`."""
    n = len(rows)
    out = LoadTables(np.zeros(n, np.int64), np.full(n, -1, np.int64), np.zeros(n, np.bool_), np.zeros(n, np.int64),
                     np.zeros((n, 2)), np.zeros((n, 2)), np.zeros(n), np.zeros((n, 2)), np.zeros(n), np.zeros(n))
    for i, (kind, link, guide, carrier, at, force, moment, u0) in enumerate(rows):
        out.link[i], out.carrier[i], out.at[i], out.moment[i] = link, carrier, at, moment
        if kind == LOAD_INERTIA:
            out.inertia[i], out.mass[i], out.moment_of_inertia[i] = True, force[0], force[1]
        elif kind == LOAD_GUIDE:
            out.guide[i], out.u0[i] = guide, u0
        else:
            out.force[i] = force
    return out


def kinematics_tables(engine, joint_table) -> tuple[StepTables, CutTables, BlockTables, JointTables]:
    """The engine's `BlockPlan`s and its joints (`kinematics._JointTable`) as the kinematics kernel's tables."""
    idx = engine.link_index
    steps, cuts, blocks, anchors, rows, vars_ = [], [], [], [], [], []
    var0, written = 0, set()
    for bp in engine.blocks:
        placed = {idx[st.child] for st in bp.steps}
        read = {idx[st.parent] for st in bp.steps} | {idx[n] for law in bp.cuts for n in law.links[:2]}
        mine = sorted((read - placed) & written)
        if bp.m:
            written |= placed
        blocks.append((len(steps), len(steps) + len(bp.steps), len(cuts), len(cuts) + len(bp.cuts), var0, bp.m,
                       len(anchors), len(anchors) + len(mine)))
        anchors += mine
        for st in bp.steps:
            law = st.law
            prismatic = law.kind == PRISMATIC
            steps.append((prismatic, idx[st.parent], idx[st.child], st.relative,
                           -1 if st.var is None else var0 + st.var, -1 if st.input is None else st.input, st.sign,
                           tuple(law.s0), tuple(law.u0) if prismatic else (0.0, 0.0),
                           1.0 if not prismatic or st.parent == law.carrier else -1.0))
        for law in bp.cuts:
            prismatic = law.kind == PRISMATIC
            cuts.append((prismatic, idx[law.links[0]], idx[law.links[1]], tuple(law.s0),
                         tuple(law.n0) if prismatic else (0.0, 0.0)))
        rows.extend(bp.row_scale)
        vars_.extend(bp.var_scale)
        var0 += bp.m
    block_cols = [np.array(c, np.int64) for c in zip(*blocks)] if blocks else [np.zeros(0, np.int64)] * 8
    return (_columns(StepTables, steps), _columns(CutTables, cuts),
            BlockTables(*block_cols, np.array(anchors, np.int64), np.array(rows, float), np.array(vars_, float)),
            _joint_tables(joint_table))


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


def _joint_tables(t) -> JointTables:
    """From `kinematics._JointTable`: revolute columns and prismatic columns merged by joint."""
    n_j = len(t.drawn)
    prismatic, a, b = np.zeros(n_j, np.bool_), np.zeros(n_j, np.int64), np.zeros(n_j, np.int64)
    at, u0 = np.zeros((n_j, 2)), np.zeros((n_j, 2))
    a[t.r_col], b[t.r_col] = t.r_a, t.r_b
    prismatic[t.p_col], a[t.p_col], b[t.p_col] = True, t.p_c, t.p_s
    at[t.p_col], u0[t.p_col] = t.p_at, t.p_u0
    return JointTables(prismatic, a, b, np.array(t.drawn, float), at, u0)
