"""Seed 001's synthesis end to end: candidates by form (a), (b) or (c), ranked by the seed's objective,
checked for defects by mbplanar, and returned as a model whose analysed foot path gives Δ1 and Δ2.

The ranking uses `guiding.foot_paths` over a batch of candidates (fast, closed form); the reported
design and every number reported for it come from mbplanar's analysis of the written model.
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass

import numpy as np

from ..engine import Engine
from ..errors import ModelError
from ..kinematics import analyse
from ._models import guiding_slider_toml, read_design
from .defects import Defects, check_defects
from .guiding import (SEED001_CHAIN, Candidates, Chain, WalkingTarget, form_a, form_b, form_c,
                      guiding_poses, node_configurations, seed_objective)

__all__ = ["GuidingResult", "synthesise_seed001", "walking_deviations"]


@dataclass(frozen=True)
class GuidingResult:
    """A defect-free guiding crank-slider for a walking foot and its errors, from mbplanar's analysis of
    the model `toml`.

    Attributes
    ----------
    design : dict
        l (m), gamma_deg, k, d (m), theta_deg, rho (m): the guided rod point and the line; the crank's
        sense (+1 or -1) and the chain's assembly modes at the nodes.
    toml : str
        The model's TOML text (crank "1", rod "2", slider; foot point "E").
    mechanism : Mechanism
        The model read back from `toml`.
    target : WalkingTarget
        The foot path asked for.
    nodes : (n, 2) ndarray
        The interpolation nodes, m.
    node_phi : (n,) ndarray
        The model's crank angle at each node, rad.
    node_errors : (n,) ndarray
        The analysed foot's distance from each node, m.
    delta1, delta2 : float
        The seed's deviations (15), m: the foot's largest distance from the support line over the
        segment, and the path's top point's distance from the required height (`delta` is their sum).
    path : (P, 2) ndarray
        The analysed foot path over a crank turn, m.
    defects : Defects
        mbplanar's check of the design.
    candidates, checked : int
        Candidate designs scored; candidates put through the defect check.
    rejected : list of dict
        The checked candidates that failed, with their defects.
    seconds : float
        Wall time of the synthesis.

    Examples
    --------
    >>> from mbplanar.synthesis import WalkingTarget, synthesise_seed001
    >>> r = synthesise_seed001(WalkingTarget(0.0, -2.6, 1.0, 0.2, -1), theta_deg=(165.0, 180.0, 1.0))
    >>> r.defects.ok, r.path.shape, bool(r.node_errors.max() < 1e-9)
    (True, (3600, 2), True)
    """

    design: dict
    toml: str
    mechanism: object
    target: WalkingTarget
    nodes: np.ndarray
    node_phi: np.ndarray
    node_errors: np.ndarray
    delta1: float
    delta2: float
    path: np.ndarray
    defects: Defects
    candidates: int
    checked: int
    rejected: list
    seconds: float

    @property
    def delta(self) -> float:
        return self.delta1 + self.delta2


def _candidates(chain, nodes, form, fit, theta, gamma) -> Candidates:
    """Every candidate of the form, over every combination of the chain's modes at the nodes."""
    parts = []
    for modes in itertools.product((1, -1), repeat=len(nodes)):
        try:
            if form == "b":
                parts.append(form_b(chain, nodes, theta, modes, fit))
            elif form == "a":
                parts.append(form_a(chain, nodes, gamma, modes))
            else:
                parts.append(form_c(chain, nodes, modes))
        except np.linalg.LinAlgError:
            continue
    cand = Candidates.join(parts) if parts else None
    if cand is None or not len(cand):
        raise ModelError("no candidate design: the node equations have no real solution")
    keep = np.isfinite(cand.rho) & np.isfinite(cand.p2) & np.isfinite(cand.p3) & (cand.l > 1e-9)
    return cand.take(np.flatnonzero(keep))


def _crank_senses(phi1) -> np.ndarray:
    """Per candidate (rows of node crank angles (D, n)): +1 if the crank reaches the nodes in order
    turning counter-clockwise, −1 clockwise, 0 neither."""
    out = np.zeros(len(phi1), int)
    for s in (-1, 1):
        u = np.mod(s * (phi1 - phi1[:, :1]), 2 * math.pi)
        out[np.all(np.diff(u, axis=1) > 0, axis=1)] = s
    return out


def _ranked(chain, target, nodes, cand, phi):
    """Node configurations (with the crank sense per candidate) and the seed's objective Δ1 + Δ2 of
    every candidate (inf for a candidate whose nodes are on two circuits or out of order, which are not
    traced at all)."""
    conf = node_configurations(chain, cand, nodes)
    sigma = conf["sigma"]
    conf["sense"] = _crank_senses(conf["phi1"])
    live = np.flatnonzero(np.all(sigma == sigma[:, :1], axis=1) & (conf["sense"] != 0))
    score = np.full(len(cand), np.inf)
    if len(live):
        path, ok = guiding_poses(chain, cand.take(live), sigma[live, 0], phi)[2:]
        d1, d2 = seed_objective(target, path, ok)
        score[live] = d1 + d2
    return conf, score


