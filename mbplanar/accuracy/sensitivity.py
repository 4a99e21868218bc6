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
- the input: δzero − δα_b + δα_a (its value is measured between the links' reference lines);
- a higher pair (gear, rack, cam, slot; always a cut): its residuals' change with its made numbers at fixed
  q and contact parameter, by the complex step through the law's own closure (`higher.sources`).

The pass reuses each block's factorised Jacobian from the position solve (the factorisation the rates
use) and its sensitivities of the links' rates to the block's unknowns; its cost is that of a rate
pass with K columns. Outputs: a point P on link k moves by v_k + ω_k·perp(R_k s) + R_k·δs_P, a link's
angle by ω_k + δα_k, a revolute joint's value by the difference of its links', a prismatic joint's by
u·(δX_s − δX_l) + (ω_c + δγ)·perp(u)·Δ, less its change at the drawn pose (the value is measured from
there). Everything is SI per SI unit of the dimension.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..engine import Rates, perp, solve_positions
from ..errors import ModelError
from . import higher
from .geometry import STEP
from .spec import closest

CHUNK = 20_000   # positions per Dask task

__all__ = ["Output", "Sensitivities", "resolve_outputs", "sensitivities", "Sources", "Patch", "source_pass",
           "output_rates"]


@dataclass(frozen=True)
class Output:
    """One reported quantity of a model: a point's coordinate, a link's angle or a joint's value.

    Attributes
    ----------
    name : str
        "M.x", "3.angle", "B.value", ...
    kind : {"x", "y", "angle", "value"}
        What is measured.
    target : str
        The point, joint or link.
    unit : {"m", "rad"}
        Its SI unit.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.accuracy import resolve_outputs
    >>> out = resolve_outputs(mbplanar.read_model("models/slider_crank.toml"), ["Bp.value"])[0]
    >>> out.kind, out.target, out.unit            # the slider's displacement along its guide
    ('value', 'Bp', 'm')
    """

    name: str
    kind: str
    target: str
    unit: str


def resolve_outputs(mech, names=None, source: str | None = None) -> tuple[Output, ...]:
    """The outputs that names stand for, in order, each once.

    Parameters
    ----------
    mech : Mechanism
        The model.
    names : sequence of str, optional
        A joint or point name gives its x and y, a link's its angle; X.x, X.y, L.angle and J.value
        name one each (J.value: a revolute pair's relative angle, a prismatic pair's displacement from
        the drawn pose). None: every joint and point, x and y, and every moving link's angle.
    source : str, optional
        The model file, for the messages.

    Returns
    -------
    tuple of Output
        The outputs.

    Raises
    ------
    ModelError
        A name the model does not have (with the closest), or one that is both a link and a point.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.accuracy import resolve_outputs
    >>> mech = mbplanar.read_model("models/fourbar.toml")
    >>> [o.name for o in resolve_outputs(mech, ["M", "3", "B.value"])]
    ['M.x', 'M.y', '3.angle', 'B.value']
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
    """The sensitivities of outputs to toleranced dimensions over a set of positions.

    Attributes
    ----------
    phi : (N, n_in) ndarray
        The positions' input values, SI.
    valid : (N,) ndarray of bool
        The positions solved on the drawn branch (`success` is True when all are; `message` says how
        many are not).
    outputs : tuple of Output
        The Y outputs.
    dimensions : tuple of Dimension
        The K toleranced dimensions.
    value : (N, Y) ndarray
        The outputs' nominal values, m or rad.
    d : (N, Y, K) ndarray
        ∂output/∂dimension, SI per SI unit of the dimension (NaN where not valid).

    Examples
    --------
    A slider-crank (crank r = 0.1 m, rod l = 0.3 m): the slider's x = r cos φ + √(l² − r² sin² φ), so at
    90° ∂x/∂r = −r/√(l² − r²) and ∂x/∂l = l/√(l² − r²):

    >>> import numpy as np
    >>> from mbplanar.accuracy import DesignSpace, resolve_outputs, sensitivities
    >>> from mbplanar.accuracy.run import load
    >>> template, raw, engine = load("models/slider_crank.toml")
    >>> space = DesignSpace(engine, raw, template, ["links.1.length", "links.2.length"])
    >>> s = sensitivities(space, np.radians([0.0, 90.0]), resolve_outputs(engine.mech, ["Bp.x"]))
    >>> s.d.shape, s.success, s.d[1, 0].round(6).tolist()
    ((2, 1, 2), True, [-0.353553, 1.06066])
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


