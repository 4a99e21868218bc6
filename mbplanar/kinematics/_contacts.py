"""The contacts of the higher pairs over a motion: where each one touches, its common normal, how fast the
surfaces slide there and the pressure angle.

`contact_geometry(engine, motion)` reads the link frames and the contact parameters a `Motion` holds:

- gear: the pitch point (a point of the carrier), the normal along the line of centres, out of gear a;
- rack: the pitch point (the pinion's centre moved by its pitch radius square to the rack's line), the
  normal from the pinion's centre to it;
- cam: the contact point on the profile, the normal out of the cam (its material is inside a closed
  profile; on an open one, away from the follower);
- slot: the pin's centre, the normal to the slot's centre line (to its left).

`contacts(engine, motion)` adds the sliding speed and the pressure angle (`Contact`). The pressure angle
of a cam or a slot is the angle between the common normal (the direction of the contact force) and the
direction in which the driven link's point moves when the contact is released, the other link held (the
motion the contact drives: the follower's own guide or pivot); it is the cam designer's pressure angle,
defined on a dwell too, where the actual velocity is zero. It is signed counter-clockwise from that
direction (taken away from the other link) to the normal (taken into the driven link). For gears and
racks it is the pair's own pressure angle.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..engine import Engine, solve_positions

__all__ = ["Contact", "ContactGeometry", "contact_geometry", "contacts"]


@dataclass(frozen=True)
class ContactGeometry:
    """Where a higher pair touches, over a batch of B positions (`contact_geometry`).

    Attributes
    ----------
    name, kind : str
        The pair's name and kind ("gear", "rack", "cam", "slot").
    links : tuple of str
        The pair's two links.
    point : ndarray, shape (B, 2)
        The contact point (m): a gear's pitch point, a rack's pitch point, a cam's contact on its profile,
        a slot's pin centre.
    normal : ndarray, shape (B, 2)
        The unit common normal, from the first link's side into the second's.
    tangent : ndarray, shape (B, 2)
        The normal turned by +90°.
    parameter : ndarray, shape (B,)
        The contact's place on its curve (the cam's or slot's curve parameter); NaN for a gear or a rack.

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> from mbplanar.kinematics import contact_geometry
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/geared_five_bar.toml"))
    >>> g = contact_geometry(engine, mbplanar.analyse(engine, [1.0]))["G"]
    >>> g.kind, g.links, g.point.round(6), g.normal.round(6), bool(np.isnan(g.parameter[0]))
    ('gear', ('1', '4'), array([[0.04, 0.  ]]), array([[1., 0.]]), True)
    """

    name: str
    kind: str
    links: tuple
    point: np.ndarray
    normal: np.ndarray
    tangent: np.ndarray
    parameter: np.ndarray


@dataclass(frozen=True)
class Contact:
    """A higher pair's contact over a batch (B,): its `ContactGeometry`'s arrays, the sliding speed `slip`
    (m/s, of the second link on the first along the tangent, at the real speed of the motion; 0 for
    pitch circles that roll), the `pressure_angle` (rad, see the module) and the driven link (`driven`).

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> from mbplanar.kinematics import contacts
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/geared_five_bar.toml"))
    >>> gear = contacts(engine, mbplanar.analyse(engine, [1.0]))["G"]
    >>> gear.point.round(6), float(np.degrees(gear.pressure_angle[0])), bool(abs(gear.slip[0]) < 1e-15)
    (array([[0.04, 0.  ]]), 20.0, True)
    """

    name: str
    kind: str
    links: tuple
    driven: str
    point: np.ndarray
    normal: np.ndarray
    tangent: np.ndarray
    parameter: np.ndarray
    slip: np.ndarray
    pressure_angle: np.ndarray


def _turn(th: np.ndarray, vec) -> np.ndarray:
    """Vectors vec (2,) or (B, 2) turned by the angles th (B,): (B, 2)."""
    vec = np.asarray(vec, float)
    c, s = np.cos(th), np.sin(th)
    x, y = (vec[..., 0], vec[..., 1])
    return np.stack([c * x - s * y, s * x + c * y], axis=-1)


def _place(motion, engine, link: str, at) -> np.ndarray:
    """World positions (B, 2) of a material point drawn at `at` ((2,) or (B, 2)) of `link`."""
    k = engine.link_index[link]
    return motion.frames.r[:, k] + _turn(motion.frames.th[:, k], at)


def _perp(v: np.ndarray) -> np.ndarray:
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def contact_geometry(engine: Engine, motion) -> dict[str, ContactGeometry]:
    """Every higher pair's `ContactGeometry` over the positions of `motion`: the contact point and the
    common normal, read from the link frames and the contact parameters a `Motion` holds (no solve).

    Parameters
    ----------
    engine : Engine
        The mechanism.
    motion : Motion
        Positions of `engine` (batch B), from `analyse` with the frames (the default outputs).

    Returns
    -------
    dict of str to ContactGeometry
        The pairs in the model's `higher` order; empty without higher pairs.

    Raises
    ------
    AttributeError
        A `motion` without frames (`analyse(..., outputs=...)` that left "frames" out).

    Examples
    --------
    The cam follower's contact at input 0 and 90°: the point on the profile and the normal out of the cam.

    >>> import numpy as np, mbplanar
    >>> from mbplanar.kinematics import contact_geometry
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/cam_follower.toml"))
    >>> k = contact_geometry(engine, mbplanar.analyse(engine, np.radians([0.0, 90.0])))["K"]
    >>> k.kind, k.point.round(6), k.normal.round(6)
    ('cam', array([[0.0064  , 0.039485],
           [0.008229, 0.057542]]), array([[ 0.16    ,  0.987117],
           [-0.022933,  0.999737]]))
    """
    out = {}
    names = list(engine.mech.higher)
    batch = len(motion.phi)
    for col, name in enumerate(names):
        law = engine.laws[name]
        h, g = law.pair, law.geometry
        a, b = h.links
        nan = np.full(batch, np.nan)
        th = motion.frames.th
        if h.kind == "gear":
            th_c = th[:, engine.link_index[law.carrier]]
            point = _place(motion, engine, law.carrier, g.pitch)
            normal = _turn(th_c, g.normal)
            u = nan
        elif h.kind == "rack":
            th_k = th[:, engine.link_index[b]]
            normal = _turn(th_k, g.normal)              # square to the rack's line, turning with it
            point = _place(motion, engine, a, g.centres[0]) + h.radius * normal
            u = nan
        else:
            u = motion.frames.contact[:, col]
            path = law.path
            th_a = th[:, engine.link_index[a]]
            if h.kind == "slot":
                point = _place(motion, engine, b, h.at)
                d1 = path.point(u, 1).T
                normal = _perp(d1) / np.hypot(d1[:, 0], d1[:, 1])[:, None]
                normal = _turn(th_a, normal)
            else:
                profile = g.profile
                point = _place(motion, engine, a, profile.point(u).T)
                d1 = profile.point(u, 1).T
                normal = g.side * _turn(th_a, _perp(d1) / np.hypot(d1[:, 0], d1[:, 1])[:, None])
        out[name] = ContactGeometry(name, h.kind, h.links, point, normal, _perp(normal), u)
    return out


def contacts(engine: Engine, motion) -> dict[str, Contact]:
    """Every higher pair's `Contact` over the positions of `motion`: its geometry, the sliding speed at
    the motion's real speed and the pressure angle (the positions are solved again for the Jacobians the
    released motions come from).

    Parameters
    ----------
    engine : Engine
        A mechanism with higher pairs (an empty dict without).
    motion : Motion
        Its positions (`analyse`).

    Returns
    -------
    dict
        Higher pair name → `Contact`.

    Raises
    ------
    MotionError
        Never for the positions of a `Motion` (they are solved); a `ModelError` for a motion of another engine.

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> from mbplanar.kinematics import contacts
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/cam_eccentric.toml"))
    >>> found = contacts(engine, mbplanar.analyse(engine, np.radians([0.0, 90.0])))
    >>> np.degrees(found["K"].pressure_angle).round(4)
    array([18.0322, -7.4005])
    """
    geometry = contact_geometry(engine, motion)
    if not geometry or not len(motion.phi):
        return {name: Contact(g.name, g.kind, g.links, g.links[1], g.point, g.normal, g.tangent, g.parameter,
                              np.zeros(len(motion.phi)), np.zeros(len(motion.phi))) for name, g in geometry.items()}
    sol = solve_positions(engine, motion.phi)
    released = _released(engine, sol, geometry)
    engine.rates(sol, motion.omega, motion.epsilon)
    out = {}
    for name, g in geometry.items():
        h = engine.mech.higher[name]
        a, b = h.links
        ka, kb = engine.link_index[a], engine.link_index[b]

        def velocity(k):
            r = motion.frames.r[:, k]
            return sol.v[:, k] + sol.w[:, k, None] * _perp(g.point - r)

        slip = np.einsum("bi,bi->b", velocity(kb) - velocity(ka), g.tangent)
        if h.kind in ("gear", "rack"):
            driven, angle = b, np.full(len(motion.phi), h.pressure_angle)
        else:
            driven, angle = released[name]
        out[name] = Contact(name, g.kind, g.links, driven, g.point, g.normal, g.tangent, g.parameter, slip, angle)
    return out


def _released(engine: Engine, sol, geometry) -> dict:
    """(driven link, pressure angle (B,)) of every cam and slot: the driven link's point moves, with the
    contact released (its normal equation dropped, the other link held), along the null vector of the
    rest of its block's Jacobian."""
    out = {}
    batch = len(sol.phi)
    for bp, state in zip(engine.blocks, sol.blocks):
        if not bp.params:
            continue
        jac, sens = engine.solver.block_jacobian(bp, state.caches, state.cut_caches, batch)
        row = 0
        for law in bp.cuts:
            first, row = row, row + (2 if law.kind in ("R", "P") else law.equations)
            if law.parameters == 0:
                continue
            g = geometry[law.name]
            keep = [i for i in range(bp.m) if i not in (first, first + 1)]
            rest = jac[keep].transpose(2, 0, 1)                       # (B, m − 2, m)
            if law.kind == "face":
                released_row = jac[first + 1].T[:, None, :]              # the tangency stays
            else:                                                        # the point stays on the line along t
                t = g.tangent
                released_row = (t[:, 0, None] * jac[first].T + t[:, 1, None] * jac[first + 1].T)[:, None, :]
            free = np.linalg.svd(np.concatenate([rest, released_row], axis=1))[2][:, -1, :]    # (B, m)
            a, b = law.pair.links
            driven = b if b in bp.links else a
            w = np.einsum("jb,bj->b", sens.w[driven], free)
            v = np.einsum("ijb,bj->bi", sens.v[driven], free)
            if law.kind == "face" or driven == a:                     # in the engine's frame, as sol.pose
                point = g.point - np.asarray(engine.centre)
            else:
                point = sol.pose.r[driven].T + _turn(sol.pose.th[driven], law.at)
            lever = v + w[:, None] * _perp(point - sol.pose.r[driven].T)
            normal = g.normal if driven == b else -g.normal
            along = np.einsum("bi,bi->b", lever, normal)
            lever = lever * np.where(along < 0, -1.0, 1.0)[:, None]
            cross = lever[:, 0] * normal[:, 1] - lever[:, 1] * normal[:, 0]
            out[law.name] = (driven, np.arctan2(cross, np.abs(along)))
    return out
