"""Shaking force and moment on the frame, and force balancing by counterweights.

The shaking force is what the mechanism does to its frame: the sum of the forces on the frame from the
pairs with the ground, from the drive (its stator), and from loads with an end on the frame (a spring
anchored there). The shaking moment is their moment about a point (default: the origin). By d'Alembert,
the moving links are in equilibrium under every load, their inertia loads and those frame forces, so the
same sums follow from the loads alone: force = Σ F (every load and d'Alembert load, on any link) and
moment = Σ (p × F + M). `shaking` computes the first, `shaking_from_loads` the second (a check).

Balancing. The inertia shaking force at unit crank speed, F(φ) = −Σ m·a_qS(φ), is linear in the
counterweights: a point mass m_c on link k at ρ_c from a point P of the link (its first joint; ρ_c
turning with the link) adds −m_c·a_qP − (ε_q·perp − ω_q²)·(m_c·ρ_c). With unknowns m_c and the first
moment u_c = m_c·ρ_c of every counterweight, minimising Σ|F(φ_j)|² over the cycle is a linear least
squares problem: its minimum is zero where the mechanism can be fully force-balanced (a four-bar with
counterweights on the crank and the rocker, the classic two-counterweight static balance), otherwise
the counterweights minimise the RMS of the shaking force (a slider-crank balanced on its crank alone:
the rotating mass and half the reciprocating one). On a link turning about a frame pivot P, m_c itself
does not shake anything: only u_c counts, and m_c = |u_c|/`radius` for the radius chosen (default: the
distance between the link's first two joints).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..errors import ModelError, MotionError, did_you_mean
from ..kinematics import analyse, contact_geometry, material_points
from ._loads import guide_direction, heavy_links, real_frames, world_points
from ..model import Point

__all__ = ["Shaking", "shaking", "shaking_from_loads", "Counterweight", "Balancing", "balance",
           "inertia_shaking_force", "inertia_shaking"]


@dataclass(frozen=True, eq=False)
class Shaking:
    """What the mechanism does to its frame over a batch of B positions (`shaking`, `inertia_shaking`).

    Attributes
    ----------
    force : ndarray, shape (B, 2)
        The force on the frame (N).
    moment : ndarray, shape (B,)
        Its moment about `about` (N·m).
    about : tuple of float
        The point moments are taken about (m).
    magnitude : ndarray, shape (B,)
        ‖force‖ (N).

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians([60.0, 150.0]), omega=10.0)
    >>> from mbplanar.forces import shaking
    >>> sh = shaking(engine, mbplanar.kinetostatics(engine, motion))
    >>> sh.force.round(4), sh.moment.round(4), sh.magnitude.round(4)
    (array([[ 24.7689, -23.7328],
           [-17.3825, -28.3328]]), array([-15.5586,  -6.8743]), array([34.3038, 33.24  ]))
    """

    force: np.ndarray
    moment: np.ndarray
    about: tuple[float, float] = (0.0, 0.0)

    @property
    def magnitude(self) -> np.ndarray:
        return np.hypot(self.force[:, 0], self.force[:, 1])


def _cross(p, f):
    return p[:, 0] * f[:, 1] - p[:, 1] * f[:, 0]


def shaking(engine, ks, about=(0.0, 0.0)) -> Shaking:
    """Shaking force and moment from a `Kinetostatics` `ks`: the pairs with the ground (their force at the
    joint, a prismatic pair's moment too), the drive at inputs with the ground, and loads on the frame.

    Parameters
    ----------
    engine : Engine
        The mechanism.
    ks : Kinetostatics
        Its reactions over B positions.
    about : tuple of float
        The point moments are taken about (m).

    Returns
    -------
    Shaking
        The force and moment on the frame.

    Raises
    ------
    KeyError
        A `ks` of another engine.

    Examples
    --------
    The force on the frame equals the sum of every load on the links (`shaking_from_loads`: d'Alembert):

    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians([60.0, 150.0]), omega=10.0)
    >>> from mbplanar.forces import shaking, shaking_from_loads
    >>> ks = mbplanar.kinetostatics(engine, motion)
    >>> bool(np.allclose(shaking(engine, ks).force, shaking_from_loads(ks).force, atol=1e-12))
    True
    >>> shaking(engine, ks, about=(0.3, 0.0)).moment.round(4)
    array([-8.4388,  1.6255])
    """
    mech, motion = engine.mech, ks.motion
    batch = len(motion.phi)
    force, moment = np.zeros((batch, 2)), np.zeros(batch)
    c = np.asarray(about, float)
    ground = engine.link_index[mech.ground]
    contact = None
    for name, r in ks.reactions.items():
        j = mech.joints[name] if name in mech.joints else mech.higher[name]
        if mech.ground not in j.links:
            continue
        sign = -1.0 if r.on != mech.ground else 1.0  # the force on the frame
        moving = j.other(mech.ground)
        if name in mech.higher:  # a higher pair with the frame: its force at the contact
            if contact is None:
                contact = contact_geometry(engine, motion)
            point = contact[name].point
        else:
            point = world_points(motion, engine.link_index[moving], np.asarray(j.at, float))
        f = sign * np.stack([r.fx, r.fy], axis=1)
        force += f
        moment += _cross(point - c, f) + sign * r.moment
    for inp in engine.inputs:
        j = mech.joints[inp.joint]
        if mech.ground not in j.links:
            continue
        q = ks.balancing[inp.joint]  # on the input link; the frame takes −q
        if j.kind == "R":
            moment -= q
        else:
            u = guide_direction(engine, motion, inp.joint)
            point = world_points(motion, engine.link_index[j.slider], np.asarray(j.at, float))
            f = -q[:, None] * u
            force += f
            moment += _cross(point - c, f)
    for ld in ks.loads:
        if ld.link == ground:
            force += ld.force
            moment += _cross(ld.point - c, ld.force) + ld.moment
    return Shaking(force, moment, tuple(map(float, c)))


def shaking_from_loads(ks, about=(0.0, 0.0)) -> Shaking:
    """The same from d'Alembert: the sums of every load (inertia loads included) and their moments; it
    equals `shaking` where the kinetostatics is right (a check of the reactions).

    Parameters
    ----------
    ks : Kinetostatics
        Reactions over B positions, with the loads that acted (`ks.loads`).
    about : tuple of float
        The point moments are taken about (m).

    Returns
    -------
    Shaking
        The loads' resultant force and moment.

    Raises
    ------
    AttributeError
        `ks` is not a `Kinetostatics`.

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians([60.0, 150.0]), omega=10.0)
    >>> from mbplanar.forces import shaking_from_loads
    >>> sh = shaking_from_loads(mbplanar.kinetostatics(engine, motion))
    >>> sh.force.round(4), sh.about
    (array([[ 24.7689, -23.7328],
           [-17.3825, -28.3328]]), (0.0, 0.0))
    """
    batch = len(ks.motion.phi)
    c = np.asarray(about, float)
    force, moment = np.zeros((batch, 2)), np.zeros(batch)
    for ld in ks.loads:
        force += ld.force
        moment += _cross(ld.point - c, ld.force) + ld.moment
    return Shaking(force, moment, tuple(map(float, c)))


# -- balancing --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Counterweight:
    """A counterweight (`Balancing.counterweights`): a point mass on a link, SI.

    Attributes
    ----------
    link : str
        The link it is fixed to.
    mass : float
        Its mass (kg), for the radius asked for.
    at : tuple of float
        Where it sits in the drawn pose (m).
    about : str
        The joint its first moment is taken about (the link's pivot on the frame, else its first joint).
    first_moment : float
        mass × its distance from `about` (kg·m): what balancing fixes; any radius with it works.
    angle_deg : float
        Its direction from `about`, degrees from the link's reference line.

    Examples
    --------
    The classic first moments of the four-bar's static balance: (m₂/2)·‖OA‖ = 1 kg × 0.1 m opposite the
    crank, (m₂/2 + m₃/2)·‖CB‖ = 1.75 kg × 0.25 m opposite the rocker's pin B.

    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians([60.0, 150.0]), omega=10.0)
    >>> from mbplanar.forces import balance
    >>> [(cw.link, cw.about, round(cw.first_moment, 6), round(cw.angle_deg, 4) % 360)
    ...  for cw in balance(engine, ["1", "3"], steps=72).counterweights]
    [('1', 'O', 0.1, 180.0), ('3', 'C', 0.4375, 0.0)]
    """

    link: str
    mass: float
    at: tuple[float, float]
    about: str
    first_moment: float
    angle_deg: float


@dataclass(frozen=True, eq=False)
class Balancing:
    """Counterweights found (`balance`), the balanced `mechanism` (the counterweights added to the links'
    mass, centre and inertia), and the RMS of the inertia shaking force at unit speed (N per (rad/s)²)
    before and after, over the grid `phi`.

    Attributes
    ----------
    counterweights : list of Counterweight
        One per link balanced.
    mechanism : Mechanism
        The model with them: each link's mass, centre (a new point "<link>:balanced") and inertia.
    phi : ndarray, shape (N,)
        The input's grid over a turn (rad).
    rms_before, rms_after : float
        The RMS of the inertia shaking force at 1 rad/s (N).

    Examples
    --------
    The loaded four-bar balanced on its crank and rocker: the shaking force vanishes (to rounding).

    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians([60.0, 150.0]), omega=10.0)
    >>> from mbplanar.forces import balance
    >>> result = balance(engine, ["1", "3"], steps=72)
    >>> round(result.rms_before, 6), result.rms_after < 1e-12, [p for p in result.mechanism.points if ":" in p]
    (0.240476, True, ['1:balanced', '3:balanced'])
    """

    counterweights: list
    mechanism: object
    phi: np.ndarray
    rms_before: float
    rms_after: float


def inertia_shaking_force(engine, motion) -> np.ndarray:
    """Shaking force (B, 2) of the links' inertia alone at the motion's speed: Σ −m·a_S."""
    heavy = [h for h in heavy_links(engine.mech) if h[1].mass]
    out = np.zeros((len(motion.phi), 2))
    if not heavy:
        return out
    ks = np.array([engine.link_index[name] for name, _, _ in heavy], int)
    w, v, e, a = real_frames(engine, motion, ks)
    at = np.array([c for _, _, c in heavy], float)
    _, _, acc = material_points(motion.frames.th[:, ks], motion.frames.r[:, ks], w, v, e, a,
                                np.arange(len(ks)), at)
    for i, (_, lk, _) in enumerate(heavy):
        out -= lk.mass * acc[:, i]
    return out


def inertia_shaking(engine, motion, about=(0.0, 0.0)) -> Shaking:
    """The resultant of the links' inertia forces at the motion's speed (the shaking that balancing
    cancels): force Σ −m·a_S (B, 2) and moment Σ ((r_S − c) × (−m·a_S) − J_S·ε) (B,) about c = `about`.
    The static weight is left out (constant: it loads the foundation without shaking it, and
    counterweights add to it), and so are the working loads and the drive.

    Parameters
    ----------
    engine : Engine
        The mechanism.
    motion : Motion
        Positions with their real rates (batch B).
    about : tuple of float
        The point moments are taken about (m).

    Returns
    -------
    Shaking
        Σ −m·a_S and its moment (with −J_S·ε).

    Raises
    ------
    ModelError
        A link with a mass and no centre.

    Examples
    --------
    A crank of 2 kg whose centre turns on a 0.05 m radius at 10 rad/s shakes its frame with
    m·r·ω² = 10 N, gravity or not:

    >>> import numpy as np, mbplanar
    >>> m = mbplanar.parse_model({"links": [{"name": "1", "mass": 2.0, "centre": "S"}],
    ...     "joints": [{"name": "O", "type": "R", "links": ["0", "1"], "at": [0, 0]}],
    ...     "points": [{"name": "S", "link": "1", "at": [0.05, 0]}],
    ...     "input": {"joint": "O", "omega": 10.0}, "gravity": {"g": 9.81}})
    >>> engine = mbplanar.Engine(m)
    >>> from mbplanar.forces import inertia_shaking
    >>> sh = inertia_shaking(engine, mbplanar.analyse(engine, np.radians([0.0, 90.0])))
    >>> np.round(sh.force, 12).tolist()
    [[10.0, 0.0], [0.0, 10.0]]
    """
    heavy = heavy_links(engine.mech)
    batch = len(motion.phi)
    force, moment = np.zeros((batch, 2)), np.zeros(batch)
    if not heavy:
        return Shaking(force, moment, tuple(map(float, about)))
    ks = np.array([engine.link_index[name] for name, _, _ in heavy], int)
    w, v, e, a = real_frames(engine, motion, ks)
    at = np.array([c for _, _, c in heavy], float)
    xy, _, acc = material_points(motion.frames.th[:, ks], motion.frames.r[:, ks], w, v, e, a,
                                 np.arange(len(ks)), at)
    c = np.asarray(about, float)
    for i, (_, lk, _) in enumerate(heavy):
        f = -lk.mass * acc[:, i]
        force += f
        moment += _cross(xy[:, i] - c, f) - lk.inertia * e[:, i]
    return Shaking(force, moment, tuple(map(float, c)))


def _reference_joint(mech, link: str):
    """The point a counterweight's first moment is taken about: the link's first pair with the frame,
    else its first joint."""
    joints = mech.joints_of(link)
    if not joints:
        raise ModelError(f"link '{link}' has no joints", source=mech.source)
    return next((j for j in joints if mech.ground in j.links), joints[0])


def _columns(engine, motion, link: str):
    """Shaking force (B, 2) per unit of each unknown (m_c, u_x, u_y) of a counterweight on `link`, at
    unit speed: three columns (B, 2, 3)."""
    mech = engine.mech
    k = engine.link_index[link]
    j = _reference_joint(mech, link)
    f = motion.frames
    _, _, acc = material_points(f.th, f.r, f.w, f.v, f.e, f.a, np.array([k]),
                                np.array([j.at], float))
    th, w, e = f.th[:, k], f.w[:, k], f.e[:, k]
    c, s = np.cos(th), np.sin(th)
    out = np.empty((len(th), 2, 3))
    out[:, :, 0] = -acc[:, 0]
    # −(ε·perp − ω²)·R(θ)·u for u = (1, 0) and (0, 1)
    for col, (ux, uy) in ((1, (1.0, 0.0)), (2, (0.0, 1.0))):
        rx, ry = c * ux - s * uy, s * ux + c * uy
        out[:, 0, col] = -(-e * ry - w * w * rx)
        out[:, 1, col] = -(e * rx - w * w * ry)
    return out, j


def balance(engine, links, radius=None, steps: int = 360) -> Balancing:
    """Counterweights on `links` (names) that cancel the inertia shaking force over a full turn of the
    input, or minimise its RMS. `radius` (m, one or per link) sets the counterweight's distance on a link
    turning about a frame pivot (default: its first two joints' distance).

    Parameters
    ----------
    engine : Engine
        A one-input mechanism whose input turns.
    links : list of str
        The links to put counterweights on.
    radius : float or list of float, optional
        The counterweights' distances from their pivots (m), one or per link.
    steps : int
        Positions over the turn.

    Returns
    -------
    Balancing
        The counterweights, the balanced mechanism and the RMS before and after.

    Raises
    ------
    ModelError
        No link or a link listed twice, a name that is not a moving link of the model, radii of another
        count than the links, a model without masses or with several inputs.
    MotionError
        The input does not turn fully.

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians([60.0, 150.0]), omega=10.0)
    >>> from mbplanar.forces import balance
    >>> cw = balance(engine, ["1"], radius=0.05, steps=72).counterweights[0]
    >>> cw.link, round(cw.mass, 6), tuple(round(x, 6) for x in cw.at)
    ('1', 3.833309, (-0.033435, -0.037176))
    """
    mech = engine.mech
    if len(engine.inputs) != 1:
        raise ModelError(f"balancing turns one input through a cycle; the model has {len(engine.inputs)}",
                         source=mech.source)
    links = [str(n) for n in links]
    if not links:
        raise ModelError(f"give the links that get a counterweight (the moving links are "
                         f"{', '.join(mech.moving_links)})", source=mech.source, where="balance")
    twice = [n for k, n in enumerate(links) if n in links[:k]]
    if twice:
        raise ModelError(f"link '{twice[0]}' is listed twice", source=mech.source, where="balance")
    if radius is not None and np.size(radius) not in (1, len(links)):
        raise ModelError(f"{np.size(radius)} radii for {len(links)} links: give one radius, or one per link",
                         source=mech.source, where="balance")
    if not any(lk.mass for lk in mech.links.values()):
        raise ModelError("the model's links have no mass: nothing shakes the frame, nothing to balance (give "
                         "the links 'mass' and 'centre')", source=mech.source, where="balance")
    for name in links:
        if name not in mech.links or name == mech.ground:
            raise ModelError(f"'{name}' is not a moving link of the model; "
                             f"{did_you_mean(name, mech.moving_links, 'moving links')}", source=mech.source,
                             where="balance")
    radii = list(np.broadcast_to(np.asarray(radius if radius is not None else np.nan, float), (len(links),)))
    phi = np.linspace(0.0, 2 * math.pi, steps, endpoint=False) + engine.phi_drawn[0]
    motion = analyse(engine, phi, omega=1.0, epsilon=0.0)
    if not motion.success:
        raise MotionError(f"balancing needs a full turn of the input: {motion.message}", source=mech.source)
    before = inertia_shaking_force(engine, motion)
    cols, refs = zip(*[_columns(engine, motion, name) for name in links])
    A = np.concatenate(cols, axis=2).reshape(-1, 3 * len(links))
    scale = np.maximum(np.linalg.norm(A, axis=0), 1e-300)
    x, *_ = np.linalg.lstsq(A / scale, -before.reshape(-1), rcond=1e-12)
    x /= scale
    weights = []
    for i, (name, j, rho) in enumerate(zip(links, refs, radii)):
        m_c, u = x[3 * i], x[3 * i + 1:3 * i + 3]
        pivot = mech.ground in j.links
        if pivot:  # the mass does not matter: put it at the radius chosen
            if not math.isfinite(rho):
                rho = _link_size(mech, name)
            m_c = float(np.hypot(*u)) / rho
        at = tuple(np.asarray(j.at) + (u / m_c if m_c else np.zeros(2)))
        weights.append(Counterweight(name, float(m_c), (float(at[0]), float(at[1])), j.name,
                                     float(np.hypot(*u)), _angle_to_link(engine, name, u)))
    balanced = with_counterweights(mech, weights)
    after = before + (A @ x).reshape(-1, 2)
    rms = lambda f: float(np.sqrt(np.mean(np.sum(f * f, axis=1))))  # noqa: E731
    return Balancing(weights, balanced, phi, rms(before), rms(after))


def _link_size(mech, link: str) -> float:
    pts = [j.at for j in mech.joints_of(link)]
    size = max((math.dist(a, b) for a in pts for b in pts), default=0.0)
    if size == 0:
        raise ModelError("give the counterweight's radius", source=mech.source, where=f"link '{link}'")
    return size


def _angle_to_link(engine, link: str, u) -> float:
    """Direction of the vector u (drawn pose) from the link's reference line, degrees."""
    return math.degrees(math.atan2(u[1], u[0]) - engine.reference_angle[link]) % 360.0


def with_counterweights(mech, weights) -> object:
    """A copy of `mech` with point masses added to its links: new mass, centre (a new point
    `<link>:balanced`) and inertia about it (parallel axes)."""
    out = replace(mech, links=dict(mech.links), points=dict(mech.points))
    for cw in weights:
        lk = out.links[cw.link]
        s = np.array(_centre_at(out, cw.link), float)
        m = lk.mass + cw.mass
        c = (lk.mass * s + cw.mass * np.asarray(cw.at)) / m if m else s
        inertia = (lk.inertia + lk.mass * float(np.sum((s - c) ** 2))
                   + cw.mass * float(np.sum((np.asarray(cw.at) - c) ** 2)))
        name = f"{cw.link}:balanced"
        out.points[name] = Point(name, cw.link, (float(c[0]), float(c[1])))
        out.links[cw.link] = replace(lk, mass=m, inertia=inertia, centre=name)
    return out


def _centre_at(mech, link: str):
    lk = mech.links[link]
    if lk.centre is None:
        return mech.joints_of(link)[0].at
    return mech.points[lk.centre].at if lk.centre in mech.points else mech.joints[lk.centre].at