@dataclass(frozen=True)
class Patch:
    """Moves (2, n, B) of a point in the world for the columns `cols` (n,) of C (the others do not move it):
    a dimension moves few of a mechanism's points."""

    cols: np.ndarray
    value: np.ndarray

    def add_to(self, target, sign: float = 1.0):
        """target (2, C, B) += sign · this (in place)."""
        if sign > 0:
            target[:, self.cols] += self.value
        else:
            target[:, self.cols] -= self.value

    def dense(self, columns: int) -> np.ndarray:
        out = np.zeros((2, columns) + self.value.shape[2:])
        out[:, self.cols] = self.value
        return out


@dataclass
class Sources:
    """What a perturbation changes at fixed q, seen in the world, for C columns over B positions:
    `side[(joint, link)]` (`Patch`) moves of the joints' points, `turn[joint]` (C, B) turns of the prismatic
    pairs' guides, `point[name]` (`Patch`) moves of the points of interest, `alpha[link]` (C, B) turns of
    the links' reference lines in their frames, `input` (n_in, C, B) changes of the inputs' joint values,
    `higher[pair]` (cols (n,), value (rows, n, B)) changes of a higher pair's residuals. Absent entries
    are zero."""

    columns: int
    side: dict
    turn: dict
    point: dict
    alpha: dict
    input: np.ndarray
    higher: dict = field(default_factory=dict)


def _link_arrays(engine, pose):
    """cos θ, sin θ (L, B) and r (2, L, B) of every link, in engine.links order."""
    links = engine.links
    c = np.stack([pose.c[n] for n in links])
    s = np.stack([pose.s[n] for n in links])
    r = np.stack([pose.r[n] for n in links], axis=1)
    return c, s, r


def _turned(c, s, vec) -> Patch:
    """R(θ)·vec for cos, sin (B,) and vectors vec (2, C), for the columns where vec is not zero."""
    cols = np.flatnonzero(np.any(vec != 0, axis=0))
    v = vec[:, cols]
    out = np.empty((2, len(cols), len(c)))
    out[0] = v[0][:, None] * c - v[1][:, None] * s
    out[1] = v[0][:, None] * s + v[1][:, None] * c
    return Patch(cols, out)


def dimension_sources(engine, sol, deriv, frames=None) -> Sources:
    """The sources of the K toleranced dimensions (`deriv`: `DesignSpace.derivatives()`, per SI unit) at
    the solved positions `sol` (`frames`: its `_link_arrays`, when already made)."""
    pose = sol.pose
    B = len(sol.phi)
    K = deriv.zero.shape[1]
    c, s, _ = frames if frames is not None else _link_arrays(engine, pose)
    index = engine.link_index
    side = {(j, k): _turned(c[index[k]], s[index[k]], v) for (j, k), v in deriv.side.items() if np.any(v)}
    point = {}
    for name, v in deriv.point.items():
        if np.any(v):
            k = index[engine.mech.points[name].link]
            point[name] = _turned(c[k], s[k], v)
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
    nominal = {name: higher.nominal_numbers(engine, name, 1) for name in deriv.higher}
    pairs = higher.sources(engine, pose, nominal, deriv.higher, K, STEP)
    return Sources(K, side, turn, point, alpha, inp, pairs)


def _solve_columns(factors, rhs):
    """x with J·x = rhs for every column: rhs (m, C, B), `factors` a block's `ScaledLU` (its inverse for a
    1 × 1 or 2 × 2 block, its LU with the row permutation otherwise), all columns at once."""
    b = rhs * factors.row_scale[:, :, None]
    inner = factors.lu
    if hasattr(inner, "inv"):
        inv = inner.inv
        if inv.shape[0] == 1:
            x = inv[0, 0] * b
        else:
            x = np.empty_like(b)
            x[0] = inv[0, 0] * b[0] + inv[0, 1] * b[1]
            x[1] = inv[1, 0] * b[0] + inv[1, 1] * b[1]
    else:
        lu, n = inner.lu, inner.lu.shape[0]
        x = np.take_along_axis(b, np.broadcast_to(inner.perm[:, None, :], b.shape), axis=0)
        for i in range(1, n):
            x[i] -= np.einsum("jb,jcb->cb", lu[i, :i], x[:i])
        for i in range(n - 1, -1, -1):
            if i < n - 1:
                x[i] -= np.einsum("jb,jcb->cb", lu[i, i + 1:], x[i + 1:])
            x[i] /= lu[i, i]
    return x / factors.var_scale[:, :, None]