def _model_text(chain, cand_one: Candidates, sigma, phi1, sense, comment) -> str:
    b, c, e, _ = guiding_poses(chain, cand_one, sigma[:1], [phi1])
    return guiding_slider_toml(chain.pivot, b[0, 0], c[0, 0], e[0, 0], math.degrees(cand_one.theta[0]) % 180.0,
                               sense=sense, comment=comment)


def _design(cand_one: Candidates, sense) -> dict:
    theta = float(cand_one.theta[0]) % math.pi
    vertical = abs(math.cos(theta)) < 1e-12
    return {"l": float(cand_one.l[0]), "gamma_deg": math.degrees(float(cand_one.gamma[0])),
            "k": None if vertical else math.tan(theta), "d": None if vertical else float(cand_one.rho[0]) / math.cos(theta),
            "theta_deg": math.degrees(theta), "rho": float(cand_one.rho[0]), "crank_sense": int(sense),
            "chain_modes": [int(m) for m in cand_one.elbow[0]]}


def synthesise_seed001(target: WalkingTarget, chain: Chain = SEED001_CHAIN, form: str = "b",
                       support_nodes: int | None = None, spacing: str = "chebyshev", fit: str = "exact",
                       theta_deg=(0.0, 180.0, 1.0), gamma_deg=(0.0, 360.0, 1.0), samples: int = 720,
                       max_checks: int = 20) -> GuidingResult:
    """Synthesise seed 001's guiding crank-slider for a D-shaped foot path by interpolation.

    The seed's chain (crank and rod) gets a slider guiding a point C of the rod on a straight line,
    chosen so that the foot E passes exactly through nodes of the target (or closest to them by least
    squares or minimax); the candidates are ranked by the seed's objective Δ = Δ1 + Δ2, and the best
    that passes mbplanar's defect check (full turn, one circuit, nodes in order) is returned.

    Parameters
    ----------
    target : WalkingTarget
        The D-shaped foot path.
    chain : Chain
        Crank, rod and crank pivot (the seed's by default).
    form : {"a", "b", "c"}
        (b): scan the line's direction θ (`theta_deg`; the seed scans k over 0–90°); (a): scan γ
        (`gamma_deg`); (c): no scan, 4 nodes.
    support_nodes : int, optional
        Nodes on the support segment (default 2 for (a) and (b), 3 for (c)); the top point is the last.
    spacing : {"chebyshev", "uniform"}
        Spacing of the nodes on the support segment.
    fit : {"exact", "lsq", "minimax"}
        Form (b) with more than 3 nodes needs "lsq" or "minimax".
    theta_deg, gamma_deg : (3,) tuple of float
        (from, to, step) of the scanned line direction θ (form (b)) or rod angle γ (form (a)), degrees.
    samples : int
        Crank positions per turn for ranking the candidates.
    max_checks : int
        Candidates (best first) put through mbplanar's defect check before giving up.

    Returns
    -------
    GuidingResult
        The best defect-free design, with its deviations from mbplanar's analysis of its model.

    Raises
    ------
    ModelError
        An unknown `form`, `spacing` or `fit`, fewer than 2 support nodes, a non-positive length or
        height, a node out of the chain's reach, or no candidate without a defect among the best
        `max_checks` (the message gives the first one's defects).

    Examples
    --------
    >>> from mbplanar.synthesis import WalkingTarget, synthesise_seed001
    >>> r = synthesise_seed001(WalkingTarget(0.0, -2.6, 1.0, 0.2, -1), theta_deg=(165.0, 180.0, 1.0))
    >>> r.design["theta_deg"], round(float(r.delta1), 6), round(float(r.delta2), 6)     # deg, m, m
    (172.0, 0.001949, 0.000735)
    """
    t0 = time.perf_counter()
    if form not in ("a", "b", "c"):
        raise ModelError(f"form must be 'a', 'b' or 'c', got {form!r}")
    if target.length <= 0 or target.height <= 0:
        raise ModelError("the support length and the step height must be positive")
    support = support_nodes or (3 if form == "c" else 2)
    nodes = target.nodes(support, spacing)
    theta = np.radians(np.arange(*theta_deg))
    gamma = np.radians(np.arange(*gamma_deg))
    phi = np.linspace(0.0, 2 * math.pi, samples, endpoint=False)
    cand = _candidates(chain, nodes, form, "lsq" if fit == "minimax" else fit, theta, gamma)
    conf, score = _ranked(chain, target, nodes, cand, phi)
    scored = len(cand)
    if fit == "minimax":        # the linear programmes only for the best least-squares candidates
        best = [i for i in np.argsort(score, kind="stable")[:4 * max_checks] if np.isfinite(score[i])]
        parts = [form_b(chain, nodes, cand.theta[i:i + 1], cand.elbow[i], "minimax") for i in best]
        if not parts:
            raise ModelError(f"no feasible design among {len(cand)} least-squares candidates")
        cand = Candidates.join(parts)
        conf, score = _ranked(chain, target, nodes, cand, phi)
        scored += len(cand)
    sigma = conf["sigma"]
    senses = conf["sense"]
    order = np.argsort(score, kind="stable")
    rejected, checked = [], 0
    for i in order[:max_checks]:
        if not np.isfinite(score[i]):
            break
        checked += 1
        one = cand.take([i])
        s = int(senses[i])
        phi1 = conf["phi1"][i]
        b, c, e, _ = guiding_poses(chain, one, sigma[i], phi1[None, :])
        text = _model_text(chain, one, sigma[i], phi1[0], s, _comment(target, one, form))
        mech = read_design(text)
        engine = Engine(mech)
        node_phi = s * phi1
        defects = check_defects(engine, node_phi, {"E": e[0], "C": c[0]}, full_turn=True,
                                tol=1e-7 * _size(chain))
        if not defects.ok:
            rejected.append({"candidate": int(i), "defects": defects.describe()})
            continue
        d1m, d2m, full = walking_deviations(engine, target, defects.node_phi[0])
        motion = analyse(engine, np.asarray(defects.node_phi))
        errors = np.hypot(*(motion.xy[:, motion.point("E")] - nodes).T)
        return GuidingResult(_design(one, s), text, mech,
                             target, nodes, np.asarray(defects.node_phi), errors, d1m, d2m, full, defects,
                             scored, checked, rejected, time.perf_counter() - t0)
    reason = f"; the best {checked} failed mbplanar's defect check: {rejected[0]['defects']}" if rejected else ""
    raise ModelError(f"no feasible design among {len(cand)} candidates (none turns fully through the nodes "
                     f"on one circuit in order){reason}")


