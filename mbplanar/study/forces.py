"""Kinetostatics of a design batch: every joint reaction and the balancing load of D designs × N
positions in one solve, the (design, position) pairs a flat batch.

The equilibrium system's structure is the reference engine's (`forces.plan_of`: the
layout of rows and unknowns, the blocks and their elimination order, which do not depend on the
dimensions). What does depend on them is computed here per pair, from the design batch's motion and
each design's constants: the levers of the joints about each design's moment centre (the mean of its
drawn joints) over its size, the guides' directions, the loads. The blocks are then solved by the
engine's own back-substitution (`solve_blocks`) over the flat batch.

Loads: the links' d'Alembert loads (−m·a_S at the centre S, −I_S·ε, the real accelerations from the
analogues at the input's constant `omega` and `epsilon`), gravity on the heavy links, and the model's
`force`, `weight` and `moment` rows acting at named points. Masses and inertias may be parameters.
Other rows (guide forces, springs, dampers, switched rows, loads at coordinates) and higher pairs are
declined (`design_kinetostatics` returns None): a study then solves each design's own kinetostatics.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..forces import constant_parts, heavy_links, input_link, plan_of, reported_on, solve_blocks

__all__ = ["DesignForces", "design_kinetostatics"]


@dataclass(frozen=True, eq=False)
class DesignForces:
    """Reactions and balancing loads of D designs × N positions (NaN where a position is not valid or
    singular).

    Attributes
    ----------
    joints : list of str
        The joints' order.
    reactions : (D, N, J, 2) ndarray
        The force in each joint on the link `Kinetostatics` reports it on (`forces.reported_on`), N.
    balancing : (D, N) ndarray
        The balancing moment (N·m) or force (N) on the input link.
    singular : (D, N) ndarray of bool
        Positions where the equilibrium is singular.

    Examples
    --------
    A 2 kg coupler on models/fourbar_design.toml; the design with a 0.12 m coupler cannot reach 180°:

    >>> import tomllib, numpy as np
    >>> from mbplanar.study import design_batch, design_kinetostatics, load_template, variants_from
    >>> table = tomllib.load(open("models/fourbar_design.toml", "rb"))
    >>> table["links"][1].update(mass=2.0, inertia=0.015, centre="M")
    >>> template = load_template(table)
    >>> variants = variants_from(template, {"b": np.array([0.3, 0.12])})
    >>> batch = design_batch(template, variants)
    >>> forces = design_kinetostatics(batch, batch.solve(np.radians([30.0, 180.0])), template, variants)
    >>> forces.joints, np.isnan(forces.balancing).tolist()
    (['O', 'A', 'B', 'C'], [[False, False], [False, True]])
    """

    joints: list
    reactions: np.ndarray
    balancing: np.ndarray
    singular: np.ndarray

    def largest(self) -> tuple[np.ndarray, list]:
        """Per design the largest reaction magnitude over the positions and joints (D,) (NaN without a
        valid position) and the joint where it acts (None without one)."""
        mag = np.hypot(self.reactions[..., 0], self.reactions[..., 1])  # (D, N, J)
        flat = np.where(np.isnan(mag), -np.inf, mag).max(axis=1)  # (D, J)
        best = flat.argmax(axis=1)
        value = flat[np.arange(len(flat)), best]
        joints = [self.joints[k] if np.isfinite(v) else None for k, v in zip(best, value)]
        return np.where(np.isfinite(value), value, np.nan), joints

    def mean_balancing(self) -> np.ndarray:
        """Per design the mean balancing load over its valid positions (D,)."""
        with np.errstate(invalid="ignore"):
            count = np.sum(np.isfinite(self.balancing), axis=1)
            return np.where(count > 0, np.nansum(self.balancing, axis=1) / np.maximum(count, 1), np.nan)


def _supported(mech) -> bool:
    """Whether every load row is one this module evaluates (force, weight, moment at named points), in a
    model without higher pairs (whose contact forces each design's own kinetostatics finds)."""
    if mech.higher:
        return False
    for load in mech.loads:
        if load.switch or load.kind not in ("force", "weight", "moment"):
            return False
        if load.kind != "moment" and load.at is not None:
            return False
    return True


def _link_values(template, variants, count: int, link: str, key: str) -> np.ndarray:
    """A link's `mass` or `inertia` per design (D,): a number, or the parameter it names."""
    for i, row in enumerate(template.data.get("links", [])):
        if str(row.get("name")) == link:
            values = {**{n: np.full(count, v) for n, v in template.defaults().items()}, **variants.values}
            raw = row.get(key, 0.0)
            return np.broadcast_to(np.asarray(template._value(raw, "plain", values, f"links[{i}] {key}"), float),
                                   (count,)).copy()
    return np.zeros(count)


def _scale(engine, plan, size):
    """`_Layout.scale` per design (n, D): the reported sign, times the design's size where the unknown is
    a prismatic pair's moment or a revolute input's balancing moment."""
    mech = engine.mech
    rows = []
    for j in mech.joints.values():
        sign = 1.0 if reported_on(mech, j)[0] == j.links[1] else -1.0
        rows += [np.full_like(size, sign)] * 2 + ([sign * size] if j.kind == "P" else [])
    for inp in engine.inputs:
        rows.append(size if mech.joints[inp.joint].kind == "R" else np.ones_like(size))
    return np.stack(rows)


def design_kinetostatics(batch, motion, template, variants) -> DesignForces | None:
    """Reactions and balancing loads of every design of a batch at every position, in one solve.

    Parameters
    ----------
    batch : DesignBatch
        The designs (its reference engine and drawn geometry).
    motion : DesignMotion
        Its solved motion (`batch.solve(phi)`, every point, accelerations).
    template, variants : Template, Variants
        The model and the designs' parameter values (masses and inertias may be parameters).

    Returns
    -------
    DesignForces or None
        None where the model has loads this module does not evaluate (guide forces, springs,
        dampers, switched rows, loads at coordinates, higher pairs: see the module docstring), or
        `motion` lacks points or accelerations; the caller then solves each design's own kinetostatics.

    Raises
    ------
    IndexError
        A `motion` not solved by `batch` (another number of designs).

    Examples
    --------
    models/fourbar_design.toml with a 2 kg coupler: the batch's balancing moments are each design's own
    `mbplanar.kinetostatics`:

    >>> import tomllib, numpy as np, mbplanar
    >>> from mbplanar.study import design_batch, design_kinetostatics, load_template, variants_from
    >>> table = tomllib.load(open("models/fourbar_design.toml", "rb"))
    >>> table["links"][1].update(mass=2.0, inertia=0.015, centre="M")
    >>> template = load_template(table)
    >>> variants = variants_from(template, {"b": np.array([0.3, 0.35])})
    >>> batch = design_batch(template, variants)
    >>> phi = np.radians([30.0, 120.0])
    >>> forces = design_kinetostatics(batch, batch.solve(phi), template, variants)
    >>> own = mbplanar.kinetostatics(batch.engine_of(1), mbplanar.analyse(batch.engine_of(1), phi))
    >>> forces.reactions.shape, bool(np.allclose(forces.balancing[1], own.balancing["O"], rtol=1e-9, atol=0))
    ((2, 2, 4, 2), True)
    """
    engine = batch.engine
    mech = engine.mech
    if not _supported(mech) or motion.eq is None or motion.points != batch.points:
        return None
    g, plan, lay = batch.geometry, plan_of(engine), plan_of(engine).lay
    D, N = motion.phi.shape
    inp = engine.inputs[0]
    d_idx, n_idx = np.nonzero(motion.valid)
    B = len(d_idx)
    point = {name: k for k, name in enumerate(motion.points)}
    joints = list(mech.joints)
    drawn = np.stack([g.at[j] for j in joints])  # (J, 2, D)
    centre = drawn.mean(axis=0)  # (2, D)
    pairs = np.linalg.norm(drawn[:, None] - drawn[None, :], axis=2)
    size = pairs.reshape(-1, D).max(axis=0)
    size = np.where(size > 0, size, 1.0)
    cx, cy, L = centre[0][d_idx], centre[1][d_idx], size[d_idx]
    xy, vq, aq = motion.xy[d_idx, n_idx], motion.vq[d_idx, n_idx], motion.aq[d_idx, n_idx]  # (B, P, 2)
    th = motion.angle[d_idx, n_idx] - np.stack([g.reference[n] for n in engine.links], axis=1)[d_idx]  # (B, L)
    # features (F, B): 1; the joints' levers; the guides' directions; prismatic inputs' cross levers
    features = np.empty((1 + 2 * len(plan.joints) + 2 * len(plan.guides) + len(plan.p_inputs), B))
    features[0] = 1.0
    for k, name in enumerate(plan.joints):
        features[1 + 2 * k] = (xy[:, point[name], 0] - cx) / L
        features[2 + 2 * k] = (xy[:, point[name], 1] - cy) / L
    base = 1 + 2 * len(plan.joints)
    for k, name in enumerate(plan.guides):
        t = th[:, engine.link_index[mech.joints[name].carrier]]
        u0 = g.guide[name][:, d_idx]
        c, s = np.cos(t), np.sin(t)
        features[base + 2 * k] = c * u0[0] - s * u0[1]
        features[base + 2 * k + 1] = s * u0[0] + c * u0[1]
    for k, (gi, ji) in enumerate(plan.p_inputs):
        features[base + 2 * len(plan.guides) + k] = (features[1 + 2 * ji] * features[base + 2 * gi + 1]
                                                     - features[2 + 2 * ji] * features[base + 2 * gi])
    # the right side (n, B): minus every load's force and moment about the design's centre, per link
    b = np.zeros((lay.size, B))

    def add(link: int, force, at, moment):
        row = lay.rows.get(link)
        if row is None:
            return
        fx, fy = force[:, 0], force[:, 1]
        b[row] -= fx
        b[row + 1] -= fy
        b[row + 2] -= ((at[:, 0] - cx) * fy - (at[:, 1] - cy) * fx + moment) / L

    om, ep = inp.omega, inp.epsilon
    zeros = np.zeros(B)
    for name, lk, _ in heavy_links(mech):
        k = engine.link_index[name]
        mass = _link_values(template, variants, D, name, "mass")[d_idx]
        inertia = _link_values(template, variants, D, name, "inertia")[d_idx]
        e = motion.eq[d_idx, n_idx, k] * om * om + motion.wq[d_idx, n_idx, k] * ep
        if lk.centre is None:  # inertia only: a pure moment
            add(k, np.zeros((B, 2)), np.zeros((B, 2)), -inertia * e)
            continue
        p = point[lk.centre]
        acc = aq[:, p] * om * om + vq[:, p] * ep
        add(k, -mass[:, None] * acc, xy[:, p], -inertia * e)
        if mech.gravity is not None:
            add(k, mass[:, None] * np.asarray(mech.gravity.vector, float), xy[:, p], zeros)
    for load in mech.loads:
        k = engine.link_index[load.link]
        _, force, moment = constant_parts(mech, load)
        at = xy[:, point[load.point]] if load.point is not None else np.zeros((B, 2))
        add(k, np.broadcast_to(force, (B, 2)), at, np.full(B, moment))
    x, singular = solve_blocks(plan, features, b, engine.tol.singular)
    x *= _scale(engine, plan, size)[:, d_idx]
    singular |= ~np.all(np.isfinite(x), axis=0)
    x[:, singular] = np.nan
    reactions = np.full((D, N, len(joints), 2), np.nan)
    for k, j in enumerate(joints):
        c = lay.cols[j]
        reactions[d_idx, n_idx, k, 0], reactions[d_idx, n_idx, k, 1] = x[c], x[c + 1]
    q = x[lay.in_cols[0]]
    if input_link(engine, inp)[0] != mech.joints[inp.joint].links[1]:
        q = -q
    balancing = np.full((D, N), np.nan)
    balancing[d_idx, n_idx] = q
    out_singular = np.zeros((D, N), bool)
    out_singular[d_idx, n_idx] = singular
    return DesignForces(joints, reactions, balancing, out_singular)