def source_pass(engine, sol, src: Sources) -> Rates:
    """The links' changes (w (C, B) and v (2, C, B) per link, in a `Rates`) for the sources `src`: a rate
    pass through every block with the sources added, each block's unknowns solved with the factors of
    its Jacobian kept from the position solve."""
    B, C = len(sol.phi), src.columns
    known = Rates(B, C)
    zero = np.zeros((C, B))
    for bp, state in zip(engine.solver.blocks, sol.blocks):
        for st, cache in zip(bp.steps, state.caches):
            qd = zero if st.var is not None else st.sign * src.input[st.input]
            st.law.place_rates(cache, known, st.parent, st.child, qd, st.relative)
            _tree_source(st, cache, src, known.get(st.child)[1])   # (place_rates made the child's v anew)
        if not bp.m:
            continue
        rows = []
        for law, cache in zip(bp.cuts, state.cut_caches):
            r = law.closure_rates(cache, known)
            _cut_source(law, cache, src, r)
            rows.append(r)
        rhs = np.concatenate(rows)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            dq = _solve_columns(state.lu, -rhs)                                          # (m, C, B)
        for link in bp.links:
            w, v = known.get(link)
            sw, sv = state.sens.w[link], state.sens.v[link]
            known.set(link, w + np.einsum("mb,mcb->cb", sw, dq), v + np.einsum("xmb,mcb->xcb", sv, dq))
    return known


def _tree_source(st, cache, src: Sources, v):
    """Add to a tree joint's child's frame rate v (2, C, B) what the sources move at fixed q: a revolute
    pair's parent point less its child point; a prismatic pair's line point less its slider point and
    q·δγ·perp(u), with the sign of the step (carrier to slider +)."""
    law = st.law
    if law.kind == "R":
        for key, sign in (((law.name, st.parent), 1.0), ((law.name, st.child), -1.0)):
            patch = src.side.get(key)
            if patch is not None:
                patch.add_to(v, sign)
        return
    step, u, q, pu = cache
    for key, sign in (((law.name, law.carrier), step), ((law.name, law.slider), -step)):
        patch = src.side.get(key)
        if patch is not None:
            patch.add_to(v, sign)
    turn = src.turn.get(law.name)
    if turn is not None:
        v += (step * q * turn) * pu[:, 0][:, None, :]


def _cut_source(law, cache, src: Sources, r):
    """Add to a cut joint's closure rates r (2, C, B) what the sources change at fixed q: a revolute
    pair's first point less its second; a prismatic pair's n·(slider point − line point) + δγ·perp(n)·Δ;
    a higher pair's residuals' change (`higher.sources`)."""
    if law.kind not in ("R", "P"):
        got = src.higher.get(law.name)
        if got is not None:
            r[:, got[0]] += got[1]
        return
    if law.kind == "R":
        for key, sign in (((law.name, law.links[0]), 1.0), ((law.name, law.links[1]), -1.0)):
            patch = src.side.get(key)
            if patch is not None:
                patch.add_to(r, sign)
        return
    n, _, _, _, _, pn_delta = cache
    for key, sign in (((law.name, law.slider), 1.0), ((law.name, law.carrier), -1.0)):
        patch = src.side.get(key)
        if patch is not None:
            r[1, patch.cols] += sign * (n[0] * patch.value[0] + n[1] * patch.value[1])
    turn = src.turn.get(law.name)
    if turn is not None:
        r[1] += turn * pn_delta


