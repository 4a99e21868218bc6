"""Exact sensitivities of every point, link angle and joint value to every toleranced dimension over the
cycle, from the loop equations' Jacobian by the implicit function theorem.

At a solved position q of the closure equations Φ(q, φ, p) = 0, a change of the dimensions p moves the
solution by dq/dp = −J_q⁻¹ ∂Φ/∂p. The engine solves block by block (`BlockSolver`); in each block the
tree joints place the links from their parents, the cut joints close the loops, and a rate pass gives
J_q's columns, the links' rates and the velocities (`_blocks`). Sensitivities are one more such pass,
with a column per dimension and with source terms: ∂Φ/∂p is what the made geometry (`geometry.Sided`)
changes in each joint law at fixed q, analytically:

- a revolute pair, tree or cut: R_a·δs_a − R_b·δs_b, its two points' moves seen in the world;
- a prismatic pair: the line point's and the slider point's moves across the guide, n·(R_s·δs_s − R_c·δs_l),
  and the guide's turn δγ times perp(n)·Δ (Δ the slider point from the line point), or, as a tree joint,
  R_c·δs_l − R_s·δs_s + q·δγ·perp(u);
- the input: δzero − δα_b + δα_a (its value is measured between the links' reference lines).

The pass reuses each block's factorised Jacobian from the position solve (the factorisation the rates
use) and its sensitivities of the links' rates to the block's unknowns; its cost is that of a rate
pass with K columns. Outputs: a point P on link k moves by v_k + ω_k·perp(R_k s) + R_k·δs_P, a link's
angle by ω_k + δα_k, a revolute joint's value by the difference of its links', a prismatic joint's by
u·(δX_s − δX_l) + (ω_c + δγ)·perp(u)·Δ, less its change at the drawn pose (the value is measured from
there). Everything is SI per SI unit of the dimension.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..engine._constraints import Rates, perp
from ..errors import ModelError
from .spec import closest

__all__ = ["Output", "Sensitivities", "resolve_outputs", "sensitivities", "Sources", "source_pass",
           "output_rates"]


@dataclass(frozen=True)
class Output:
    """One reported quantity: `name` ("M.x", "3.angle", "B.value"), `kind` ("x", "y", "angle", "value"),
    `target` (the point, joint or link) and `unit` ("m" or "rad")."""

    name: str
    kind: str
    target: str
    unit: str


def resolve_outputs(mech, names=None, source: str | None = None) -> tuple[Output, ...]:
    """The outputs `names` stand for (None: every joint and point, x and y, and every moving link's
    angle). A joint or point name gives its x and y, a link's its angle; X.x, X.y, L.angle and J.value
    name one each (J.value: a revolute pair's relative angle, a prismatic pair's displacement from the
    drawn pose).

    Raises
    ------
    ModelError
        A name the model does not have (with the closest), or one that is both a link and a point.
    """
    places = list(mech.joints) + list(mech.points)
    links = mech.moving_links
    if names is None:
        names = places + links

    def point(name):
        return (Output(f"{name}.x", "x", name, "m"), Output(f"{name}.y", "y", name, "m"))

    def angle(name):
        return Output(f"{name}.angle", "angle", name, "rad")

    out = []
    for raw in names:
        name = str(raw)
        base, _, what = name.rpartition(".")
        if base and what in ("x", "y") and base in places:
            out.append(point(base)["xy".index(what)])
        elif base and what == "angle" and base in links:
            out.append(angle(base))
        elif base and what == "value" and base in mech.joints:
            kind = mech.joints[base].kind
            out.append(Output(name, "value", base, "rad" if kind == "R" else "m"))
        elif name in places and name in links:
            raise ModelError(f"outputs: '{name}' is both a link and a point: write {name}.angle or {name}.x, "
                             f"{name}.y", source=source, where="[tolerances]")
        elif name in places:
            out.extend(point(name))
        elif name in links:
            out.append(angle(name))
        else:
            every = places + links + [f"{p}.{w}" for p in places for w in "xy"] + [f"{n}.angle" for n in links]
            raise ModelError(f"outputs: '{name}' is not a joint, point or moving link of the model"
                             f"{closest(name, every)}", source=source, where="[tolerances]")
    seen = set()
    unique = []
    for o in out:
        if o.name not in seen:
            seen.add(o.name)
            unique.append(o)
    return tuple(unique)


@dataclass(frozen=True)
class Sensitivities:
    """The sensitivities of `outputs` to `dimensions` over the positions `phi`.

    phi (N, n_in) SI; valid (N,) the positions solved on the drawn branch; value (N, Y) the outputs'
    nominal values (m, rad); d (N, Y, K) ∂output/∂dimension, SI per SI unit of the dimension (NaN where
    not valid).
    """

    phi: np.ndarray
    valid: np.ndarray
    outputs: tuple
    dimensions: tuple
    value: np.ndarray
    d: np.ndarray

    @property
    def success(self) -> bool:
        return bool(self.valid.all())

    @property
    def message(self) -> str:
        bad = int((~self.valid).sum())
        return "solved" if not bad else f"{bad} position(s) not reached on the drawn branch"


@dataclass
class Sources:
    """What a perturbation changes at fixed q, seen in the world, for C columns over B positions:
    `side[(joint, link)]` (2, C, B) moves of the joints' points, `turn[joint]` (C, B) turns of the prismatic
    pairs' guides, `point[name]` (2, C, B) moves of the points of interest, `alpha[link]` (C, B) turns of the
    links' reference lines in their frames, `input` (n_in, C, B) changes of the inputs' joint values.
    Absent entries are zero."""

    columns: int
    side: dict
    turn: dict
    point: dict
    alpha: dict
    input: np.ndarray


def _rotated(c, s, vec):
    """R(θ)·vec for cos, sin (B,) and vec (2, C) → (2, C, B)."""
    out = np.empty((2, vec.shape[1], c.shape[0]))
    out[0] = vec[0][:, None] * c - vec[1][:, None] * s
    out[1] = vec[0][:, None] * s + vec[1][:, None] * c
    return out


def dimension_sources(engine, sol, deriv) -> Sources:
    """The sources of the K toleranced dimensions (`deriv`: `DesignSpace.derivatives()`, per SI unit) at
    the solved positions `sol`."""
    pose = sol.pose
    B = len(sol.phi)
    K = deriv.zero.shape[1]
    side = {(j, k): _rotated(pose.c[k], pose.s[k], v) for (j, k), v in deriv.side.items() if np.any(v)}
    point = {}
    for name, v in deriv.point.items():
        if np.any(v):
            link = engine.mech.points[name].link
            point[name] = _rotated(pose.c[link], pose.s[link], v)
    turn = {}
    for name, u in deriv.guide.items():
        u0 = engine.laws[name].u0
        t = u0[0] * u[1] - u0[1] * u[0]      # the guide's turn: u0 × δu
        if np.any(t):
            turn[name] = np.broadcast_to(t[:, None], (K, B))
    alpha = {k: np.broadcast_to(a[:, None], (K, B)) for k, a in deriv.alpha.items() if np.any(a)}
    inp = np.zeros((len(engine.inputs), K, B))
    for i, i_spec in enumerate(engine.inputs):
        j = engine.mech.joints[i_spec.joint]
        change = deriv.zero[i].copy()
        if j.kind == "R":
            change = change - deriv.alpha[j.links[1]] + deriv.alpha[j.links[0]]
        inp[i] = change[:, None]
    return Sources(K, side, turn, point, alpha, inp)


def source_pass(engine, sol, src: Sources) -> Rates:
    """The links' changes (w (C, B) and v (2, C, B) per link, in a `Rates`) for the sources `src`: a rate
    pass through every block with the sources added, each block's unknowns solved with the factors of
    its Jacobian kept from the position solve."""
    B, C = len(sol.phi), src.columns
    known = Rates(B, C)
    zero = np.zeros((C, B))
    none = np.zeros((2, C, B))
    for bp, state in zip(engine.solver.blocks, sol.blocks):
        for st, cache in zip(bp.steps, state.caches):
            qd = zero if st.var is not None else st.sign * src.input[st.input]
            st.law.place_rates(cache, known, st.parent, st.child, qd, st.relative)
            added = _tree_source(st, cache, src, none)
            if added is not None:
                w, v = known.get(st.child)
                known.set(st.child, w, v + added)
        if not bp.m:
            continue
        rows = []
        for law, cache in zip(bp.cuts, state.cut_caches):
            r = law.closure_rates(cache, known)
            rows.append(r + _cut_source(law, cache, src, none))
        rhs = np.concatenate(rows)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            dq = np.stack([state.lu.solve(-rhs[:, k]) for k in range(C)], axis=1) if C else \
                np.zeros((bp.m, 0, B))                                                    # (m, C, B)
        for link in bp.links:
            w, v = known.get(link)
            sw, sv = state.sens.w[link], state.sens.v[link]
            known.set(link, w + np.einsum("mb,mcb->cb", sw, dq), v + np.einsum("xmb,mcb->xcb", sv, dq))
    return known


def _tree_source(st, cache, src: Sources, none):
    law = st.law
    if law.kind == "R":
        a, b = src.side.get((law.name, st.parent)), src.side.get((law.name, st.child))
        if a is None and b is None:
            return None
        return (none if a is None else a) - (none if b is None else b)
    sign, u, q, pu = cache
    line, slide = src.side.get((law.name, law.carrier)), src.side.get((law.name, law.slider))
    turn = src.turn.get(law.name)
    if line is None and slide is None and turn is None:
        return None
    out = (none if line is None else line) - (none if slide is None else slide)
    if turn is not None:
        out = out + (q * turn) * pu[:, 0][:, None, :]
    return sign * out


def _cut_source(law, cache, src: Sources, none):
    if law.kind == "R":
        a, b = src.side.get((law.name, law.links[0])), src.side.get((law.name, law.links[1]))
        return (none if a is None else a) - (none if b is None else b)
    n, _, _, _, _, pn_delta = cache
    line, slide = src.side.get((law.name, law.carrier)), src.side.get((law.name, law.slider))
    out = np.zeros_like(none)
    if line is not None or slide is not None:
        d = (none if slide is None else slide) - (none if line is None else line)
        out[1] = n[0] * d[0] + n[1] * d[1]
    turn = src.turn.get(law.name)
    if turn is not None:
        out[1] += turn * pn_delta
    return out


def output_rates(engine, sol, known: Rates, src: Sources, outputs) -> np.ndarray:
    """The outputs' changes (Y, C, B) from the links' changes `known` and the sources `src` (a prismatic
    joint's value: its change at these positions, not less its drawn pose's)."""
    pose, mech = sol.pose, engine.mech
    C, B = src.columns, len(sol.phi)
    out = np.empty((len(outputs), C, B))
    none = np.zeros((2, C, B))

    def moved(link, at, extra):
        """δX (2, C, B) of the material point drawn at `at` on `link`."""
        w, v = known.get(link)
        rho = np.stack([pose.c[link] * at[0] - pose.s[link] * at[1], pose.s[link] * at[0] + pose.c[link] * at[1]])
        return v + w * perp(rho)[:, None, :] + (none if extra is None else extra)

    def angle(link):
        w = known.get(link)[0]
        a = src.alpha.get(link)
        return w if a is None else w + a

    for y, o in enumerate(outputs):
        if o.kind in ("x", "y"):
            if o.target in mech.joints:
                j = mech.joints[o.target]
                link = j.slider if j.kind == "P" else j.links[0]
                d = moved(link, np.array(j.at), src.side.get((j.name, link)))
            else:
                p = mech.points[o.target]
                d = moved(p.link, np.array(p.at), src.point.get(p.name))
            out[y] = d["xy".index(o.kind)]
        elif o.kind == "angle":
            out[y] = angle(o.target)
        else:
            j = mech.joints[o.target]
            if j.kind == "R":
                out[y] = angle(j.links[1]) - angle(j.links[0])
                continue
            car, sli = j.carrier, j.slider
            at = np.array(j.at)
            ds = moved(sli, at, src.side.get((j.name, sli)))
            dl = moved(car, at, src.side.get((j.name, car)))
            u = pose.rot(car, engine.laws[j.name].u0)
            xs = pose.r[sli] + pose.rot(sli, at)
            xl = pose.r[car] + pose.rot(car, at)
            pu_delta = perp(u)[0] * (xs - xl)[0] + perp(u)[1] * (xs - xl)[1]
            turn = known.get(car)[0] + src.turn.get(j.name, 0.0)
            out[y] = u[0][None] * (ds - dl)[0] + u[1][None] * (ds - dl)[1] + turn * pu_delta[None]
    return out


def nominal_values(engine, sol, outputs) -> np.ndarray:
    """The outputs' values (B, Y) at the solved positions (m, rad)."""
    pose, mech = sol.pose, engine.mech
    out = np.empty((len(sol.phi), len(outputs)))
    for y, o in enumerate(outputs):
        if o.kind in ("x", "y"):
            if o.target in mech.joints:
                j = mech.joints[o.target]
                link = j.slider if j.kind == "P" else j.links[0]
                at = np.array(j.at)
            else:
                link = mech.points[o.target].link
                at = np.array(mech.points[o.target].at)
            out[:, y] = (pose.r[link] + pose.rot(link, at))["xy".index(o.kind)]
        elif o.kind == "angle":
            out[:, y] = pose.th[o.target] + engine.reference_angle[o.target]
        else:
            j = mech.joints[o.target]
            if j.kind == "R":
                out[:, y] = pose.th[j.links[1]] - pose.th[j.links[0]] + engine.joint_value_drawn[j.name]
            else:
                at = np.array(j.at)
                d = pose.r[j.slider] + pose.rot(j.slider, at) - pose.r[j.carrier] - pose.rot(j.carrier, at)
                u = pose.rot(j.carrier, engine.laws[j.name].u0)
                out[:, y] = u[0] * d[0] + u[1] * d[1]
    return out


