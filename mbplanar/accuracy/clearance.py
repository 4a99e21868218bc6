"""Joint clearances under load: the effective-link model.

A pair with clearance lets its two elements sit apart: a revolute pair's pin centre up to the radial
clearance c from the hole's centre, a prismatic pair's block up to c across its guide. Under load the
gap is taken up in the direction of the force the pair transmits: the element of link `source` sits at
c·F̂ from the element of link `on`, F the reaction on `on` from `source` (the kinetostatics' reaction;
for a prismatic pair its component across the guide, F·n, so the block sits at c·sign(F·n)·n). The
pin centre then lies on the line of the force, on the side it pushes, whichever link holds the pin.
The mechanism moves as one whose links are longer or shorter by these offsets, the effective links,
so the output's error is, to first order, Σ_j S_j(φ)·Δ_j(φ), S_j the output's sensitivity to the offset
of pair j's elements (a column of the exact sensitivity pass, `sensitivity.source_pass`: the closure with
the elements Δ apart is that of coincident points with the `on` link's point moved by Δ).

Where a reaction turns through zero between two positions, the gap is crossed and the elements strike
(the pair knocks): a revolute pair where F(φ_k)·F(φ_{k−1}) < 0, a prismatic one where F·n changes sign;
the input value is interpolated linearly between the two positions. Without loads or masses the pairs
carry no force: then each clearance's error is given as its worst case, c times the length of the
output's sensitivity vector (the gap taken up in the direction that hurts most). A prismatic block's tilt
in its guide (it needs the block's length) is left out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..engine import solve_positions

from .sensitivity import Patch, Sources, output_rates, source_pass

__all__ = ["ClearanceErrors", "clearance_errors"]


@dataclass(frozen=True)
class ClearanceErrors:
    """The outputs' errors from the pairs' clearances over N positions (SI).

    Attributes
    ----------
    joints : tuple of str
        The J pairs with a clearance.
    clearances : (J,) ndarray
        Their clearances, m.
    loaded : bool
        Whether the pairs carry loads (else `error` is zero and only `worst` applies).
    error : (N, Y) ndarray
        The outputs' error with every gap taken up along its pair's reaction.
    part : (N, Y, J) ndarray
        Each pair's share of `error`.
    worst : (N, Y) ndarray
        Σ_j c_j·|S_j|: every gap in its worst direction.
    direction : (N, J) ndarray
        The direction (rad) each gap is taken up in (NaN without loads).
    knocks : dict
        {pair: input values (SI) where its reaction turns through zero}: where the gap is crossed.

    Examples
    --------
    Two pins of the loaded four-bar with clearance: the error is the sum of each pin's part:

    >>> import numpy as np, mbplanar
    >>> from mbplanar.accuracy import Clearance, clearance_errors, resolve_outputs
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> gaps = [Clearance("A", 5e-5), Clearance("B", 1e-4)]
    >>> ce = clearance_errors(engine, np.radians([0, 90, 180]), gaps, resolve_outputs(engine.mech, ["3"]))
    >>> ce.joints, ce.part.shape, bool(np.allclose(ce.part.sum(axis=2), ce.error, rtol=0, atol=1e-15))
    (('A', 'B'), (3, 1, 2), True)
    """

    joints: tuple
    clearances: np.ndarray
    loaded: bool
    error: np.ndarray
    part: np.ndarray
    worst: np.ndarray
    direction: np.ndarray
    knocks: dict


def _columns(engine, sol, pairs) -> tuple[Sources, list]:
    """Unit offsets of each pair's element on link `source` from its element on link `on`: two columns
    (world x, y) for a revolute pair, one (across the guide) for a prismatic pair. (The closure with the
    elements apart by Δ is the closure of coincident points with the `on` link's point moved by Δ.)"""
    B = len(sol.phi)
    cols = []
    for name, on in pairs:
        j = engine.mech.joints[name]
        if j.kind == "R":
            cols += [(name, on, np.array([1.0, 0.0])[:, None] * np.ones(B)),
                     (name, on, np.array([0.0, 1.0])[:, None] * np.ones(B))]
        else:
            u = sol.pose.rot(j.carrier, engine.laws[name].u0)
            cols.append((name, j.slider, np.stack([-u[1], u[0]])))
    C = len(cols)
    side = {}
    for c, (name, link, vec) in enumerate(cols):
        side.setdefault((name, link), []).append((c, vec))
    side = {key: Patch(np.array([c for c, _ in got]), np.stack([v for _, v in got], axis=1))
            for key, got in side.items()}
    src = Sources(C, side, {}, {}, {}, np.zeros((len(engine.inputs), C, B)))
    return src, cols


def _knocks(force, phi, cyclic: bool) -> tuple:
    """Input values where a force (B, 2) (or a signed normal force (B,)) turns through zero."""
    f = force if force.ndim == 2 else force[:, None]
    prev, nxt = f[:-1], f[1:]
    xs = list(zip(prev, nxt, phi[:-1], phi[1:]))
    if cyclic and len(phi) > 1:
        xs.append((f[-1], f[0], phi[-1], phi[0] + (phi[1] - phi[0]) * len(phi)))
    out = []
    for a, b, pa, pb in xs:
        aa, ab = float(a @ a), float(a @ b)
        if aa > 0 and ab < 0:
            t = aa / (aa - ab)
            out.append(float(pa + t * (pb - pa)))
    return tuple(out)


def clearance_errors(engine, phi, clearances, outputs, cyclic: bool = False) -> ClearanceErrors:
    """The outputs' errors from the pairs' clearances, each gap taken up along its pair's reaction.

    The reactions come from the kinetostatics at the model's input speed; a pair's gap moves its two
    elements apart by the clearance along the reaction, which moves the outputs by the pair's
    sensitivity (the effective-link model).

    Parameters
    ----------
    engine : Engine
        The model.
    phi : (N,) array_like
        Input values, SI.
    clearances : sequence of Clearance
        The pairs' clearances, m (revolute and prismatic pairs).
    outputs : sequence of Output
        What is measured.
    cyclic : bool
        The positions close a turn (for a knock between the last and the first).

    Returns
    -------
    ClearanceErrors
        Errors along the reactions, the worst case and the knocks.

    Raises
    ------
    KeyError
        A clearance naming no joint of the model (`read_tolerances` checks names with a clear message).

    Examples
    --------
    The loaded four-bar with 0.1 mm of radial clearance in pin B: the rocker's angle error, against the
    worst case (the gap in its worst direction):

    >>> import numpy as np, mbplanar
    >>> from mbplanar.accuracy import Clearance, clearance_errors, resolve_outputs
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> phi = np.radians(np.arange(0, 360, 30))
    >>> ce = clearance_errors(engine, phi, [Clearance("B", 1e-4)], resolve_outputs(engine.mech, ["3"]), cyclic=True)
    >>> ce.loaded, bool(np.all(np.abs(ce.error) <= ce.worst + 1e-15)), ce.knocks
    (True, True, {'B': ()})
    >>> round(float(np.degrees(ce.worst).max()), 4)                  # degrees
    0.0346
    """
    from ..forces import has_force_data, kinetostatics
    from ..kinematics import analyse

    phi = np.asarray(phi, float).reshape(-1)
    loaded = has_force_data(engine.mech)
    with np.errstate(all="ignore"):
        sol = solve_positions(engine, phi[:, None])
        if loaded:
            motion = analyse(engine, phi)
            forces = kinetostatics(engine, motion).reactions
            keep = np.isin(phi, motion.phi[:, 0])
    pairs = []
    for c in clearances:
        j = engine.mech.joints[c.joint]
        pairs.append((c.joint, forces[c.joint].on if loaded else j.slider if j.kind == "P" else j.links[0]))
    src, cols = _columns(engine, sol, pairs)
    with np.errstate(all="ignore"):
        known = source_pass(engine, sol, src)
        s = output_rates(engine, sol, known, src, outputs)      # (Y, C, N)
    N, Y, J = len(phi), len(outputs), len(clearances)
    part, worst = np.zeros((N, Y, J)), np.zeros((N, Y))
    direction = np.full((N, J), np.nan)
    knocks = {}
    c0 = 0
    for k, c in enumerate(clearances):
        j = engine.mech.joints[c.joint]
        width = 2 if j.kind == "R" else 1
        sj = s[:, c0:c0 + width, :]                              # (Y, w, N)
        worst[:] += c.value * np.sqrt((sj ** 2).sum(axis=1)).T
        if loaded:
            r = forces[c.joint]
            f = np.full((N, 2), np.nan)
            f[keep] = np.stack([r.fx, r.fy], axis=1)
            if j.kind == "R":
                size = np.hypot(f[:, 0], f[:, 1])
                unit = np.where(size[:, None] > 0, f / np.where(size > 0, size, 1.0)[:, None], 0.0)
                move = c.value * unit                             # (N, 2): source's element from on's
                part[:, :, k] = np.einsum("ywn,nw->ny", sj, move)
                direction[:, k] = np.arctan2(unit[:, 1], unit[:, 0])
                knocks[c.joint] = _knocks(f[keep], phi[keep], cyclic)
            else:
                n = src.side[(c.joint, j.slider)].value[:, 0, :].T     # (N, 2): the guide's normal
                normal = (f * n).sum(axis=1)
                side = np.sign(normal)
                part[:, :, k] = (sj[:, 0, :] * (c.value * side)).T
                direction[:, k] = np.arctan2(side * n[:, 1], side * n[:, 0])
                knocks[c.joint] = _knocks(normal[keep], phi[keep], cyclic)
        c0 += width
    error = part.sum(axis=2)
    invalid = ~sol.valid
    for arr in (error, worst):
        arr[invalid] = np.nan
    part[invalid] = np.nan
    return ClearanceErrors(tuple(c.joint for c in clearances), np.array([c.value for c in clearances]), loaded,
                           error, part, worst, direction, knocks)