def _places(engine, outputs) -> list:
    """The joints and points whose x or y is an output: (name, link, drawn point (2,) in the engine's
    frame (`Engine.centre`), source key)."""
    mech, out, seen = engine.mech, [], set()
    centre = np.asarray(engine.centre, float)
    for o in outputs:
        if o.kind not in ("x", "y") or o.target in seen:
            continue
        seen.add(o.target)
        if o.target in mech.joints:
            j = mech.joints[o.target]
            link = j.slider if j.kind == "P" else j.links[0]
            out.append((o.target, link, np.array(j.at, float) - centre, ("side", (j.name, link))))
        else:
            p = mech.points[o.target]
            out.append((o.target, p.link, np.array(p.at, float) - centre, ("point", p.name)))
    return out


def output_rates(engine, sol, known: Rates, src: Sources, outputs, frames=None) -> np.ndarray:
    """The outputs' changes (Y, C, B) from the links' changes `known` and the sources `src` (a prismatic
    joint's value: its change at these positions, not less its drawn pose's)."""
    pose, mech = sol.pose, engine.mech
    C, B = src.columns, len(sol.phi)
    out = np.empty((len(outputs), C, B))
    c, s, _ = frames if frames is not None else _link_arrays(engine, pose)
    index = engine.link_index
    rows = {}
    for y, o in enumerate(outputs):
        rows.setdefault(o.target, {})[o.kind] = y
    for name, link, at, (kind, key) in _places(engine, outputs):
        w, v = known.get(link)
        k = index[link]
        rx, ry = c[k] * at[0] - s[k] * at[1], s[k] * at[0] + c[k] * at[1]       # R·at (B,)
        extra = (src.side if kind == "side" else src.point).get(key)
        for axis, word in enumerate("xy"):
            y = rows[name].get(word)
            if y is None:
                continue
            out[y] = v[axis] - w * ry if axis == 0 else v[axis] + w * rx
            if extra is not None:
                out[y, extra.cols] += extra.value[axis]

    def angle(link):
        w = known.get(link)[0]
        a = src.alpha.get(link)
        return w if a is None else w + a

    for y, o in enumerate(outputs):
        if o.kind == "angle":
            out[y] = angle(o.target)
        elif o.kind == "value" and mech.joints[o.target].kind == "R":
            j = mech.joints[o.target]
            out[y] = angle(j.links[1]) - angle(j.links[0])
        elif o.kind == "value":
            out[y] = _slider_change(engine, pose, known, src, mech.joints[o.target])
    return out


def _slider_change(engine, pose, known, src, j):
    """The change (C, B) of a prismatic joint's displacement u·(X_s − X_l): u·(δX_s − δX_l) + (ω_c + δγ)·perp(u)·Δ."""
    car, sli = j.carrier, j.slider
    at = np.array(j.at) - engine.centre

    def moved(link, extra):
        w, v = known.get(link)
        rho = pose.rot(link, at)
        d = v + w * perp(rho)[:, None, :]
        if extra is not None:
            extra.add_to(d)
        return d

    ds = moved(sli, src.side.get((j.name, sli)))
    dl = moved(car, src.side.get((j.name, car)))
    u = pose.rot(car, engine.laws[j.name].u0)
    delta = pose.r[sli] + pose.rot(sli, at) - pose.r[car] - pose.rot(car, at)
    pu_delta = -u[1] * delta[0] + u[0] * delta[1]
    turn = known.get(car)[0] + src.turn.get(j.name, 0.0)
    return u[0] * (ds - dl)[0] + u[1] * (ds - dl)[1] + turn * pu_delta


def nominal_values(engine, sol, outputs, frames=None) -> np.ndarray:
    """The outputs' values (B, Y) at the solved positions (m, rad)."""
    pose, mech = sol.pose, engine.mech
    out = np.empty((len(sol.phi), len(outputs)))
    c, s, r = frames if frames is not None else _link_arrays(engine, pose)
    places = _places(engine, outputs)
    row = {}
    if places:
        links = np.array([engine.link_index[link] for _, link, _, _ in places])
        at = np.stack([a for _, _, a, _ in places])
        cl, sl = c[links], s[links]
        cx, cy = (float(v) for v in engine.centre)      # (the engine's frame to the world's)
        xy = np.stack([(r[0, links] + cl * at[:, 0, None] - sl * at[:, 1, None]) + cx,
                       (r[1, links] + sl * at[:, 0, None] + cl * at[:, 1, None]) + cy], axis=1)   # (T, 2, B)
        row = {name: t for t, (name, _, _, _) in enumerate(places)}
    for y, o in enumerate(outputs):
        if o.kind in ("x", "y"):
            out[:, y] = xy[row[o.target], "xy".index(o.kind)]
        elif o.kind == "angle":
            out[:, y] = pose.th[o.target] + engine.reference_angle[o.target]
        else:
            j = mech.joints[o.target]
            if j.kind == "R":
                out[:, y] = pose.th[j.links[1]] - pose.th[j.links[0]] + engine.joint_value_drawn[j.name]
            else:
                at = np.array(j.at) - engine.centre
                d = pose.r[j.slider] + pose.rot(j.slider, at) - pose.r[j.carrier] - pose.rot(j.carrier, at)
                u = pose.rot(j.carrier, engine.laws[j.name].u0)
                out[:, y] = u[0] * d[0] + u[1] * d[1]
    return out