def sensitivities(space, phi, outputs=None) -> Sensitivities:
    """∂(outputs)/∂(toleranced dimensions) at input values `phi` (SI; (N,) or (N, n_in)).

    Parameters
    ----------
    space : DesignSpace
        The model's engine and its toleranced dimensions (`geometry.DesignSpace`).
    phi : array_like
        Input values, SI.
    outputs : sequence of Output, optional
        Default: every joint and point (x, y) and every moving link's angle.

    Returns
    -------
    Sensitivities
    """
    engine = space.engine
    outputs = tuple(outputs) if outputs is not None else resolve_outputs(engine.mech)
    phi = np.asarray(phi, float)
    phi = phi.reshape(len(phi), -1) if phi.ndim >= 1 else phi.reshape(1, 1)
    n = len(phi)
    values = any(o.kind == "value" and engine.mech.joints[o.target].kind == "P" for o in outputs)
    at = np.concatenate([phi, engine.phi_drawn[None, :]]) if values else phi
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        sol = engine.solve(at)
        src = dimension_sources(engine, sol, space.derivatives())
        known = source_pass(engine, sol, src)
        d = output_rates(engine, sol, known, src, outputs)      # (Y, K, B)
        value = nominal_values(engine, sol, outputs)
    if values:
        for y, o in enumerate(outputs):
            if o.kind == "value" and engine.mech.joints[o.target].kind == "P":
                d[y] -= d[y][:, -1:]
        d, value = d[..., :n], value[:n]
    valid = sol.valid[:n].copy()
    d = np.moveaxis(d, 2, 0)
    d[~valid] = np.nan
    value[~valid] = np.nan
    return Sensitivities(phi, valid, outputs, space.names, value, d)