def _size(chain: Chain) -> float:
    return chain.a + chain.b + math.hypot(*chain.pivot)


def _comment(target: WalkingTarget, one: Candidates, form: str) -> str:
    return (f"Synthesised by mbplanar synth seed001, form ({form}).\n"
            f"Target: support y = {target.y0!r} from x = {target.x_start!r} over {target.length!r}, "
            f"height {target.height!r}.\n"
            f"Guide line: theta = {math.degrees(float(one.theta[0])) % 180.0!r} deg, rho = {float(one.rho[0])!r}; "
            f"rod point C: l = {float(one.l[0])!r}, gamma = {math.degrees(float(one.gamma[0]))!r} deg.")


def _zoom(engine, phi, values, refine, passes: int = 10, points: int = 21):
    """Maximum of values(motion) over the input near the best sample of `phi`, by zooming `passes`
    times into ±1 grid step around the best (each pass narrows the step by (points − 1)/2)."""
    best = int(np.nanargmax(values))
    step = float(np.max(np.abs(np.diff(phi)))) if len(phi) > 1 else 0.0
    x, v = float(phi[best]), float(values[best])
    for _ in range(passes):
        grid = x + np.linspace(-step, step, points)
        m = analyse(engine, grid)
        vals = refine(m)
        if not len(vals) or not np.isfinite(vals).any():
            break
        k = int(np.nanargmax(vals))
        if vals[k] >= v:
            x, v = float(m.phi[k, 0]), float(vals[k])
        step *= 2.0 / (points - 1)
    return v


def walking_deviations(engine, target: WalkingTarget, phi_start: float, steps: int = 3600):
    """The seed's Δ1 and Δ2 (15) of the model's foot E over a crank turn from `phi_start` (SI), from
    mbplanar's analysis, each maximum refined by zooming to ~1e-12 in the input. Δ1 = max |y − y0| over
    the support part (x in the segment, y below y0 + height/2); Δ2 = |max y − (y0 + height)|.
    Also returns the analysed path (steps, 2)."""
    phi = phi_start + np.linspace(0.0, 2 * math.pi, steps, endpoint=False)
    motion = analyse(engine, phi)
    if len(motion.phi) != steps:
        raise ModelError("the design does not turn fully (mbplanar met a motion limit)")
    lo, hi = target.x_start, target.x_start + target.length

    def support_dev(m):
        xy = m.xy[:, m.point("E")]
        inside = (xy[:, 0] >= lo) & (xy[:, 0] <= hi) & (xy[:, 1] < target.y0 + 0.5 * target.height)
        return np.where(inside, np.abs(xy[:, 1] - target.y0), -np.inf)

    def height(m):
        return m.xy[:, m.point("E"), 1]

    path = motion.xy[:, motion.point("E")].copy()
    dev = support_dev(motion)
    if not np.isfinite(dev).any():
        raise ModelError("the foot path has no support part over the segment")
    d1 = _zoom(engine, phi, dev, support_dev)
    top = _zoom(engine, phi, height(motion), height)
    return d1, abs(top - target.top[1]), path
