"""Checking a design: does the input turn fully, where are the dead points, how far do the output links
swing, and how good are the transmission and pressure angles over the cycle.

`check(engine)` sweeps the whole range the (single) input can move through with the engine's continuation
(it stops at motion limits and says where), refines every extreme position inside the range by Newton on
the analogue (ω_q = 0 for a link angle, v_q = 0 for a slider) and gives a `CheckReport`. The range ends at
the located limits, and the values there (extreme positions at a dead point, transmission and pressure
angles) come from the configuration the engine solved at the limit itself (`Limit.q`), so they are exact
where a sample next to a fold would be off by the square root of its distance. For a four-bar it also gives
the Grashof verdict, which must agree with the numerical one. `transmission_angles` and `pressure_angles`
work on any `Motion`, so a sweep can report them too. Angles are radians inside; the report converts
to degrees at its edge (`as_dict`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace

import numpy as np

from ..errors import ModelError
from ..kinematics import Motion, analyse, describe_crossing, describe_limit, positions_at_limits, range_text
from ..engine import met_along, solve_positions

__all__ = ["Extreme", "AngleRange", "CheckReport", "LimitReport", "Separation", "RegionReport", "check", "check_region",
           "format_region", "transmission_triples",
           "grashof", "transmission_angles", "pressure_angles", "contact_angles", "separations", "format_report"]

SAMPLES = 721          # sweep resolution of a full turn (0.5°)
FULL_TURN = 2 * math.pi


@dataclass(frozen=True)
class LocalExtreme:
    """A local extreme of an output over the input's range: "min" or "max", its value (rad or m), where
    (the input's value, model unit), and `end`: an end of the range (a motion limit), where the output
    reverses with the input."""

    kind: str
    value: float
    at: float
    end: bool = False


@dataclass(frozen=True)
class Extreme:
    """Extreme positions of one output quantity over the input's range, as `check` finds them.

    Attributes
    ----------
    name : str
        The link's name (``kind == "link"``) or the prismatic pair's (``kind == "slider"``).
    kind : str
        "link": the quantity is the link's angle (rad); "slider": the pair's displacement along its guide (m).
    minimum, maximum : float or None
        The smallest and largest value over the range (rad or m); None when the link turns fully.
    at_min, at_max : float or None
        The input's values (model unit) where they occur.
    turns : bool
        The link turns fully (its angle has no extremes).
    local : list of LocalExtreme
        Every local extreme, sorted by input value ("min" or "max", value, where, `end` at a motion limit).

    Examples
    --------
    >>> import math, mbplanar
    >>> report = mbplanar.check(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), samples=73)
    >>> rocker = report.extremes[2]
    >>> rocker.name, rocker.kind, rocker.turns, round(math.degrees(rocker.maximum - rocker.minimum), 4)
    ('3', 'link', False, 51.4564)
    >>> report.extremes[0].turns, report.extremes[0].minimum
    (True, None)
    """

    name: str
    kind: str               # "link" or "slider"
    minimum: float | None
    at_min: float | None
    maximum: float | None
    at_max: float | None
    turns: bool = False
    local: list = field(default_factory=list)


@dataclass(frozen=True)
class AngleRange:
    """Min/max over the input's range of a transmission or pressure angle, as `check` finds them.

    Attributes
    ----------
    name : str
        A label: "P-J-Q" for a transmission angle, "S (A-B)" for a slider's pressure angle, "K (contact
        normal)" for a cam's or a slot's.
    points : tuple of str
        (P, J, Q): the angle at J between J→P and J→Q (or the rod A→B and the guide of S).
    minimum, maximum : float
        The smallest and largest angle (rad): a transmission angle in [0, π/2] (π/2 is ideal), a pressure
        angle of a slider in [0, π/2] (0 is ideal), a cam's signed.
    at_min, at_max : float
        The input's values (model unit) where they occur.

    Examples
    --------
    >>> import math, mbplanar
    >>> report = mbplanar.check(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), samples=73)
    >>> mu = report.transmission[0]
    >>> mu.name, round(math.degrees(mu.minimum), 4), mu.at_min
    ('A-B-C', 41.4096, 0.0)
    """

    name: str
    points: tuple           # (P, J, Q): the angle at J between J→P and J→Q (or guide / rod)
    minimum: float
    at_min: float
    maximum: float
    at_max: float


@dataclass(frozen=True)
class LimitReport:
    """A motion limit (a dead point of the input) as `check` reports it.

    Attributes
    ----------
    phi : float
        The input's value there (model unit).
    direction : int
        +1: met going up, −1: going down.
    links, joints : list of str
        The links and joints in line.
    kind : str
        How they line up ("stretched at B (C, B, D in line)", "folded at ...").
    message : str
        The sentence `format_report` prints.

    Examples
    --------
    >>> import mbplanar
    >>> report = mbplanar.check(mbplanar.Engine(mbplanar.read_model("models/crank_slider_rocker_locking.toml")))
    >>> lim = report.limits[0]
    >>> round(lim.phi, 6), lim.direction, lim.links, lim.kind
    (-0.808315, -1, ['3', '4'], 'stretched at B (C, B, D in line)')
    """

    phi: float
    direction: int
    links: list
    joints: list
    kind: str
    message: str


@dataclass(frozen=True)
class ChangePointReport:
    """A change point (two assembly branches cross) as `check` reports it: the input value (model unit),
    the links and joints in line, its kind, and the sentence."""

    phi: float
    links: list
    joints: list
    kind: str
    message: str


@dataclass(frozen=True)
class Grashof:
    """The Grashof verdict of a four-bar (`grashof`): link lengths (m), s + l and p + q, whether the
    criterion holds (`grashof`), whether s + l = p + q (`change_point`), the shortest link, the input and
    output links, the kind (crank-rocker, double crank, ...) and whether the input and output turn fully."""

    lengths: dict
    s_plus_l: float
    p_plus_q: float
    grashof: bool
    change_point: bool
    shortest: str
    input_link: str
    output_link: str
    kind: str
    input_turns: bool
    output_turns: bool


@dataclass(frozen=True)
class Separation:
    """A stretch of the input where a cam's contact force would pull (the follower would leave the cam).

    Attributes
    ----------
    pair : str
        The cam pair's name.
    start, end : float
        The stretch's ends (the input's values, model unit).
    message : str
        The sentence `format_report` prints.

    Examples
    --------
    The cam follower spun three times as fast as its model says: its spring no longer holds it on.

    >>> import dataclasses, mbplanar
    >>> model = mbplanar.read_model("models/cam_follower.toml")
    >>> fast = dataclasses.replace(model, inputs=[dataclasses.replace(i, omega=3 * i.omega) for i in model.inputs])
    >>> pulls = mbplanar.check(mbplanar.Engine(fast), samples=91).separations
    >>> [(s.pair, round(s.start), round(s.end)) for s in pulls]
    [('K', 68, 112), ('K', 184, 224)]
    """

    pair: str
    start: float
    end: float
    message: str


@dataclass(frozen=True)
class CheckReport:
    """What `check` finds over the whole input range of a one-input mechanism.

    Attributes
    ----------
    model, input, unit : str
        The model's name, its input's name and unit.
    full_turn : bool
        The input turns fully (a whole turn without a motion limit).
    range : tuple of float
        (lo, hi) the input moves through (model unit).
    limits : list of LimitReport
    change_points : list of ChangePointReport
    extremes : list of Extreme
        Every output link's angle and slider's displacement.
    transmission, pressure : list of AngleRange
    grashof : Grashof or None
        A four-bar's verdict (None for another mechanism).
    separations : list of Separation
        Where a cam's contact force would pull (empty without cams, loads or masses).

    Examples
    --------
    >>> import mbplanar
    >>> report = mbplanar.check(mbplanar.Engine(mbplanar.read_model("models/crank_slider_rocker_locking.toml")))
    >>> report.full_turn, len(report.limits)
    (False, 2)
    """

    model: str
    input: str
    unit: str
    full_turn: bool
    range: tuple
    limits: list
    change_points: list = field(default_factory=list)
    extremes: list = field(default_factory=list)
    transmission: list = field(default_factory=list)
    pressure: list = field(default_factory=list)
    grashof: Grashof | None = None
    separations: list = field(default_factory=list)

    def as_dict(self) -> dict:
        """JSON-ready document, angles in degrees."""
        doc = asdict(self)
        for ext in doc["extremes"]:
            if ext["kind"] == "link":
                for key in ("minimum", "maximum"):
                    ext[key] = None if ext[key] is None else math.degrees(ext[key])
                for loc in ext["local"]:
                    loc["value"] = math.degrees(loc["value"])
        for key in ("transmission", "pressure"):
            for ang in doc[key]:
                ang["minimum"], ang["maximum"] = math.degrees(ang["minimum"]), math.degrees(ang["maximum"])
        doc["separations"] = [{"pair": s["pair"], "from": s["start"], "to": s["end"], "message": s["message"]}
                              for s in doc["separations"]]
        return doc

    def _repr_html_(self) -> str:
        from ..model import view
        return view("html", self)


# -- four-bar closed form ---------------------------------------------------------------------------
def grashof(engine) -> Grashof | None:
    """Grashof verdict for a four-bar (four links, four revolute pairs, one input on the ground), else None.

    s + l < p + q: the shortest link turns fully relative to the others (crank-rocker, double crank,
    rocker-crank or Grashof double rocker by where the shortest link is); s + l > p + q: no link turns
    fully (triple rocker); s + l = p + q: a change-point mechanism (links can line up all at once), named
    by its equal links: parallelogram (opposite links equal, drawn uncrossed), anti-parallelogram
    (drawn crossed), deltoid (adjacent links equal in two pairs), rhombus (all equal), else change-point
    crank-rocker, double crank, rocker-crank or double rocker. Equality is relative to the mechanism's
    size (1e-9). With ties for the shortest link every one of them counts.

    Parameters
    ----------
    engine : Engine
        The mechanism; its link lengths are the distances between its joints in the drawn pose.

    Returns
    -------
    Grashof or None
        Link lengths (m), s + l and p + q (m), whether the criterion holds, whether s + l = p + q, the
        shortest link, the input and output links, the kind and whether the input and output turn
        fully; None for a mechanism that is not a four-bar driven at a ground pivot.

    Raises
    ------
    Nothing for an `Engine`: any other mechanism gives None.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.analysis import grashof
    >>> g = grashof(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")))
    >>> round(g.s_plus_l, 9), round(g.p_plus_q, 9), g.kind, g.input_turns, g.output_turns
    (0.4, 0.55, 'crank-rocker', True, False)
    >>> grashof(mbplanar.Engine(mbplanar.read_model("models/slider_crank.toml"))) is None
    True
    """
    mech = engine.mech
    joints = list(mech.joints.values())
    if len(mech.moving_links) != 3 or len(joints) != 4 or any(j.kind != "R" for j in joints) \
            or len(engine.inputs) != 1:
        return None
    lengths = {}
    for link in mech.all_links:
        pts = [j.at for j in mech.joints_of(link)]
        if len(pts) != 2:
            return None
        lengths[link] = math.dist(*pts)
    driver = mech.joints[engine.inputs[0].joint]
    if mech.ground not in driver.links:
        return None
    input_link = driver.other(mech.ground)
    output_link = next(j.other(mech.ground) for j in joints
                       if mech.ground in j.links and j.name != driver.name)
    coupler = next(n for n in mech.moving_links if n not in (input_link, output_link))
    tol = 1e-9 * engine.size
    s, p, q, l_ = sorted(lengths.values())
    shortest = min(lengths, key=lengths.get)
    ties = {n for n, v in lengths.items() if v - s <= tol}
    change_point = abs(s + l_ - p - q) <= tol
    holds = s + l_ <= p + q + tol
    turns = holds and bool(ties & {input_link, mech.ground})
    output_turns = holds and bool(ties & {output_link, mech.ground})
    kind = _grashof_kind(mech, lengths, holds, change_point, ties, input_link, output_link, coupler, tol)
    return Grashof(lengths, s + l_, p + q, bool(holds), bool(change_point), shortest, input_link, output_link, kind,
                   bool(turns), bool(output_turns))


def _grashof_kind(mech, lengths, holds, change_point, ties, input_link, output_link, coupler, tol) -> str:
    """The name of a four-bar's Grashof class (see `grashof`)."""
    if not holds:
        return "non-Grashof (triple rocker)"
    ground = mech.ground

    def equal(a, b):
        return abs(lengths[a] - lengths[b]) <= tol

    if change_point:
        if all(equal(ground, n) for n in (input_link, output_link, coupler)):
            return "rhombus (change point)"
        if equal(ground, coupler) and equal(input_link, output_link):
            return ("parallelogram (change point)" if _uncrossed(mech, input_link, output_link)
                    else "anti-parallelogram (change point)")
        if (equal(ground, input_link) and equal(coupler, output_link)) or \
                (equal(ground, output_link) and equal(coupler, input_link)):
            return "deltoid (kite; change point)"
        prefix = "change-point "
    else:
        prefix = ""
    if ground in ties:
        return prefix + "double crank"
    if input_link in ties:
        return prefix + "crank-rocker"
    if output_link in ties:
        return prefix + "rocker-crank (the input rocks, the output turns)"
    return prefix + "double rocker"


def _uncrossed(mech, input_link, output_link) -> bool:
    """Whether the drawn four-bar with equal cranks is a parallelogram: the two links on the ground
    are the same vector (else it is drawn crossed, an anti-parallelogram)."""
    g = [j for j in mech.joints.values() if mech.ground in j.links]
    (a0, a1), (b0, b1) = ((j.at, next(o for o in mech.joints_of(j.other(mech.ground)) if o is not j).at)
                          for j in g)
    u = (a1[0] - a0[0], a1[1] - a0[1])
    v = (b1[0] - b0[0], b1[1] - b0[1])
    return math.dist(u, v) <= 1e-6 * math.hypot(*u)


# -- transmission and pressure angles ---------------------------------------------------------------
def _fold(cos_angle):
    """Angle between two lines (not directions), in [0, π/2], from the cosine of their angle."""
    return np.arccos(np.clip(np.abs(cos_angle), 0.0, 1.0))


def _other_revolute(mech, link, joint):
    """The revolute joint of `link` farthest from `joint` in the drawn pose (None if all coincide)."""
    at = mech.joints[joint].at
    others = [j for j in mech.joints_of(link) if j.kind == "R" and j.name != joint
              and math.dist(j.at, at) > 1e-12]
    return max(others, key=lambda j: math.dist(j.at, at)).name if others else None


def transmission_triples(engine) -> list[tuple[str, str, str]]:
    """The revolute pairs where a transmission angle is measured: (P, J, Q) for each revolute pair J
    inside an Assur group (every R pair between moving links without a decomposition) whose two links
    carry further revolute pairs P and Q (the farthest from J in the drawn pose).

    Parameters
    ----------
    engine : Engine
        The mechanism.

    Returns
    -------
    list of tuple of str
        (P, J, Q) joint names; empty for a mechanism without such a pair (a slider-crank's coupler
        carries a prismatic pair's slider: its angle is a pressure angle, `pressure_angles`).

    Raises
    ------
    Nothing for an `Engine`.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.analysis import transmission_triples
    >>> transmission_triples(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")))
    [('A', 'B', 'C')]
    """
    mech = engine.mech
    structure = engine.topology.structure
    if structure is not None:
        candidates = [name for g in structure.groups for name in g.internal]
    else:
        candidates = [j.name for j in mech.joints.values() if mech.ground not in j.links]
    out = []
    for name in candidates:
        j = mech.joints.get(name)   # (not a pair of a link that replaces a higher pair)
        if j is None or j.kind != "R":
            continue
        p, q = (_other_revolute(mech, link, name) for link in j.links)
        if p is not None and q is not None:
            out.append((p, name, q))
    return out


def transmission_angles(engine, motion: Motion):
    """Transmission angle at every R–R–R pair (`transmission_triples`): the angle at J between links J→P
    and J→Q, folded into [0, π/2] (π/2 is ideal, 0 is a dead point).

    Parameters
    ----------
    engine : Engine
        The mechanism.
    motion : Motion
        Positions of `engine` (batch B), from `analyse`.

    Returns
    -------
    triples : list of tuple of str
        (P, J, Q) of each of the K angles.
    angles : ndarray, shape (B, K)
        The angles (rad); NaN where a position was not solved.

    Raises
    ------
    KeyError
        A `motion` of another engine (a joint it does not hold).

    Examples
    --------
    The four-bar of Hartenberg and Denavit's crank-rocker: the angle at B is 41.41° with the crank at 0°.

    >>> import numpy as np, mbplanar
    >>> from mbplanar.analysis import transmission_angles
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> triples, mu = transmission_angles(engine, mbplanar.analyse(engine, np.radians([0.0, 90.0])))
    >>> triples, np.degrees(mu).round(4)
    ([('A', 'B', 'C')], array([[41.4096],
           [69.5127]]))
    """
    triples = transmission_triples(engine)
    if not triples:
        return triples, np.zeros((len(motion.phi), 0))
    idx = np.array([[motion.point(n) for n in t] for t in triples])
    xy = motion.xy
    u = xy[:, idx[:, 0]] - xy[:, idx[:, 1]]
    v = xy[:, idx[:, 2]] - xy[:, idx[:, 1]]
    cos = np.einsum("bki,bki->bk", u, v) / (np.linalg.norm(u, axis=-1) * np.linalg.norm(v, axis=-1))
    return triples, _fold(cos)


def _rod(mech, link, joint, inputs):
    """The far pin of `link` if it is a connecting rod pinned at `joint`: only revolute pairs, at two
    distinct places, not driven (a two-force member); else None."""
    pairs = mech.joints_of(link)
    if link == mech.ground or any(j.kind != "R" or j.name in inputs for j in pairs):
        return None
    far = _other_revolute(mech, link, joint)
    at = mech.joints[joint].at
    places = {j.name for j in pairs if math.dist(j.at, at) > 1e-12}
    if far is None or any(math.dist(mech.joints[n].at, mech.joints[far].at) > 1e-12 for n in places):
        return None
    return far


def pressure_pairs(engine) -> list[tuple[str, str, str]]:
    """(A, B, S): the force on the slider of prismatic pair S acts along the line A→B. Either a
    connecting rod (two-force link) far pin A, pinned to the slider at B, or, for a slider with only one
    other pair, a frictionless prismatic pair B (A = B) whose normal carries the force."""
    mech = engine.mech
    inputs = {i.joint for i in engine.inputs}
    out = []
    for s in mech.joints.values():
        if s.kind != "P" or s.name in inputs:
            continue
        others = [j for j in mech.joints_of(s.slider) if j.name != s.name]
        for j in others:
            if j.kind == "R":
                far = _rod(mech, j.other(s.slider), j.name, inputs)
                if far is not None:
                    out.append((far, j.name, s.name))
            elif len(others) == 1:
                out.append((j.name, j.name, s.name))
    return out


def pressure_angles(engine, motion: Motion):
    """Pressure angle of each slider driven by a rod: the angle between the rod (force direction) and
    the slider's guide (its relative velocity), in [0, π/2] (0 is ideal).

    Parameters
    ----------
    engine : Engine
        The mechanism.
    motion : Motion
        Positions of `engine` (batch B), from `analyse`.

    Returns
    -------
    pairs : list of tuple of str
        (A, B, S) of each of the K angles: the force on the slider of prismatic pair S acts along A→B (a
        connecting rod's pins), or along the normal of prismatic pair B when A = B.
    angles : ndarray, shape (B, K)
        The angles (rad).

    Raises
    ------
    KeyError
        A `motion` of another engine (a joint it does not hold).

    Examples
    --------
    A centred slider-crank (crank 0.1 m, rod 0.3 m): the angle is arcsin(r/l) = 19.47° with the crank square
    to the guide, 0 when the crank lies along it.

    >>> import numpy as np, mbplanar
    >>> from mbplanar.analysis import pressure_angles
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/slider_crank.toml"))
    >>> pairs, alpha = pressure_angles(engine, mbplanar.analyse(engine, np.radians([0.0, 90.0])))
    >>> pairs, np.degrees(alpha).round(4)
    ([('A', 'B', 'Bp')], array([[ 0.    ],
           [19.4712]]))
    """
    pairs = pressure_pairs(engine)
    if not pairs:
        return pairs, np.zeros((len(motion.phi), 0))
    mech = engine.mech
    th = motion.frames.th

    def guide_angle(name):
        j = mech.joints[name]
        return np.radians(j.guide_deg) + th[:, engine.link_index[j.carrier]]

    rods = []
    for a, b, _ in pairs:
        if a == b:  # force normal to the guide of the prismatic pair b
            g = guide_angle(b) + np.pi / 2
            rods.append(np.stack([np.cos(g), np.sin(g)], axis=-1))
        else:
            rods.append(motion.xy[:, motion.point(b)] - motion.xy[:, motion.point(a)])
    rod = np.stack(rods, axis=1)
    guide = np.stack([guide_angle(s) for _, _, s in pairs], axis=1)
    cos = (rod[..., 0] * np.cos(guide) + rod[..., 1] * np.sin(guide)) / np.linalg.norm(rod, axis=-1)
    return pairs, _fold(cos)


def contact_angles(engine, motion: Motion):
    """The pressure angle of every cam and slot contact (`mbplanar.kinematics.contacts`): the angle from
    the driven point's direction of motion to the contact normal, signed.

    Parameters
    ----------
    engine : Engine
        The mechanism.
    motion : Motion
        Positions of `engine` (batch B), from `analyse`.

    Returns
    -------
    names : list of str
        The K cam and slot pairs.
    angles : ndarray, shape (B, K)
        Their pressure angles (rad).

    Raises
    ------
    KeyError
        A `motion` of another engine (a pair it does not hold).

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> from mbplanar.analysis import contact_angles
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/cam_follower.toml"))
    >>> names, alpha = contact_angles(engine, mbplanar.analyse(engine, np.radians([0.0, 60.0])))
    >>> names, np.degrees(alpha).round(3)
    (['K'], array([[-9.207],
           [10.591]]))
    """
    names = [n for n, h in engine.mech.higher.items() if h.kind in ("cam", "slot")]
    if not names or not len(motion.phi):
        return names, np.zeros((len(motion.phi), len(names)))
    from ..kinematics import contacts
    found = contacts(engine, motion)
    return names, np.stack([found[n].pressure_angle for n in names], axis=1)


def separations(engine, motion: Motion) -> list[Separation]:
    """Where a cam's contact force would pull (the follower would leave the cam), with the model's loads
    at the motion's speed: a `Separation` per stretch of the input (model unit); nothing without cams or
    without loads and masses (every force is then zero)."""
    from ..forces import has_force_data, kinetostatics
    cams = [n for n, h in engine.mech.higher.items() if h.kind == "cam"]
    if not cams or not has_force_data(engine.mech) or len(motion.phi) < 2:
        return []
    inp = engine.inputs[0]
    pulls = kinetostatics(engine, motion).pulling
    phi = inp.from_si(motion.phi[:, 0])
    out = []
    for name in cams:
        bad = pulls[name]
        edges = np.flatnonzero(np.diff(np.concatenate([[False], bad, [False]]).astype(int)))
        for lo, hi in zip(edges[::2], edges[1::2] - 1):
            a, b = float(phi[lo]), float(phi[hi])
            out.append(Separation(
                name, a, b, f"cam '{name}': the contact force would pull from {inp.name} = {a:.6g} to {b:.6g} "
                            f"{inp.unit}: the follower leaves the cam there unless a spring or a preload "
                            "holds it on (force closure)"))
    return out


# -- the sweep --------------------------------------------------------------------------------------
def _reach(engine):
    """Input range (SI) reachable from the drawn pose, its limits, and whether the input turns fully."""
    inp = engine.inputs[0]
    phi0 = float(engine.phi_drawn[0])
    revolute = engine.mech.joints[inp.joint].kind == "R"
    span = FULL_TURN if revolute else 4.0 * engine.size
    up = analyse(engine, np.array([phi0, phi0 + span]))
    limits = {lim.direction: lim for lim in up.limits}
    if revolute and +1 not in limits:
        return (phi0, phi0 + span), [], True
    down = analyse(engine, np.array([phi0 - span, phi0]))
    limits.update({lim.direction: lim for lim in down.limits})
    lo = float(limits[-1].phi[0]) if -1 in limits else phi0 - span
    hi = float(limits[+1].phi[0]) if +1 in limits else phi0 + span
    return (lo, hi), [limits[d] for d in (-1, +1) if d in limits], False


def _grid(engine, lo, hi, limits, samples):
    """Sweep positions over [lo, hi]. At a motion limit the end sample is the atlas' last node before it
    (within a few `H_MIN` of the limit): the nearest position a sweep can solve, rates included; the
    limit itself is added from its located configuration (`positions_at_limits`)."""
    grid = np.linspace(lo, hi, samples)
    nodes = engine.atlas().nodes
    for lim in limits:
        end, node = (0, nodes[0]) if lim.direction < 0 else (-1, nodes[-1])
        if lo <= node.phi[0] <= hi:
            grid[end] = node.phi[0]
    return grid


def _quantities(engine, motion):
    """Output quantities (B, K) with their first and second analogues, names and kinds."""
    mech = engine.mech
    names, kinds, q, dq, ddq = [], [], [], [], []
    for k, link in enumerate(motion.link_names):
        if link == mech.ground:
            continue
        names.append(link), kinds.append("link")
        q.append(motion.angle[:, k]), dq.append(motion.wq[:, k]), ddq.append(motion.eq[:, k])
    for k, joint in enumerate(motion.joint_names):
        if mech.joints[joint].kind == "P":
            names.append(joint), kinds.append("slider")
            q.append(motion.value[:, k]), dq.append(motion.rate_q[:, k]), ddq.append(motion.accel_q[:, k])
    return names, kinds, np.stack(q, 1), np.stack(dq, 1), np.stack(ddq, 1)


def _ends(engine, motion, at_limits, kinds, q):
    """Input values (2,) and quantities (2, K) at the two ends of the sweep: the end samples, replaced at
    a located motion limit by the exact configuration there (`at_limits`, rows in the order of its
    `limits`), whose link angles are put on the unwrapped branch of the neighbouring sample."""
    phi, values = motion.phi[[0, -1], 0].copy(), q[[0, -1]].copy()
    if at_limits is None:
        return phi, values
    link = np.array(kinds) == "link"
    _, _, q_lim, _, _ = _quantities(engine, at_limits)
    for row, lim in enumerate(at_limits.limits):
        end = 0 if lim.direction < 0 else 1
        value = q_lim[row]
        value[link] += FULL_TURN * np.round((values[end, link] - value[link]) / FULL_TURN)
        phi[end], values[end] = lim.phi[0], value
    return phi, values


def _stationary(engine, phi, dq, q, full_turn):
    """Candidate local extremes from the sampled analogue dq (N, K): brackets (a, b) of the input
    around each interior stationary point of quantity k, with its kind, from strict sign changes of the
    rate between samples and from exact zeros on a sample (an extreme that falls on a sample, where the
    rate is exactly 0 and no product of neighbours is negative). For a full turn the samples wrap
    around (the last sample is the first turned once). Returns (a, b, k, is_max) arrays."""
    sign = np.sign(dq)
    n = len(phi)
    a, b, k, top = [], [], [], []
    i, kk = np.nonzero(sign[:-1] * sign[1:] < 0)                 # strictly between samples
    a.append(phi[i]), b.append(phi[i + 1]), k.append(kk), top.append(sign[i, kk] > 0)
    if full_turn:  # samples 0 … n − 2 cyclic; sample n − 1 is sample 0 turned once
        idx = np.arange(n - 1)
        prev, nxt = (idx - 1) % (n - 1), idx + 1
    else:
        idx = np.arange(1, n - 1)
        prev, nxt = idx - 1, idx + 1
    zi, zk = np.nonzero(sign[idx] == 0)
    before, after = sign[prev[zi], zk], sign[nxt[zi], zk]
    turn = before * after < 0                                    # a zero with a sign change: an extreme
    zi, zk, before = zi[turn], zk[turn], before[turn]
    a.append(phi[idx[zi]]), b.append(phi[idx[zi]]), k.append(zk), top.append(before > 0)
    return (np.concatenate(a), np.concatenate(b), np.concatenate(k).astype(int),
            np.concatenate(top).astype(bool))


ROOT_ITERATIONS = 40


def _root(engine, a, b, which):
    """The input values (N,) in [a, b] where quantity `which` is stationary (dq/dφ = 0), by Newton on
    the continuation's analogues (ddq) safeguarded by bisection of the bracket, all candidates in one
    batch per iteration; a == b is a zero found on a sample. Returns (φ, q) or None when a position
    cannot be solved."""
    a, b = np.asarray(a, float).copy(), np.asarray(b, float).copy()
    x = 0.5 * (a + b)
    rows = np.arange(len(x))
    for _ in range(ROOT_ITERATIONS):
        motion = analyse(engine, x)
        if not motion.success:
            return None
        _, _, q, dq, ddq = _quantities(engine, motion)
        d1, d2 = dq[rows, which], ddq[rows, which]
        fa = _rate_at(engine, a, which)
        if fa is None:
            return None
        left = np.sign(d1) == np.sign(fa)
        a, b = np.where(left & (d1 != 0), x, a), np.where(~left & (d1 != 0), x, b)
        with np.errstate(divide="ignore", invalid="ignore"):
            newton = x - d1 / d2
        ok = np.isfinite(newton) & (newton > np.minimum(a, b)) & (newton < np.maximum(a, b))
        nxt = np.where(d1 == 0, x, np.where(ok, newton, 0.5 * (a + b)))
        done = np.abs(nxt - x) <= 4 * np.finfo(float).eps * np.maximum(1.0, np.abs(x))
        x = nxt
        if done.all():
            break
    motion = analyse(engine, x)
    if not motion.success:
        return None
    return x, _quantities(engine, motion)[2][rows, which]


def _rate_at(engine, x, which):
    motion = analyse(engine, x)
    if not motion.success:
        return None
    return _quantities(engine, motion)[3][np.arange(len(x)), which]


def _within_turn(engine, values, full_turn: bool):
    """Input values (model unit) of a full turn reduced to one turn, [0, 360) deg or [0, 2π) rad: the
    sweep starts at the drawn pose, so its values run past a turn (398.6° for 38.6°); otherwise as
    they are."""
    inp = engine.inputs[0]
    values = np.asarray(values, float)
    if not full_turn or inp.unit not in ("deg", "rad"):
        return values
    turn = 360.0 if inp.unit == "deg" else 2 * math.pi
    reduced = np.mod(values, turn)
    # a whole turn (from either side, by round-off of the sweep's start) is 0
    return np.where(np.minimum(reduced, turn - reduced) <= 1e-12 * turn, 0.0, reduced)


def _local(kind, value, at, end=False) -> LocalExtreme:
    return LocalExtreme(kind, float(value), float(at), bool(end))


def _extremes(engine, motion, full_turn, at_limits=None):
    """Extreme positions of every output quantity: every local extreme (a dead centre of the output:
    its rate is zero, found by sign changes and exact zeros of the sampled rate and refined by
    `_root`), and the ends of the range at motion limits (exact at located limits, see `_ends`); the
    global minimum and maximum among them."""
    inp = engine.inputs[0]
    names, kinds, q, dq, _ = _quantities(engine, motion)
    phi = motion.phi[:, 0]
    q = np.where(np.array(kinds) == "link", np.unwrap(q, axis=0), q)
    end_phi, end_q = _ends(engine, motion, at_limits, kinds, q)
    a, b, k, top = _stationary(engine, phi, dq, q, full_turn)
    found = _root(engine, a, b, k) if len(k) else None
    if found is not None:
        at, values = found
    else:  # cannot happen on a solved sweep; fall back to the nearer sample
        at, values = a, q[np.searchsorted(phi, a), k]
    # the unwrapped branch of a link angle: shift the refined value next to its neighbour sample
    near = np.clip(np.searchsorted(phi, at), 0, len(phi) - 1)
    values = np.where(np.array(kinds)[k] == "link",
                      values + FULL_TURN * np.round((q[near, k] - values) / FULL_TURN), values)
    out = []
    for n, (name, kind) in enumerate(zip(names, kinds)):
        span = q[:, n].max() - q[:, n].min()
        if kind == "link" and full_turn and span >= FULL_TURN - 1e-6:
            out.append(Extreme(name, kind, None, None, None, None, turns=True))
            continue
        if span <= 1e-12 * (1.0 if kind == "link" else engine.size):  # (rad; a slider relative to the size)
            continue  # does not move (a block that only translates, say)
        local = [(float(at[m]), float(values[m]), "max" if top[m] else "min") for m in np.flatnonzero(k == n)]
        if not full_turn:
            for e, other in ((0, 1), (1, -2)):
                value = end_q[e, n]
                local.append((float(end_phi[e]), float(value), "max" if value > q[other, n] else "min", True))
        local.sort(key=lambda c: c[0])
        local = _significant(local, 1e-9 * (engine.size if kind == "slider" else 1.0))
        values_n = np.array([c[1] for c in local]) if local else q[[0, -1], n]
        ats_n = np.array([c[0] for c in local]) if local else end_phi
        lo, hi = int(np.argmin(values_n)), int(np.argmax(values_n))
        vmin, vmax = float(values_n[lo]), float(values_n[hi])
        shift = 0.0
        if kind == "link":  # report angles in (−π, π] around the minimum
            shift = FULL_TURN * math.floor((vmin + math.pi) / FULL_TURN)
            vmin, vmax = vmin - shift, vmax - shift
        ats = _within_turn(engine, inp.from_si(np.asarray(ats_n, float)), full_turn)
        places = _within_turn(engine, [inp.from_si(c[0]) for c in local], full_turn)
        out.append(Extreme(name, kind, vmin, float(ats[lo]), vmax, float(ats[hi]),
                           local=sorted((_local(c[2], c[1] - shift, at, len(c) > 3) for c, at in zip(local, places)),
                                        key=lambda loc: loc.at)))
    return out


def _significant(local: list, tol: float) -> list:
    """The local extremes (φ, value, kind[, end]) in order, without the wiggles of a dwell: an interior
    maximum and minimum next to each other that differ by no more than `tol` (the rounding of a profile
    given by points) are dropped in pairs."""
    out = []
    for c in local:
        if out and len(c) == 3 and len(out[-1]) == 3 and abs(c[1] - out[-1][1]) <= tol:
            out.pop()
            continue
        out.append(c)
    return out


def _angle_ranges(engine, motion, at_limits, angles_of, name_of, full_turn=False):
    """Min/max of the angles `angles_of(engine, motion)` over the sweep and the located limits."""
    inp = engine.inputs[0]
    labels, angles = angles_of(engine, motion)
    phi = motion.phi[:, 0]
    if at_limits is not None:
        phi = np.concatenate([phi, at_limits.phi[:, 0]])
        angles = np.concatenate([angles, angles_of(engine, at_limits)[1]])
    phi = _within_turn(engine, inp.from_si(phi), full_turn)
    out = []
    for k, label in enumerate(labels):
        a = angles[:, k]
        lo, hi = int(np.argmin(a)), int(np.argmax(a))
        out.append(AngleRange(name_of(label), tuple(label), float(a[lo]), float(phi[lo]),
                              float(a[hi]), float(phi[hi])))
    return out


def check(engine, samples: int = SAMPLES) -> CheckReport:
    """Sweep the whole input range of a one-input mechanism and report its motion limits, extreme
    positions, transmission and pressure angles (see the module docstring).

    Parameters
    ----------
    engine : Engine
        A one-input mechanism.
    samples : int
        Positions sampled over a turn (or the travel) before the limits and the extremes are solved
        exactly.

    Returns
    -------
    CheckReport
        Whether the input turns fully, its range, the motion limits and change points, the extreme
        positions of every output, the transmission and pressure angles and, for a four-bar, Grashof.

    Raises
    ------
    ModelError
        A model with more than one input (`check_region` takes two).

    Examples
    --------
    >>> import mbplanar
    >>> report = mbplanar.check(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")))
    >>> report.full_turn, report.grashof.kind
    (True, 'crank-rocker')
    """
    if len(engine.inputs) != 1:
        raise ModelError("check drives one input; this model has "
                         f"{len(engine.inputs)}", source=engine.mech.source)
    inp = engine.inputs[0]
    (lo, hi), limits, full = _reach(engine)
    motion = analyse(engine, _grid(engine, lo, hi, limits, samples))
    located = [lim for lim in limits if lim.q is not None]
    at_limits = positions_at_limits(engine, located) if located else None
    # (a full turn starts and ends at the drawn pose, which cannot be a change point: none is counted twice)
    crossings = met_along(engine.atlas(), lo, hi)[1]
    report = CheckReport(
        model=engine.mech.name, input=inp.name, unit=inp.unit, full_turn=full,
        range=(float(inp.from_si(lo)), float(inp.from_si(hi))),
        limits=[LimitReport(float(inp.from_si(lim.phi[0])), lim.direction, list(lim.links), list(lim.joints),
                            lim.kind, describe_limit(engine, lim)) for lim in limits],
        change_points=[ChangePointReport(float(inp.from_si(c.phi[0])), list(c.links), list(c.joints), c.kind,
                                         describe_crossing(engine, c)) for c in crossings],
        grashof=grashof(engine))
    if len(motion.phi) < 2:
        return report
    pressure = _angle_ranges(engine, motion, at_limits, pressure_angles,
                             lambda t: f"{t[2]} ({t[0]}-{t[1]})" if t[0] != t[1] else
                             f"{t[2]} (normal of {t[0]})", full)
    pulls = []
    if engine.mech.higher:
        pressure += _angle_ranges(engine, motion, at_limits, _contact_angle_labels,
                                  lambda t: f"{t[0]} (contact normal)", full)
        pulls = separations(engine, motion)
    return replace(report, extremes=_extremes(engine, motion, full, at_limits),
                   transmission=_angle_ranges(engine, motion, at_limits, transmission_angles,
                                              lambda t: f"{t[0]}-{t[1]}-{t[2]}", full),
                   pressure=pressure, separations=pulls)


def _contact_angle_labels(engine, motion):
    names, angles = contact_angles(engine, motion)
    return [(n, n, n) for n in names], angles


def format_report(report: CheckReport, length: tuple[str, float] = ("m", 1.0)) -> str:
    """The plain-text report ``mbplanar check`` prints.

    Parameters
    ----------
    report : CheckReport
        What `check` found.
    length : tuple of (str, float)
        The lengths' unit: its name and its size in metres (``("mm", 0.001)``); angles are in degrees,
        the input in its model unit.

    Returns
    -------
    str
        One line per finding: Grashof, the range, the limits and change points, each output's extremes,
        the transmission and pressure angles, the cams' separations.

    Raises
    ------
    ZeroDivisionError
        A length unit of size 0.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.analysis import format_report
    >>> report = mbplanar.check(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")))
    >>> print(format_report(report, ("mm", 0.001)).splitlines()[1])
    Grashof: s + l = 400 mm ≤ p + q = 550 mm: crank-rocker; the input turns fully
    """
    u = report.unit
    lu, k = length
    lines = [f"{report.model}: input {report.input} [{u}]"]
    if report.grashof is not None:
        g = report.grashof
        lines.append(f"Grashof: s + l = {g.s_plus_l / k:.6g} {lu} {'≤' if g.grashof else '>'} p + q = "
                     f"{g.p_plus_q / k:.6g} {lu}: {g.kind}; the input "
                     f"{'turns fully' if g.input_turns else 'does not turn fully'}")
    if report.full_turn:
        lines.append("the input turns fully (numerically: a whole turn without a motion limit)")
    else:
        lines.append(f"the input does NOT turn fully: it moves through {range_text(*report.range, 8)} {u}")
    for lim in report.limits:
        lines.append(f"  dead point / limit: {lim.message}")
    for c in report.change_points:
        lines.append(f"  {c.message}")
    for e in report.extremes:
        if e.turns:
            lines.append(f"  link {e.name}: turns fully")
        elif e.kind == "link":
            lines.append(f"  link {e.name}: angle {math.degrees(e.minimum):.6f}° at {e.at_min:.8g} {u} … "
                         f"{math.degrees(e.maximum):.6f}° at {e.at_max:.8g} {u} "
                         f"(swing {math.degrees(e.maximum - e.minimum):.6f}°)")
        else:
            lines.append(f"  slider {e.name}: {e.minimum / k:.9g} {lu} at {e.at_min:.8g} {u} … {e.maximum / k:.9g} "
                         f"{lu} at {e.at_max:.8g} {u} (stroke {(e.maximum - e.minimum) / k:.9g} {lu})")
        if e.local:
            lines.append("    local extremes: " + "; ".join(_format_local(e, loc, u, lu, k) for loc in e.local))
    for title, items in (("transmission angle", report.transmission), ("pressure angle", report.pressure)):
        for a in items:
            lines.append(f"  {title} {a.name}: min {math.degrees(a.minimum):.4f}° at {a.at_min:.8g} {u}, "
                         f"max {math.degrees(a.maximum):.4f}° at {a.at_max:.8g} {u}")
    for sep in report.separations:
        lines.append(f"  force closure: {sep.message}")
    return "\n".join(lines)


def _format_local(ext: Extreme, loc: LocalExtreme, unit: str, lu: str = "m", k: float = 1.0) -> str:
    """One local extreme: 'max 61.601550° at 315 deg' (an end of the range marked '(limit)'); lengths
    in `lu`, k metres each."""
    value = f"{math.degrees(loc.value):.6f}°" if ext.kind == "link" else f"{loc.value / k:.9g} {lu}"
    return f"{loc.kind} {value} at {loc.at:.8g} {unit}" + (" (limit)" if loc.end else "")


# -- two inputs: the reachable region and the singular curves ----------------------------------------
REGION_SAMPLES = 19    # grid points per input (20° over a full turn)


@dataclass(frozen=True)
class SingularPoint:
    """A point of a singular curve of a two-input mechanism: where (the inputs' values, model units),
    the links and joints in line, its kind."""

    at: list
    links: list
    joints: list
    kind: str


@dataclass(frozen=True, eq=False)
class RegionReport:
    """What a two-input mechanism can reach, as `check_region` finds it.

    Attributes
    ----------
    model : str
        The model's name.
    inputs, units : list of str
        The two inputs' names and model units.
    grid : list of ndarray
        Per input the grid values (n_k,), model units.
    reachable : ndarray, shape (n_1, n_2), bool
        The grid points the drawn branch reaches.
    ranges : list of tuple or None
        Per input (lo, hi) over the reached grid points (None when none is reached).
    singular : list of SingularPoint
        Points of the singular curves: the motion limits the walks ran into (the region's edge), and
        where a block's Jacobian determinant changes sign between neighbouring reached grid points (the
        branch folds there, links line up).

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.analysis import check_region
    >>> region = check_region(mbplanar.Engine(mbplanar.read_model("models/five_bar.toml")), samples=5)
    >>> region.inputs, int(region.reachable.sum()), region.ranges[0]
    (['phi1', 'phi2'], 23, (0.0, 360.0))
    >>> sorted({tuple(p.links) for p in region.singular})
    [('2', '3')]
    """

    model: str
    inputs: list            # names
    units: list
    grid: list              # per input the grid values (n_k,)
    reachable: np.ndarray   # (n_1, n_2) bool
    ranges: list            # per input (lo, hi) over the reached grid points
    singular: list          # [{"at": [a, b], "links": [...], "joints": [...], "kind": str}]: the motion
                            # limits the walks ran into (the edge of the region) and sign changes inside

    def as_dict(self) -> dict:
        return {"model": self.model, "inputs": self.inputs, "units": self.units,
                "grid": [list(map(float, g)) for g in self.grid],
                "reachable": self.reachable.tolist(), "reached": int(self.reachable.sum()),
                "ranges": [list(r) if r is not None else None for r in self.ranges],
                "singular": [asdict(p) for p in self.singular]}


def check_region(engine, samples: int = REGION_SAMPLES) -> RegionReport:
    """The region of a two-input mechanism: every grid line (first input fixed) is walked on the drawn
    branch from the drawn pose, first along the first input, then along the second up and down from
    its drawn value, so a grid point counts as reached when the branch gets there without crossing a
    motion limit. Sign changes of a block's Jacobian determinant between neighbours on a line or
    across lines mark the singular curves (located by linear interpolation of the determinant).

    Parameters
    ----------
    engine : Engine
        A two-input mechanism.
    samples : int
        Grid points per input over its default sweep (a full turn or the travel).

    Returns
    -------
    RegionReport
        The grid, the reached points, each input's reached range and the singular points.

    Raises
    ------
    ModelError
        A model without exactly two inputs (`check` takes one).

    Examples
    --------
    The five-bar reaches its whole 5 × 5 grid but where links 2 and 3 stretch into line (phi1 = 180° with
    phi2 = 0° or 360°):

    >>> import mbplanar
    >>> from mbplanar.analysis import check_region
    >>> region = check_region(mbplanar.Engine(mbplanar.read_model("models/five_bar.toml")), samples=5)
    >>> int(region.reachable.sum()), region.reachable.size
    (23, 25)
    >>> float(region.grid[0][2]), region.reachable[2]
    (180.0, array([False,  True,  True,  True, False]))
    """
    if len(engine.inputs) != 2:
        raise ModelError(f"{engine.mech.source}: the region check drives two inputs; this model has "
                         f"{len(engine.inputs)}")
    inputs = engine.inputs
    grid = [np.linspace(*inp.default_sweep(), samples) for inp in inputs]
    drawn = [inp.from_si(float(p)) for inp, p in zip(inputs, engine.phi_drawn)]
    n1, n2 = len(grid[0]), len(grid[1])
    reach = np.zeros((n1, n2), bool)
    dets = np.full((n1, n2, len(engine.blocks)), np.nan)
    folds = []
    up = grid[1] >= drawn[1]
    for i, a in enumerate(grid[0]):
        for part in (np.flatnonzero(up), np.flatnonzero(~up)[::-1]):
            values = np.column_stack([np.full(len(part) + 1, a), np.append(drawn[1], grid[1][part])])
            phi = np.column_stack([inp.to_si(values[:, k]) for k, inp in enumerate(inputs)])
            sol = solve_positions(engine, phi)
            ok = sol.valid[1:]
            reach[i, part] = ok
            dets[i, part] = np.where(ok[:, None], engine.dets(sol)[1:], np.nan)
            folds += [SingularPoint([float(inp.from_si(p)) for inp, p in zip(inputs, lim.phi)], list(lim.links),
                                    list(lim.joints), lim.kind) for lim in sol.limits]
    ranges = []
    for axis in (0, 1):
        hit = np.flatnonzero(reach.any(axis=1 - axis))
        ranges.append((float(grid[axis][hit[0]]), float(grid[axis][hit[-1]])) if len(hit) else None)
    return RegionReport(engine.mech.name, [i.name for i in inputs], [i.unit for i in inputs], grid, reach,
                        ranges, sorted(_singular_points(engine, grid, dets) + folds, key=lambda s: s.at))


def _singular_points(engine, grid, dets) -> list:
    """Where a block's determinant changes sign between reached neighbours along either input."""
    out = []
    for axis in (0, 1):
        d0 = dets[:-1] if axis == 0 else dets[:, :-1]
        d1 = dets[1:] if axis == 0 else dets[:, 1:]
        i, j, k = np.nonzero(d0 * d1 < 0)
        for a, b, blk in zip(i, j, k):
            t = d0[a, b, blk] / (d0[a, b, blk] - d1[a, b, blk])
            p = [grid[0][a], grid[1][b]]
            nxt = grid[axis][(a if axis == 0 else b) + 1]
            p[axis] = p[axis] + t * (nxt - p[axis])
            bp = engine.blocks[blk]
            out.append(SingularPoint([float(p[0]), float(p[1])], list(bp.links), list(bp.joints),
                                     "change of assembly sign between grid points"))
    return out


def format_region(report: RegionReport) -> str:
    """The plain-text summary ``mbplanar check`` prints for a two-input mechanism: the reached grid
    points, each input's range, a map of the grid ('#' reached, '.' not; the second input upwards) and
    the singular points.

    Parameters
    ----------
    report : RegionReport
        What `check_region` found.

    Returns
    -------
    str
        The summary, one finding a line.

    Raises
    ------
    Nothing for a `RegionReport`.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.analysis import check_region, format_region
    >>> region = check_region(mbplanar.Engine(mbplanar.read_model("models/five_bar.toml")), samples=5)
    >>> print("\\n".join(format_region(region).splitlines()[:4]))
    five_bar: inputs phi1 [deg], phi2 [deg]; 23 of 25 grid points (5 × 5) reached on the drawn branch
      phi1 reaches 0 … 360 deg (on the grid)
      phi2 reaches 0 … 360 deg (on the grid)
        ##.##  360
    """
    names = ", ".join(f"{n} [{u}]" for n, u in zip(report.inputs, report.units))
    total = report.reachable.size
    lines = [f"{report.model}: inputs {names}; {int(report.reachable.sum())} of {total} grid points "
             f"({len(report.grid[0])} × {len(report.grid[1])}) reached on the drawn branch"]
    for name, unit, r in zip(report.inputs, report.units, report.ranges):
        lines.append(f"  {name} reaches {r[0]:.6g} … {r[1]:.6g} {unit} (on the grid)" if r else
                     f"  {name}: no grid point reached")
    for row in _region_map(report):
        lines.append("    " + row)
    if report.singular:
        lines.append(f"  singular curves ({len(report.singular)} points, links in line):")
        for s in report.singular:
            lines.append(f"    {report.inputs[0]} = {s.at[0]:.8g}, {report.inputs[1]} = {s.at[1]:.8g}: "
                         f"links {', '.join(s.links)} — {s.kind}")
    return "\n".join(lines)


def _region_map(report: RegionReport) -> list[str]:
    """The reached grid as text: one row per value of the second input (top: the largest), '#' reached."""
    return ["".join("#" if r else "." for r in report.reachable[:, j]) + f"  {report.grid[1][j]:g}"
            for j in range(report.reachable.shape[1] - 1, -1, -1)]
