"""Friction in the kinematic pairs, and the efficiency it leaves.

A revolute pair with friction has a friction circle: a pin of radius r and coefficient μ, so the pair
transmits besides its force F a moment of size μ·r·‖F‖ opposing the relative rotation of its links (on
the second link b, −μ·r·‖F‖·sign(ω_b − ω_a); on a the opposite). A prismatic pair with friction pushes
its slider back along the guide with a force μ·‖N‖ against the sliding, N the pair's normal force; with
the block's length b given, the pair's moment M is carried by two normal forces at the block's ends,
N/2 ∓ M/b, and the friction is μ·(|N/2 − M/b| + |N/2 + M/b|) = μ·max(|N|, 2|M|/b).

A cam's or a slot's contact with friction adds, to its normal force N, a force μ·‖N‖ along the contact's
tangent against the sliding of its surfaces; gears and racks roll at their pitch point, a roller on its cam
(no sliding there), and the model gives them no friction.

The reactions depend on the friction and the friction on the reactions: the kinetostatics becomes
nonlinear. It is solved by fixed-point iteration over the whole batch at once: reactions without
friction, then friction loads from the reactions, reactions with those loads, ... until the reactions
of two iterations agree to `tolerance` (relative to the largest reaction at that position). The number
of iterations and the residual (the last change, per position) are reported; the iteration converges
when the friction moments are small against the levers (μ·r much smaller than the links), and a
mechanism near self-locking shows itself by not converging.

Efficiency: the instantaneous efficiency is the drive's power without friction over its power with
friction at the same motion, η = Σ Q₀·q̇ / Σ Q·q̇ (while the drive gives power), and the cycle efficiency
the same ratio of the drive's work over the batch (one input: ∫Q·dq over φ) — the useful work over the
driving work, the friction's work being the difference.

The `[friction]` section of a model::

    [friction]
    mu = 0.1              # coefficient of every pair (default 0: none)
    pin_radius = 0.01     # pin radius of every revolute pair with friction (the table's length_unit)
    block_length = 0.08   # length of every slider (default: none, friction μ·‖N‖)
    tolerance = 1e-12     # of the fixed-point iteration
    max_iterations = 100
    pairs = [{ joint = "Bp", mu = 0.15, block_length = 0.1 }, { joint = "O", mu = 0.0 }]
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError, did_you_mean
from ..kinematics import contact_geometry
from ._kinetostatics import Kinetostatics, kinetostatics
from ._loads import LoadValue, evaluate_loads, guide_direction, load_power, real_frames, world_points
from ..model import Key, Row, Section, drawing_size

__all__ = ["PairFriction", "FrictionSpec", "FrictionResult", "read_friction", "friction_kinetostatics",
           "friction_loads", "FRICTION", "FRICTION_PAIR", "implausible_friction", "not_converged"]

#: the largest plausible friction coefficient: dry metal pairs 0.1–0.6 (steel on steel ~0.15), lubricated
#: 0.01–0.1, rubber or brake linings up to ~1
MU_PLAUSIBLE = 1.0
#: plausible pin radii and block lengths, as shares of the mechanism's size (its drawing's extent)
PIN_SHARE = (1e-3, 0.25)
BLOCK_SHARE = (1e-3, 2.0)

FRICTION_PAIR = Section("friction_pair", "[friction] pairs[]", "one pair's own friction", (
    Key("joint", "text", "the pair", required=True),
    Key("mu", "number", "its coefficient of friction", minimum=0.0, default_doc="the section's mu"),
    Key("pin_radius", "number", "its pin radius", unit="length", minimum=0.0, default_doc="the section's pin_radius"),
    Key("block_length", "number", "its slider block's length", unit="length", positive=True,
        default_doc="the section's block_length")))
FRICTION = Section("friction", "[friction]", "friction in the kinematic pairs", (
    Key("mu", "number", "coefficient of every pair", default=0.0, minimum=0.0),
    Key("pin_radius", "number", "pin radius of every revolute pair with friction", unit="length", default=0.0,
        minimum=0.0),
    Key("block_length", "number", "length of every slider block", unit="length", positive=True,
        default_doc="none: the friction is mu·|N|"),
    Key("tolerance", "number", "of the fixed-point iteration", default=1e-12, positive=True),
    Key("max_iterations", "number", "of the fixed-point iteration (a whole number)", default=100, positive=True),
    Key("pairs", "rows", "pairs whose friction differs", section=FRICTION_PAIR)))


@dataclass(frozen=True)
class PairFriction:
    """Friction of one pair (`FrictionSpec.pairs`), SI.

    Attributes
    ----------
    joint : str
        The pair (a lower pair, or a cam or slot contact).
    mu : float
        Its coefficient of friction.
    radius : float
        A revolute pair's pin radius (m): the friction moment is μ·r·‖F‖.
    block_length : float or None
        A prismatic pair's block length (m): its moment adds 2‖M‖/length to the normal force; None:
        the friction is μ·‖N‖.

    Examples
    --------
    >>> import pathlib, numpy as np, mbplanar
    >>> from mbplanar.model import read_model_text
    >>> text = pathlib.Path("models/fourbar_loaded.toml").read_text()
    >>> mech = read_model_text(text + "[friction]\\nmu = 0.1\\npin_radius = 0.01\\n")   # 10 mm pins
    >>> from mbplanar.forces import read_friction
    >>> read_friction(mech).pairs[0]
    PairFriction(joint='O', mu=0.1, radius=0.01, block_length=None)
    """

    joint: str
    mu: float
    radius: float = 0.0
    block_length: float | None = None


@dataclass(frozen=True)
class FrictionSpec:
    """Friction in a model's pairs (`read_friction`): the pairs with friction and the fixed-point
    iteration's `tolerance` (on the reactions' relative change) and `max_iterations`.

    Attributes
    ----------
    pairs : tuple of PairFriction
        The pairs whose coefficient is above 0.
    tolerance : float
        The iteration stops when no reaction changes by more than this, relative.
    max_iterations : int
        The most iterations.

    Examples
    --------
    >>> import pathlib, numpy as np, mbplanar
    >>> from mbplanar.model import read_model_text
    >>> text = pathlib.Path("models/fourbar_loaded.toml").read_text()
    >>> mech = read_model_text(text + "[friction]\\nmu = 0.1\\npin_radius = 0.01\\n")   # 10 mm pins
    >>> from mbplanar.forces import read_friction
    >>> spec = read_friction(mech)
    >>> [p.joint for p in spec.pairs], spec.tolerance, spec.max_iterations
    (['O', 'A', 'B', 'C'], 1e-12, 100)
    """

    pairs: tuple[PairFriction, ...] = ()
    tolerance: float = 1e-12
    max_iterations: int = 100


def read_friction(mech, mu: float | None = None) -> FrictionSpec | None:
    """The model's `[friction]` section (None when there is none and no `mu` is given); `mu` overrides
    the model's default coefficient. Implausible values warn (`implausible_friction`).

    Parameters
    ----------
    mech : Mechanism
        The model.
    mu : float, optional
        The coefficient of every pair not listed in the section's `pairs` (``--mu``).

    Returns
    -------
    FrictionSpec or None
        The pairs with friction, lengths in m; None without a section and without `mu`.

    Raises
    ------
    ModelError
        A revolute pair with friction and no pin radius, a negative value, a pair the model does not
        have, or a gear or a roller given friction (they roll).

    Examples
    --------
    >>> import pathlib, numpy as np, mbplanar
    >>> from mbplanar.model import read_model_text
    >>> text = pathlib.Path("models/fourbar_loaded.toml").read_text()
    >>> mech = read_model_text(text + "[friction]\\nmu = 0.1\\npin_radius = 0.01\\n")   # 10 mm pins
    >>> from mbplanar.forces import read_friction
    >>> read_friction(mech, mu=0.2).pairs[1]
    PairFriction(joint='A', mu=0.2, radius=0.01, block_length=None)
    >>> read_friction(mbplanar.read_model("models/fourbar_loaded.toml")) is None
    True
    """
    raw = mech.extras.get("friction")
    if raw is None and mu is None:
        return None
    where = f"{mech.source}: friction"
    row = Row({} if raw is None else raw, where, section=FRICTION)
    scale = mech.units.length_scale  # lengths in the table's length_unit
    block = row.get("block_length")
    table_mu = row.number("mu", FRICTION["mu"].default)          # (bounds: checked per pair below)
    default = PairFriction("", table_mu if mu is None else float(mu),
                           row.number("pin_radius", FRICTION["pin_radius"].default) * scale,
                           None if block is None else block * scale)
    tolerance = row.get("tolerance")
    max_iter = row.get("max_iterations")
    given = {}
    rows = row.raw("pairs", [])
    row.check_unknown_keys()
    if not isinstance(rows, list):
        row.fail("'pairs' must be a list of rows {joint = ..., mu = ...}")
    for k, raw_pair in enumerate(rows):
        pr = Row(raw_pair, f"{where}: pairs[{k}]", section=FRICTION_PAIR)
        joint = pr.get("joint")
        if joint not in mech.joints and joint not in mech.higher:
            pr.fail(f"'{joint}' is not a joint of the model; {did_you_mean(joint, [*mech.joints, *mech.higher], 'joints')}")
        if joint in mech.higher and (mech.higher[joint].kind in ("gear", "rack") or mech.higher[joint].follower == "roller"
                                     and mech.higher[joint].kind == "cam"):
            what = "roller rolls on its cam" if mech.higher[joint].kind == "cam" else "pitch circles roll"
            pr.fail(f"'{joint}' is a {mech.higher[joint].kind} pair whose {what} without sliding: the model gives "
                    "it no friction")
        if joint in given:
            pr.fail(f"joint '{joint}' is listed twice")
        radius, block = pr.number("pin_radius"), pr.get("block_length")
        given[joint] = PairFriction(joint, pr.number("mu", default.mu),
                                    default.radius if radius is None else radius * scale,
                                    default.block_length if block is None else block * scale)
        pr.check_unknown_keys()
    pairs = []
    for name, j in mech.joints.items():
        p = given.get(name, PairFriction(name, default.mu, default.radius, default.block_length))
        if p.mu < 0 or p.radius < 0:
            raise ModelError(f"{where}: joint '{name}': mu and pin_radius must be >= 0")
        if p.mu > 0 and j.kind == "R" and p.radius == 0:
            raise ModelError(f"{where}: joint '{name}' is revolute with mu = {p.mu}: give its pin_radius")
        if p.mu > 0:
            pairs.append(p)
    for name, h in mech.higher.items():   # a cam's or a slot's contact slides; gears and rollers roll
        p = given.get(name, PairFriction(name, default.mu))
        if p.mu > 0 and (h.kind == "slot" or h.kind == "cam" and h.follower != "roller"):
            pairs.append(PairFriction(name, p.mu))
    if int(max_iter) != max_iter:
        row.fail(f"'max_iterations' must be a whole number, got {max_iter}")
    spec = FrictionSpec(tuple(pairs), tolerance, int(max_iter))
    for note in implausible_friction(mech, spec):
        row.warn(note)
    return spec


def _listed(values: dict, unit: str = "", scale: float = 1.0) -> str:
    """'10 in O, A; 0.5 in B' of {joint: value}, the same values together."""
    groups: dict = {}
    for joint, value in values.items():
        groups.setdefault(value, []).append(joint)
    return "; ".join(f"{v / scale:.4g}{unit} in {', '.join(js)}" for v, js in groups.items())


def implausible_friction(mech, spec: FrictionSpec) -> list[str]:
    """What in `spec` lies outside plausible values, each with its numbers: a coefficient above
    `MU_PLAUSIBLE`, a pin radius or block length out of `PIN_SHARE` or `BLOCK_SHARE` of the mechanism's
    size (a length in another unit). Lengths are shown in the table's length unit.

    Parameters
    ----------
    mech : Mechanism
        The model (its size and length unit).
    spec : FrictionSpec
        The friction to judge.

    Returns
    -------
    list of str
        One sentence per implausible kind of value; empty when all are plausible.

    Raises
    ------
    KeyError
        A pair of `spec` the model does not have.

    Examples
    --------
    A coefficient written as a percentage:

    >>> import pathlib, numpy as np, mbplanar
    >>> from mbplanar.model import read_model_text
    >>> text = pathlib.Path("models/fourbar_loaded.toml").read_text()
    >>> mech = read_model_text(text + "[friction]\\nmu = 0.1\\npin_radius = 0.01\\n")   # 10 mm pins
    >>> import dataclasses
    >>> from mbplanar.forces import implausible_friction, read_friction
    >>> spec = read_friction(mech)
    >>> implausible_friction(mech, spec)
    []
    >>> implausible_friction(mech, dataclasses.replace(spec, pairs=(dataclasses.replace(spec.pairs[0], mu=15.0),)))
    ['mu = 15 in O: friction coefficients lie in 0.01 … 1 (lubricated 0.01–0.1, dry steel ~0.15); a percentage
    written for a fraction?']
    """
    size, unit = drawing_size(mech), mech.units
    k, lu = unit.length_scale, f" {unit.length}"
    notes = []
    high = {p.joint: p.mu for p in spec.pairs if p.mu > MU_PLAUSIBLE}
    if high:
        notes.append(f"mu = {_listed(high)}: friction coefficients lie in 0.01 … {MU_PLAUSIBLE:g} (lubricated 0.01–0.1, "
                     "dry steel ~0.15); a percentage written for a fraction?")
    if size <= 0:
        return notes
    for key, share, values in (
            ("pin_radius", PIN_SHARE, {p.joint: p.radius for p in spec.pairs if mech.joints[p.joint].kind == "R"}),
            ("block_length", BLOCK_SHARE, {p.joint: p.block_length for p in spec.pairs if p.block_length})):
        for kind, bad in (("large", {j: v for j, v in values.items() if v > share[1] * size}),
                          ("small", {j: v for j, v in values.items() if 0 < v < share[0] * size})):
            if bad:
                ratio = max(bad.values()) / size if kind == "large" else min(bad.values()) / size
                notes.append(f"{key} = {_listed(bad, lu, k)} against a mechanism {size / k:.4g}{lu} across "
                             f"({ratio:.3g} × its size; plausible {share[0]:g} … {share[1]:g} ×): too {kind}, "
                             "or in another unit?")
    return notes


def not_converged(engine, spec: FrictionSpec, result, at: str = "") -> str:
    """Why the friction iteration of `result` did not converge, with the numbers: the friction out of
    scale (`implausible_friction`), or else a mechanism that self-locks (the friction moments as large as
    what the drive can overcome through its levers). `at` names the positions (e.g. "at phi = 30 deg").

    Parameters
    ----------
    engine : Engine
        The mechanism.
    spec : FrictionSpec
        The friction the iteration ran with.
    result : FrictionResult
        The iteration that did not converge.
    at : str
        Where, for the message ("at phi = 30 deg"); empty: nothing.

    Returns
    -------
    str
        The sentence a command prints.

    Raises
    ------
    ValueError
        A `spec` without pairs (nothing could fail to converge).

    Examples
    --------
    Pins of 0.2 m with μ = 0.9 on a mechanism 0.39 m across: the friction circles are too large for the
    drive's levers.

    >>> import pathlib, numpy as np, mbplanar
    >>> from mbplanar.model import read_model_text
    >>> text = pathlib.Path("models/fourbar_loaded.toml").read_text()
    >>> mech = read_model_text(text + "[friction]\\nmu = 0.1\\npin_radius = 0.01\\n")   # 10 mm pins
    >>> import dataclasses
    >>> from mbplanar.forces import friction_kinetostatics, not_converged, read_friction
    >>> engine = mbplanar.Engine(mech)
    >>> spec = read_friction(mech)
    >>> big = dataclasses.replace(spec, pairs=tuple(dataclasses.replace(p, mu=0.9, radius=0.2) for p in spec.pairs))
    >>> result = friction_kinetostatics(engine, mbplanar.analyse(engine, np.radians([60.0]), omega=10.0), big)
    >>> result.converged
    False
    >>> print(not_converged(engine, big, result, "at phi = 60 deg"))
    the friction iteration did not converge in 100 iterations at phi = 60 deg (residual 0.342): the friction is
    out of scale: pin_radius = 0.2 m in O, A, B, C against a mechanism 0.3917 m across (0.511 × its size;
    plausible 0.001 … 0.25 ×): too large, or in another unit?
    """
    where = f" {at}" if at else ""
    head = (f"the friction iteration did not converge in {result.iterations} iterations{where} (residual "
            f"{float(np.nanmax(result.residual)):.3g})")
    notes = implausible_friction(engine.mech, spec)
    if notes:
        return f"{head}: the friction is out of scale: " + "; ".join(notes)
    radii = {p.joint: p.mu * p.radius for p in spec.pairs if p.radius}
    circle = (f"; friction circles μ·r up to {max(radii.values()) / engine.mech.units.length_scale:.4g} "
              f"{engine.mech.units.length}") if radii else ""
    return (f"{head}: the mechanism self-locks there (mu up to {max(p.mu for p in spec.pairs):g}{circle}): "
            "the friction grows with the forces faster than the drive can overcome it")


@dataclass(frozen=True, eq=False)
class FrictionResult:
    """Kinetostatics with friction: `kinetostatics` (reactions and balancing loads with friction),
    `ideal` (without), `iterations` (fixed-point iterations made), `residual` (B,) (the last relative
    change of the reactions), `converged`, `losses` (B,) (the friction's power, ≤ 0, W),
    `efficiency` (B,) (NaN where the drive takes power, or gives almost none: a dead point's 0/0) and `cycle_efficiency` (one input).

    Attributes
    ----------
    kinetostatics, ideal : Kinetostatics
        With friction and without.
    iterations : int
        Fixed-point iterations made.
    residual : ndarray, shape (B,)
        The last relative change of the reactions.
    converged : bool
        Every position's residual is within the spec's tolerance.
    losses : ndarray, shape (B,)
        The friction's power (W, ≤ 0).
    efficiency : ndarray, shape (B,)
        The drive's power without friction over its power with it (NaN where the drive takes power).
    cycle_efficiency : float or None
        Over the motion's positions (one input): the work of the drive without friction over with it.

    Examples
    --------
    >>> import pathlib, numpy as np, mbplanar
    >>> from mbplanar.model import read_model_text
    >>> text = pathlib.Path("models/fourbar_loaded.toml").read_text()
    >>> mech = read_model_text(text + "[friction]\\nmu = 0.1\\npin_radius = 0.01\\n")   # 10 mm pins
    >>> from mbplanar.forces import friction_kinetostatics
    >>> engine = mbplanar.Engine(mech)
    >>> result = friction_kinetostatics(engine, mbplanar.analyse(engine, np.radians([60.0]), omega=10.0))
    >>> result.converged, result.iterations, result.efficiency.round(4), result.losses.round(4)
    (True, 6, array([0.9545]), array([-1.2866]))
    """

    kinetostatics: Kinetostatics
    ideal: Kinetostatics
    iterations: int
    residual: np.ndarray
    converged: bool
    losses: np.ndarray
    efficiency: np.ndarray
    cycle_efficiency: float | None


def friction_loads(engine, motion, spec: FrictionSpec, reactions: dict) -> list[LoadValue]:
    """The friction loads (two per pair: on each of its links) for the given reactions."""
    out = []
    batch = len(motion.phi)
    zero2 = np.zeros((batch, 2))
    mech = engine.mech
    slips = None
    for p in spec.pairs:
        if p.joint in mech.higher:
            if slips is None:
                slips = contact_slips(engine, motion)
            out += _contact_friction(engine, p, reactions[p.joint], *slips[p.joint])
            continue
        j = mech.joints[p.joint]
        r = reactions[p.joint]
        ka, kb = (engine.link_index[n] for n in j.links)
        rate = motion.rate[:, motion.joint(p.joint)]
        if j.kind == "R":
            point = world_points(motion, kb, np.asarray(j.at, float))
            m = -p.mu * p.radius * np.hypot(r.fx, r.fy) * np.sign(rate)  # on b; rate = ω_b − ω_a
            out += [LoadValue(f"friction in {p.joint}", kb, zero2, point, m),
                    LoadValue(f"friction in {p.joint}", ka, zero2.copy(), point.copy(), -m)]
            continue
        u = guide_direction(engine, motion, p.joint)
        normal = np.abs(r.fx * -u[:, 1] + r.fy * u[:, 0])
        if p.block_length:
            normal = np.maximum(normal, 2 * np.abs(r.moment) / p.block_length)
        size = -p.mu * normal * np.sign(rate)  # along the guide, on the slider
        ks = engine.link_index[j.slider]
        point = world_points(motion, ks, np.asarray(j.at, float))
        force = size[:, None] * u
        kc = engine.link_index[j.carrier]
        out += [LoadValue(f"friction in {p.joint}", ks, force, point, np.zeros(batch)),
                LoadValue(f"friction in {p.joint}", kc, -force, point.copy(), np.zeros(batch))]
    return out


def contact_slips(engine, motion) -> dict:
    """Per higher pair (contact point (B, 2), unit tangent (B, 2), sliding speed (B,)): the velocity of the
    second link's material point at the contact less the first's, along the tangent (real velocities)."""
    w, v, _, _ = real_frames(engine, motion)
    r = motion.frames.r
    out = {}
    for name, g in contact_geometry(engine, motion).items():
        ka, kb = (engine.link_index[n] for n in g.links)

        def velocity(k):
            d = g.point - r[:, k]
            return v[:, k] + w[:, k, None] * np.stack([-d[:, 1], d[:, 0]], axis=1)

        out[name] = (g.point, g.tangent, np.einsum("bi,bi->b", velocity(kb) - velocity(ka), g.tangent))
    return out


def _contact_friction(engine, p: PairFriction, reaction, point, tangent, slip) -> list[LoadValue]:
    """Coulomb friction in a cam's or a slot's contact: μ·‖N‖ along the tangent against the sliding of the
    second link on the first, on the second link; the opposite on the first."""
    a, b = (engine.link_index[n] for n in engine.mech.higher[p.joint].links)
    size = -p.mu * np.hypot(reaction.fx, reaction.fy) * np.sign(slip)
    force = size[:, None] * tangent
    zero = np.zeros(len(size))
    return [LoadValue(f"friction in {p.joint}", b, force, point, zero),
            LoadValue(f"friction in {p.joint}", a, -force, point.copy(), zero.copy())]


def _change(old: dict, new: dict, names) -> np.ndarray:
    """Largest change of the pairs' reactions (B,), relative to the largest reaction at each position."""
    scale = np.zeros(len(next(iter(new.values())).fx))
    diff = np.zeros_like(scale)
    for name in names:
        a, b = old[name], new[name]
        scale = np.maximum(scale, np.hypot(b.fx, b.fy))
        diff = np.maximum(diff, np.hypot(b.fx - a.fx, b.fy - a.fy))
    return diff / np.where(scale > 0, scale, 1.0)


def friction_kinetostatics(engine, motion, spec: FrictionSpec | None = None,
                           input_inertia=0.0) -> FrictionResult:
    """Reactions and balancing loads with friction in the pairs over the batch of `motion` (the model's
    loads, gravity and inertia), by fixed-point iteration; and the efficiency.

    Each iteration adds, for the reactions of the one before, a friction moment μ·r·‖F‖ against the
    relative rotation in every revolute pair and a friction force μ·‖N‖ against the sliding in every
    prismatic pair and sliding contact, and solves the kinetostatics again.

    Parameters
    ----------
    engine : Engine
        The mechanism.
    motion : Motion
        Positions with their real rates (batch B).
    spec : FrictionSpec, optional
        The friction (default: the model's `[friction]`; without one, none).
    input_inertia : float or array_like
        J_I per input (kg·m², or kg), as `kinetostatics` takes it.

    Returns
    -------
    FrictionResult
        The reactions with and without friction, the losses, the efficiency, and whether the iteration
        converged (`not_converged` says why not).

    Raises
    ------
    ModelError
        An `input_inertia` that is not finite and ≥ 0.

    Examples
    --------
    With 10 mm pins at μ = 0.1 the loaded four-bar's crank needs 2.83 N·m instead of 2.70 at 60°:

    >>> import pathlib, numpy as np, mbplanar
    >>> from mbplanar.model import read_model_text
    >>> text = pathlib.Path("models/fourbar_loaded.toml").read_text()
    >>> mech = read_model_text(text + "[friction]\\nmu = 0.1\\npin_radius = 0.01\\n")   # 10 mm pins
    >>> from mbplanar.forces import friction_kinetostatics
    >>> engine = mbplanar.Engine(mech)
    >>> result = friction_kinetostatics(engine, mbplanar.analyse(engine, np.radians([60.0]), omega=10.0))
    >>> result.kinetostatics.balancing["O"].round(4), result.ideal.balancing["O"].round(4)
    (array([2.8273]), array([2.6986]))
    """
    spec = spec if spec is not None else (read_friction(engine.mech) or FrictionSpec())
    base = evaluate_loads(engine, motion)
    ideal = kinetostatics(engine, motion, input_inertia, loads=base)
    ks, iterations = ideal, 0
    residual = np.zeros(len(motion.phi))
    names = list(engine.mech.joints) + list(engine.mech.higher)
    while spec.pairs and iterations < spec.max_iterations:
        iterations += 1
        new = kinetostatics(engine, motion, input_inertia,
                            loads=base + friction_loads(engine, motion, spec, ks.reactions))
        residual = _change(ks.reactions, new.reactions, names)
        ks = new
        if not np.any(residual > spec.tolerance):
            break
    converged = bool(np.all(residual <= spec.tolerance))
    losses = _losses(engine, motion, spec, ks)
    power, power0 = _drive_power(engine, motion, ks), _drive_power(engine, motion, ideal)
    with np.errstate(invalid="ignore", divide="ignore"):  # NaN where the drive takes power or gives ~none
        eta = np.where(power > 1e-9 * np.max(np.abs(power), initial=0.0), power0 / power, np.nan)
    return FrictionResult(ks, ideal, iterations, residual, converged, losses, eta,
                          _cycle_efficiency(engine, motion, ks, ideal))


def _losses(engine, motion, spec, ks) -> np.ndarray:
    """The friction's power (B,) (W, ≤ 0) at the reactions `ks`: −μ·r·‖F‖·|ω_rel| and −(friction)·|v_rel|."""
    w, v, _, _ = real_frames(engine, motion)
    r = motion.frames.r
    return sum((load_power(ld, w, v, r) for ld in friction_loads(engine, motion, spec, ks.reactions)),
               np.zeros(len(motion.phi)))


def _on_input_link(engine, inp) -> float:
    """+1 when the input link (the one the balancing load acts on) is the joint's second link, else −1:
    the input link's rate is that times the joint's rate."""
    j = engine.mech.joints[inp.joint]
    return 1.0 if j.links[1] != engine.mech.ground else -1.0


def _drive_power(engine, motion, ks) -> np.ndarray:
    """Σ over the inputs of the balancing load times its link's rate (B,) (W)."""
    out = np.zeros(len(motion.phi))
    for inp in engine.inputs:
        out += ks.balancing[inp.joint] * _on_input_link(engine, inp) * motion.rate[:, motion.joint(inp.joint)]
    return out


def _cycle_efficiency(engine, motion, ks, ideal) -> float | None:
    """Work of the drive without friction over its work with friction along the batch (one input:
    ∫Q·dq over the input), None with several inputs or fewer than two positions."""
    if len(engine.inputs) != 1 or len(motion.phi) < 2:
        return None
    inp = engine.inputs[0]
    x = motion.phi[:, 0]

    def work(q):
        y = q * inp.sense * _on_input_link(engine, inp)
        return float(np.sum((y[1:] + y[:-1]) * np.diff(x)) / 2)

    total = work(ks.balancing[inp.joint])
    return work(ideal.balancing[inp.joint]) / total if total else None