def sensitivities(space, phi, outputs=None, client=None, chunk: int = CHUNK) -> Sensitivities:
    """∂(outputs)/∂(toleranced dimensions) at input values `phi` (SI; (N,) or (N, n_in)).

    Parameters
    ----------
    space : DesignSpace
        The model's engine and its toleranced dimensions (`geometry.DesignSpace`).
    phi : array_like
        Input values, SI.
    outputs : sequence of Output, optional
        Default: every joint and point (x, y) and every moving link's angle.
    client : dask.distributed.Client, optional
        Cut the positions into chunks of `chunk`, one Dask task each (`mbplanar.study.cluster`); the
        answer is the serial one.
    chunk : int
        Positions per Dask task (with `client` only).

    Returns
    -------
    Sensitivities
        ∂output/∂dimension at every position (`d`, (N, Y, K)), exact to rounding (the complex step).

    Raises
    ------
    ModelError
        From `resolve_outputs` when the default outputs are built; positions the model does not reach
        on its drawn branch are not an error: they come back NaN with `valid` False.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.accuracy import DesignSpace, sensitivities, resolve_outputs
    >>> from mbplanar.accuracy.run import load
    >>> template, raw, engine = load("models/slider_crank.toml")
    >>> space = DesignSpace(engine, raw, template, ["links.2.length"])
    >>> s = sensitivities(space, np.radians([90.0]), resolve_outputs(engine.mech, ["Bp.x"]))
    >>> round(float(s.d[0, 0, 0]), 6)        # l/√(l² − r²) with r = 0.1, l = 0.3: m per m
    1.06066
    """
    engine = space.engine
    outputs = tuple(outputs) if outputs is not None else resolve_outputs(engine.mech)
    phi = np.asarray(phi, float)
    phi = phi.reshape(len(phi), -1) if phi.ndim >= 1 else phi.reshape(1, 1)
    if client is not None and len(phi) > chunk:
        from ..study.cluster import run_on_client
        parts = [phi[k:k + chunk] for k in range(0, len(phi), chunk)]
        got = run_on_client(client, _task, space, space.source, parts, (outputs,))
        return Sensitivities(phi, np.concatenate([g.valid for g in got]), outputs, space.names,
                             np.concatenate([g.value for g in got]), np.concatenate([g.d for g in got]))
    n = len(phi)
    values = any(o.kind == "value" and engine.mech.joints[o.target].kind == "P" for o in outputs)
    at = np.concatenate([phi, engine.phi_drawn[None, :]]) if values else phi
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        sol = solve_positions(engine, at)
        frames = _link_arrays(engine, sol.pose)
        src = dimension_sources(engine, sol, space.derivatives(), frames)
        known = source_pass(engine, sol, src)
        d = output_rates(engine, sol, known, src, outputs, frames)      # (Y, K, B)
        value = nominal_values(engine, sol, outputs, frames)
    if values:
        for y, o in enumerate(outputs):
            if o.kind == "value" and engine.mech.joints[o.target].kind == "P":
                d[y] -= d[y][:, -1:]
        d, value = d[..., :n], value[:n]
    valid = sol.valid[:n].copy()
    d = np.moveaxis(d, 2, 0)
    if not valid.all():
        d = d.copy()
        d[~valid] = np.nan
        value[~valid] = np.nan
    return Sensitivities(phi, valid, outputs, space.names, value, d)


def _task(space, source, part, outputs):
    return sensitivities(space, part, outputs)
