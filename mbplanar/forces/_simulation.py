"""Motion under given forces: the equations of motion of a mechanism of any number of degrees of
freedom in its generalised coordinates (the inputs φ), integrated in time with scipy's `solve_ivp`.

For inputs q (n,) the velocity of every link frame and centre of mass is linear in q̇: v_S = J_S·q̇,
ω = J_ω·q̇, with the Jacobians J taken from the kinematics (the velocity analogues with one input, the
velocities for unit input rates with several); the accelerations are J·q̈ + a₀, a₀ the convective part
(the accelerations for q̈ = 0). Lagrange's equations (d'Alembert's principle in the allowed velocities):

    M(q)·q̈ = Q(q, q̇, t) − Σ (m·J_Sᵀ·a₀S + I_S·J_ωᵀ·ε₀),   M(q) = Σ (m·J_SᵀJ_S + I_S·J_ωᵀJ_ω) + J_in,

Q the generalised forces of the model's loads (their power per unit of each q̇: springs, dampers,
torques, gravity, forces) plus the drive Q_in = `torque` − `motor_slope`·q̇ on each input. With one
input this is the reduced form J(φ)·φ̈ + ½·J′(φ)·φ̇² = M(φ, φ̇, t), since Σ(m·v_qS·a_qS + I_S·ω_q·ε_q)
= ½·dJ/dφ. The state (q, q̇) needs no projection: the positions are solved from q at every evaluation,
so the constraints hold to the Newton tolerance along the whole motion. The initial values are
consistent by construction: any position q₀ (on the drawn branch) and speed q̇₀; q̈₀ follows.

Along the computed motion, `kinetostatics` gives every joint reaction (the Lagrange multipliers of a
formulation in absolute coordinates), and the balancing moment at each input equals the drive.

The `[simulate]` section of a model (all keys optional)::

    [simulate]
    t = 0.03              # s, the end time (the command's --t overrides it)
    torque = 0.033        # N·m (N for a prismatic input; the table's moment_unit) along each input
    motor_slope = 0.0     # N·m·s/rad (moment_unit): drive = torque − motor_slope·q̇
    omega = 0.0           # initial speed(s) q̇₀ (default: 0); the start position is the drawn one
    rtol = 1e-10          # solve_ivp's tolerances and method
    atol = 1e-12
    method = "DOP853"
    steps = 100           # output intervals
    input_inertia = 0.0   # kg·m² (the table's inertia_unit) on each input link besides the links' own
    max_evaluations = 50000    # a motion that chatters at a switched load (a stalled press) stops here

Without a `torque` (here or given), a crank-driven model with `[dynamics]` runs as the machine that
section describes: the drive M_dr − slope·(q̇ − ω_m) (its `driving_moment`, else the constant that
balances the cycle's work), started at ω_m, with `[dynamics.flywheel] inertia` on the crank when no
`input_inertia` is given. Such a machine is first checked over one cycle by the energy equation
(`stall_ahead`): one that cannot run through its cycle (a flywheel missing) is refused at once, saying
where it stops. Any other model has no drive unless given (0).

A stall is found as it happens: when an input's speed passes through zero (or starts at zero) and the
drive cannot restart it (the accelerations just forward and just backward point back to zero: the
switched loads and friction hold it), the simulation stops with a one-line `MotionError` that says
when, where, and what the model lacks (a flywheel: `input_inertia`; a drive). The integration steps
scipy's solver one step at a time (the same steps and output as `solve_ivp` with `t_eval`), reporting
its progress and stopping on Ctrl-C with the motion so far (`Interrupted.partial`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from .._progress import Interrupted
from ..engine import dispatch, solve_positions
from ..errors import MbplanarError, ModelError, MotionError
from ..kinematics import analyse, material_points
from ._kinetostatics import kinetostatics
from ._loads import (evaluate_loads, heavy_links, load_power, read_gravity, read_loads, real_frames,
                     spring_energy, world_points)
from ..model import Key, Row, Section

__all__ = ["SimulateSpec", "Trajectory", "read_simulate", "simulate_motion", "accelerations", "SIMULATE"]

METHODS = ("DOP853", "RK45", "Radau", "BDF", "LSODA", "RK23")
_PER_INPUT = {"anyOf": [{"type": "number"}, {"type": "array", "items": {"type": "number"}}]}
SIMULATE = Section("simulate", "[simulate]", "the motion under given forces, integrated in time", (
    Key("t", "number", "the end time (the command's --t overrides it)", unit="s", positive=True),
    Key("torque", "custom", "drive along each input: a number, or one per input", unit="moment",
        default_doc="the machine of [dynamics] (its M_dr), else 0", schema=_PER_INPUT),
    Key("motor_slope", "custom", "drive = torque − motor_slope·q̇, per input", unit="moment*s/rad",
        default_doc="[dynamics]' motor_slope, else 0", schema=_PER_INPUT),
    Key("omega", "custom", "initial speed(s) q̇₀; the start position is the drawn one", unit="rad/s",
        default_doc="ω_m of [dynamics], else 0", schema=_PER_INPUT),
    Key("input_inertia", "custom", "inertia on each input link besides the links' own", unit="inertia",
        default_doc="[dynamics.flywheel] inertia, else 0", schema=_PER_INPUT),
    Key("rtol", "number", "solve_ivp's relative tolerance", default=1e-10, positive=True),
    Key("atol", "number", "solve_ivp's absolute tolerance", default=1e-12, positive=True),
    Key("method", "choice", "solve_ivp's method", default="DOP853", choices=METHODS),
    Key("steps", "number", "output intervals (a whole number)", default=100, positive=True),
    Key("max_evaluations", "number", "right-hand-side evaluations at most (a whole number)", default=50000,
        positive=True)))


@dataclass(frozen=True)
class SimulateSpec:
    """What drives the motion and how it is integrated: the drive `torque` (N·m or N) and `motor_slope`
    (N·m·s/rad) per input (None: the machine of `[dynamics]`, else 0 and 0), the start speed `omega`
    (rad/s or m/s) per input (None: 0, or ω_m), the start position `phi` (SI, None: the drawn pose), the
    end time `t` (s), solve_ivp's `rtol`, `atol`, `method`, the output `steps`, the `input_inertia`
    (kg·m² or kg) per input link besides the links' own (None: `[dynamics.flywheel] inertia`, else 0), and
    the most right-hand-side evaluations `max_evaluations`.

    The model's `[simulate]` section (`read_simulate`), SI; the section's keys are documented in
    docs/forces.md.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.forces import read_simulate
    >>> spec = read_simulate(mbplanar.read_model("models/squeezer.toml"))
    >>> spec.t, spec.torque, spec.rtol, spec.method
    (0.03, (0.033,), 1e-12, 'DOP853')
    """

    t: float | None = None
    torque: tuple[float, ...] | None = (0.0,)
    motor_slope: tuple[float, ...] | None = (0.0,)
    omega: tuple[float, ...] | None = None
    phi: tuple[float, ...] | None = None
    rtol: float = 1e-10
    atol: float = 1e-12
    method: str = "DOP853"
    steps: int = 100
    input_inertia: tuple[float, ...] | None = None
    max_evaluations: int = 50000


def read_simulate(mech, **override) -> SimulateSpec:
    """The model's `[simulate]` section as a `SimulateSpec`; keyword arguments that are not None
    override it (same names, SI).

    Parameters
    ----------
    mech : Mechanism
        The model (its section is in the table's units).
    override
        Fields of `SimulateSpec` to replace (SI; a per-input value as a number or a sequence); None
        leaves the section's.

    Returns
    -------
    SimulateSpec
        The run's data, SI.

    Raises
    ------
    ModelError
        A section that is not a table, an unknown key, a value out of its bounds, or a per-input list
        of the wrong length.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.forces import read_simulate
    >>> spec = read_simulate(mbplanar.read_model("models/squeezer.toml"), t=0.001, steps=10)
    >>> spec.t, spec.steps, spec.torque
    (0.001, 10, (0.033,))
    """
    raw = mech.extras.get("simulate", {})
    where = f"{mech.source}: simulate"
    if not isinstance(raw, dict):
        raise ModelError(f"{where}: expected a table")
    row = Row(raw, where, section=SIMULATE)
    n = len(mech.inputs)
    values = {"t": row.get("t")}
    for key in ("torque", "motor_slope", "omega", "input_inertia"):
        values[key] = _per_input(row, key, None, n)     # (absent: the machine of [dynamics], else 0)
    units = mech.units  # the section is in the table's units; the overrides are SI
    for key, scale in (("torque", units.moment_scale), ("motor_slope", units.moment_scale),
                       ("input_inertia", units.inertia_scale)):
        if values[key] is not None:
            values[key] = tuple(v * scale for v in values[key])
    for key in ("rtol", "atol", "method", "steps", "max_evaluations"):
        values[key] = row.get(key)
    row.check_unknown_keys()
    values.update({k: v for k, v in override.items() if v is not None})
    for key in ("torque", "motor_slope", "omega", "phi", "input_inertia"):
        if values.get(key) is not None:
            values[key] = _tuple(values[key], n, f"{where}: '{key}'")
    spec = SimulateSpec(**values)
    _check(spec, where)
    return spec


def _per_input(row: Row, key, default, n):
    value = row.raw(key)
    if value is None:
        return None if default is None else (default,) * n
    values = value if isinstance(value, list) else [value]
    return tuple(row._check_number(key, v) for v in values)


def _tuple(value, n, where) -> tuple[float, ...]:
    values = tuple(float(v) for v in np.atleast_1d(np.asarray(value, float)))
    if len(values) == 1 and n > 1:
        values *= n
    if len(values) != n:
        raise ModelError(f"{where}: expected {n} value(s), one per input, got {len(values)}")
    if not all(math.isfinite(v) for v in values):
        raise ModelError(f"{where}: values must be finite, got {values}")
    return values


def _check(spec: SimulateSpec, where):
    if spec.method not in METHODS:
        raise ModelError(f"{where}: 'method' must be one of {', '.join(METHODS)}, got {spec.method!r}")
    if spec.t is not None and not (math.isfinite(spec.t) and spec.t > 0):
        raise ModelError(f"{where}: the end time t must be a positive number of seconds, got {spec.t}")
    if not (0 < spec.rtol < 1 and 0 < spec.atol):
        raise ModelError(f"{where}: rtol must be in (0, 1) and atol positive, got {spec.rtol}, {spec.atol}")
    if int(spec.steps) != spec.steps or spec.steps < 1:
        raise ModelError(f"{where}: 'steps' must be a positive whole number, got {spec.steps}")
    if any(s < 0 for s in spec.motor_slope or ()):
        raise ModelError(f"{where}: 'motor_slope' must be >= 0 (a motor gives less when faster)")
    if spec.input_inertia is not None and any(j < 0 for j in spec.input_inertia):
        raise ModelError(f"{where}: 'input_inertia' must be >= 0")
    if int(spec.max_evaluations) != spec.max_evaluations:
        raise ModelError(f"{where}: 'max_evaluations' must be a whole number, got {spec.max_evaluations}")


# -- the equations of motion ------------------------------------------------------------------------
@dataclass
class _Columns:
    """The kinematics of one state: the Motion (real velocities, q̈ = 0), and per input k the link
    frames' velocities for q̇ = e_k (w (1, L), v (1, L, 2)), plus the convective accelerations."""

    motion: object
    cols: list
    e0: np.ndarray
    a0: np.ndarray


def _columns(engine, q, qd) -> _Columns:
    n = len(engine.inputs)
    if n == 1:
        _cover(engine, float(q[0]))
    m = analyse(engine, q[None, :], omega=qd[None, :], epsilon=np.zeros((1, n)))
    if not m.success:
        raise MotionError(f"the motion reaches a position it cannot pass: {m.message}", source=engine.mech.source)
    f = m.frames
    if f.analogues:
        om = qd[0]
        return _Columns(m, [(f.w, f.v)], f.e * om * om, f.a * om * om)
    sol = solve_positions(engine, q[None, :])
    cols = []
    for k in range(n):
        unit = np.zeros((1, n))
        unit[0, k] = 1.0
        engine.rates(sol, unit, np.zeros((1, n)))
        cols.append((sol.w.copy(), sol.v.copy()))
    engine.rates(sol, qd[None, :], np.zeros((1, n)))
    return _Columns(m, cols, sol.e.copy(), sol.a.copy())


def _cover(engine, x: float):
    """Extend the drawn branch's atlas past x by a turn (a revolute input) or by the model's size, so
    that a motion running on does not grow the atlas a little at every step."""
    atlas = engine.atlas()
    lo, hi = atlas.nodes[0].phi[0], atlas.nodes[-1].phi[0]
    if lo <= x <= hi:
        return
    span = 2 * math.pi if engine.mech.joints[engine.inputs[0].joint].kind == "R" else engine.size
    atlas.cover(min(lo, x - span), max(hi, x + span))


def _mass_and_forces(engine, c: _Columns, qd, spec: SimulateSpec, input_inertia):
    """M (n, n) and the right-hand side (n,) of M·q̈ = rhs, and the drive (n,)."""
    m = c.motion
    heavy = heavy_links(engine.mech)
    ks = np.array([engine.link_index[name] for name, _, _ in heavy], int)
    at = np.array([centre for _, _, centre in heavy], float).reshape(-1, 2)
    th, r = m.frames.th, m.frames.r
    mass = np.array([lk.mass for _, lk, _ in heavy])
    inertia = np.array([lk.inertia for _, lk, _ in heavy])
    zero_w, zero_v = np.zeros_like(c.cols[0][0]), np.zeros_like(c.cols[0][1])
    jv, jw = [], []
    for w, v in c.cols:
        _, vel, _ = material_points(th, r, w, v, zero_w, zero_v, ks, at)
        jv.append(vel[0])        # (H, 2)
        jw.append(w[0, ks])      # (H,)
    # the convective acceleration of a centre: its link's ε₀, a₀ and the real ω (centripetal part)
    w_real = sum(w * qd[k] for k, (w, _) in enumerate(c.cols))
    v_real = sum(v * qd[k] for k, (_, v) in enumerate(c.cols))
    _, _, acc0 = material_points(th, r, w_real, v_real, c.e0, c.a0, ks, at)
    acc0, e0 = acc0[0], c.e0[0, ks]
    jv, jw = np.array(jv), np.array(jw)  # (n, H, 2), (n, H)
    M = (np.einsum("h,khi,lhi->kl", mass, jv, jv) + np.einsum("h,kh,lh->kl", inertia, jw, jw)
         + np.diag(input_inertia))
    rhs = -(np.einsum("h,khi,hi->k", mass, jv, acc0) + np.einsum("h,kh,h->k", inertia, jw, e0))
    loads = evaluate_loads(engine, m)
    for k, (w, v) in enumerate(c.cols):
        rhs[k] += sum(float(load_power(ld, w, v, r)[0]) for ld in loads)
    drive = np.asarray(spec.torque) - np.asarray(spec.motor_slope) * qd
    return M, rhs + drive, drive, loads


def accelerations(engine, q, qd, spec: SimulateSpec, input_inertia=None) -> np.ndarray:
    """q̈ (n,) at the state (q, q̇) (SI) from the equations of motion."""
    q, qd = np.asarray(q, float).reshape(-1), np.asarray(qd, float).reshape(-1)
    J_in = np.zeros(len(q)) if input_inertia is None else np.asarray(input_inertia, float)
    if spec.torque is None or spec.motor_slope is None:
        spec = _drive(engine, spec)[0]
    M, rhs, _, _ = _mass_and_forces(engine, _columns(engine, q, qd), qd, spec, J_in)
    return _solve_mass(engine, M, rhs)


def _solve_mass(engine, M, rhs):
    try:
        out = np.linalg.solve(M, rhs)
    except np.linalg.LinAlgError:
        out = np.full(len(rhs), np.nan)
    if not np.all(np.isfinite(out)):
        raise MotionError("the generalised mass matrix is singular (a link without mass or inertia moves while "
                          "every massive link stands still?)", source=engine.mech.source)
    return out


# -- integration ------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class Trajectory:
    """The motion over time: t (N,), phi, omega, epsilon (N, n) of the inputs; `motion` (a Motion with
    the real rates at every t), `kinetostatics` (the reactions along it, the balancing loads equal to
    `drive`), `drive` (N, n), `energy` (kinetic, potential, drive_work, (N,) each, J), and the solver's
    success, message and number of evaluations.

    Attributes
    ----------
    t : ndarray, shape (N,)
        The output times (s).
    phi, omega, epsilon : ndarray, shape (N, n)
        The n inputs' values, speeds and accelerations (SI).
    drive : ndarray, shape (N, n)
        The drive's moment (N·m) or force (N) on each input.
    motion : Motion
        The positions with their real rates at every t.
    kinetostatics : Kinetostatics
        The reactions along the motion (its balancing loads equal `drive`).
    energy : dict of str to ndarray, shape (N,)
        "kinetic", "potential" (springs and gravity), "drive_work" (J).
    success : bool
        The solver reached the end time.
    message : str
        The solver's message.
    nfev : int
        Evaluations of the equations of motion.
    spec : SimulateSpec
        What ran.

    Examples
    --------
    A wheel of 0.5 kg·m² driven by 1 N·m from rest: ε = 2 rad/s², ω = 2t, φ = t², its kinetic energy the
    drive's work.

    >>> import mbplanar
    >>> m = mbplanar.parse_model({"links": [{"name": "1", "inertia": 0.5}],
    ...     "joints": [{"name": "O", "type": "R", "links": ["0", "1"], "at": [0, 0]}],
    ...     "input": {"joint": "O", "unit": "rad"}, "simulate": {"torque": 1.0, "t": 1.0, "steps": 4}})
    >>> from mbplanar.forces import simulate_motion
    >>> run = simulate_motion(mbplanar.Engine(m))
    >>> run.t, run.phi[:, 0].round(9), run.omega[:, 0].round(9)
    (array([0.  , 0.25, 0.5 , 0.75, 1.  ]), array([0.    , 0.0625, 0.25  , 0.5625, 1.    ]), array([0. , 0.5, 1.
    , 1.5, 2. ]))
    >>> bool(abs(run.energy["kinetic"] - run.energy["drive_work"]).max() < 1e-9)
    True
    """

    t: np.ndarray
    phi: np.ndarray
    omega: np.ndarray
    epsilon: np.ndarray
    drive: np.ndarray
    motion: object
    kinetostatics: object
    energy: dict
    success: bool
    message: str
    nfev: int
    spec: SimulateSpec = field(default_factory=SimulateSpec)


def simulate_motion(engine, spec: SimulateSpec | None = None, input_inertia=None, progress=None) -> Trajectory:
    """Integrate the equations of motion from the start state of `spec` (default: the model's
    `[simulate]` section) to its end time, with scipy's solver stepped as `solve_ivp` steps it; the
    reactions along the motion follow. `input_inertia` (default: the spec's) is added on each input link.
    `progress(t)` is called after each step with the time reached.


    Parameters
    ----------
    engine : Engine
        The mechanism.
    spec : SimulateSpec, optional
        The drive, the start state, the end time and the solver (default: `read_simulate` of the model).
    input_inertia : float or array_like, optional
        Inertia (kg·m², or kg) on each input link besides the links' own, instead of the spec's.
    progress : callable, optional
        Called as ``progress(t)`` after each step.

    Returns
    -------
    Trajectory
        The inputs over time, the motion with its real rates, the reactions along it and the energies.

    Raises
    ------
    ModelError
        No end time (`t`), or a start state the model cannot take.
    MotionError
        An input stalls (its speed through zero, the drive unable to restart it), naming what the model
        lacks; or the solver needs more than `max_evaluations`.
    Interrupted
        Ctrl-C, with the motion so far as its `partial`.

    Examples
    --------
    A wheel of 0.5 kg·m² driven by 1 N·m from rest: ε = 2 rad/s², ω = 2t, φ = t², its kinetic energy the
    drive's work.

    >>> import mbplanar
    >>> m = mbplanar.parse_model({"links": [{"name": "1", "inertia": 0.5}],
    ...     "joints": [{"name": "O", "type": "R", "links": ["0", "1"], "at": [0, 0]}],
    ...     "input": {"joint": "O", "unit": "rad"}, "simulate": {"torque": 1.0, "t": 1.0, "steps": 4}})
    >>> from mbplanar.forces import simulate_motion
    >>> run = simulate_motion(mbplanar.Engine(m), mbplanar.forces.read_simulate(m, t=0.5, steps=2))
    >>> run.t, run.omega[:, 0].round(9), run.epsilon[:, 0].round(9), run.success
    (array([0.  , 0.25, 0.5 ]), array([0. , 0.5, 1. ]), array([2., 2., 2.]), True)
    """
    mech = engine.mech
    spec = spec or read_simulate(mech)
    if spec.t is None:
        raise ModelError("no end time: give --t or t = ... in [simulate]", source=mech.source)
    n = len(engine.inputs)
    spec, machine = _drive(engine, spec)
    q0 = np.array(spec.phi if spec.phi is not None else engine.phi_drawn, float)
    qd0 = np.array(spec.omega if spec.omega is not None else (0.0,) * n, float)
    if input_inertia is None:
        input_inertia = spec.input_inertia
    J_in = np.broadcast_to(np.asarray(input_inertia, float), (n,))
    if machine is not None and qd0[0] > 0:
        _check_cycle(engine, machine, float(J_in[0]), float(q0[0]), float(qd0[0]))
    # (no backend integrates: the seam says so and numpy does; each evaluation's position goes through it)
    return dispatch(engine, "simulation", int(spec.steps) + 1,
                    lambda: _simulate(engine, spec, q0, qd0, J_in, machine, progress))


def _simulate(engine, spec: SimulateSpec, q0, qd0, J_in, machine, progress) -> Trajectory:
    """`simulate_motion` from q0, qd0 (n,) with J_in (n,) on the input links, the drive settled."""
    mech, n = engine.mech, len(engine.inputs)
    calls = [0]

    def rhs(t, y):
        calls[0] += 1
        if calls[0] > spec.max_evaluations:
            raise MotionError(f"{spec.max_evaluations} evaluations reached at t = {t:.9g} s: the motion chatters "
                              "(a switched load at a stall?) or needs a looser rtol", source=mech.source)
        q, qd = y[:n], y[n:2 * n]
        M, b, drive, _ = _mass_and_forces(engine, _columns(engine, q, qd), qd, spec, J_in)
        qdd = _solve_mass(engine, M, b)
        return np.concatenate([qd, qdd, [float(drive @ qd)]])

    stall = _Stall(engine, spec, J_in, machine)
    try:
        t, y, success, message = _integrate(rhs, np.concatenate([q0, qd0, [0.0]]), spec, n, stall, progress)
    except MotionError as exc:
        raise MotionError(f"{exc.message} (simulating from t = 0 to {spec.t} s)", source=exc.source,
                          where=exc.where) from None
    except _Stopped as stop:
        partial = _trajectory(engine, spec, J_in, stop.t, stop.y, False, "interrupted", calls[0]) if len(stop.t) else None
        raise Interrupted(f"interrupted (Ctrl-C) at t = {stop.at:.6g} s of {spec.t:g} s", source=mech.source,
                          partial=partial) from None
    return _trajectory(engine, spec, J_in, t, y, success, message, calls[0])


def _trajectory(engine, spec, J_in, t, y, success, message, nfev) -> Trajectory:
    """The Trajectory of the states y (N, 2n + 1) at the times t (N,): accelerations, positions,
    reactions and energies along them."""
    n = len(engine.inputs)
    phi, omega, work = y[:, :n], y[:, n:2 * n], y[:, 2 * n]
    eps = np.array([accelerations(engine, q, qd, spec, J_in) for q, qd in zip(phi, omega)]).reshape(-1, n)
    drive = np.asarray(spec.torque)[None, :] - np.asarray(spec.motor_slope)[None, :] * omega
    motion = analyse(engine, phi, omega=omega, epsilon=eps)
    ks = kinetostatics(engine, motion, input_inertia=J_in)
    energy = {"kinetic": _kinetic(engine, motion, omega, J_in), "potential": _potential(engine, motion),
              "drive_work": work}
    return Trajectory(t, phi, omega, eps, drive, motion, ks, energy, bool(success), message, int(nfev), spec)


class _Stopped(Exception):
    """Ctrl-C during the integration: the output rows so far (t (N,), y (N, 2n + 1)) and the time reached."""

    def __init__(self, t, y, at):
        super().__init__()
        self.t, self.y, self.at = t, y, at


_FINISHED = "The solver successfully reached the end of the integration interval."  # (solve_ivp's words)


def _integrate(rhs, y0, spec: SimulateSpec, n: int, stall, progress):
    """solve_ivp(rhs, (0, t), y0, method, t_eval=grid, rtol, atol), stepped here: after each step the
    output points it passed are read from its dense output (as solve_ivp does, so the numbers are the
    same), the inputs' speeds are watched for a stall (`_Stall`) and `progress(t)` is called."""
    import scipy.integrate

    solver = getattr(scipy.integrate, spec.method)(rhs, 0.0, y0, spec.t, rtol=spec.rtol, atol=spec.atol)
    grid = np.linspace(0.0, spec.t, int(spec.steps) + 1)
    ts, ys, i, status, message = [], [], 0, None, _FINISHED
    stall.at_start(y0)
    try:
        while status is None:
            previous = solver.y.copy()
            message = solver.step() or _FINISHED
            if solver.status == "failed":
                status = -1
                break
            status = 0 if solver.status == "finished" else None
            dense = None
            end = int(np.searchsorted(grid, solver.t, side="right"))
            if end > i:
                dense = solver.dense_output()
                ts.append(grid[i:end])
                ys.append(dense(grid[i:end]))
                i = end
            stall.after_step(solver, previous, dense)
            if progress is not None:
                progress(float(solver.t))
    except KeyboardInterrupt:
        raise _Stopped(np.concatenate(ts) if ts else np.zeros(0),
                       np.hstack(ys).T if ys else np.zeros((0, len(y0))), float(solver.t)) from None
    t = np.concatenate(ts) if ts else np.zeros(0)
    y = np.hstack(ys).T if ys else np.zeros((0, len(y0)))
    return t, y, status == 0, message


class _Stall:
    """Watches the inputs' speeds: where one passes through zero (or starts at zero), the motion is
    stuck when the accelerations just forward and just backward both point back to zero (the drive
    cannot restart it against the switched loads and friction): then a `MotionError` says so."""

    def __init__(self, engine, spec, J_in, machine):
        self.engine, self.spec, self.J_in, self.machine = engine, spec, J_in, machine
        self.n = len(engine.inputs)

    def at_start(self, y0):
        for k in range(self.n):
            if y0[self.n + k] == 0:
                self._check(0.0, y0, k)

    def after_step(self, solver, previous, dense):
        n = self.n
        for k in range(n):
            a, b = previous[n + k], solver.y[n + k]
            if a == 0 or (a > 0) == (b > 0) and b != 0:
                continue
            dense = dense or solver.dense_output()
            at = solver.t if b == 0 else _root(lambda x: dense(x)[n + k], solver.t_old, solver.t)
            self._check(at, dense(at), k)

    def _check(self, t, y, k):
        n = self.n
        q, qd = y[:n].copy(), y[n:2 * n].copy()
        qd[k] = 0.0
        delta = 1e-9 * max(1.0, float(np.max(np.abs(qd))))
        ahead, back = qd.copy(), qd.copy()
        ahead[k], back[k] = delta, -delta
        forward = accelerations(self.engine, q, ahead, self.spec, self.J_in)[k]
        backward = accelerations(self.engine, q, back, self.spec, self.J_in)[k]
        if forward < 0 < backward:
            raise _stall_error(self.engine, self.spec, self.J_in, self.machine, k, t, q[k],
                               f"its speed {'is' if t == 0 else 'falls to'} zero and the drive cannot "
                               f"{'start' if t == 0 else 'restart'} it: the loads hold it there (φ̈ = "
                               f"{forward:.3g} just forward, {backward:.3g} just backward)")


def _root(f, a, b, tol=1e-14):
    """A root of f in [a, b] where f changes sign (bisection to the float resolution of t)."""
    fa = f(a)
    for _ in range(200):
        m = 0.5 * (a + b)
        if b - a <= tol * max(1.0, abs(b)):
            break
        fm = f(m)
        if (fm > 0) == (fa > 0) and fm != 0:
            a, fa = m, fm
        else:
            b = m
    return b


def _drive(engine, spec: SimulateSpec):
    """The spec with its drive, speeds and input inertia settled, and the machine dynamics it was taken
    from (None unless the drive is that of `[dynamics]`, see the module docstring)."""
    n = len(engine.inputs)
    mech = engine.mech
    fly = mech.dynamics.flywheel.inertia if mech.dynamics is not None else None
    inertia = spec.input_inertia if spec.input_inertia is not None else (fly if fly is not None else 0.0,) * n
    if spec.torque is not None or mech.dynamics is None:
        return replace(spec, torque=spec.torque if spec.torque is not None else (0.0,) * n,
                       motor_slope=spec.motor_slope if spec.motor_slope is not None else (0.0,) * n,
                       input_inertia=inertia), None
    from ._dynamics import machine_dynamics
    dyn = machine_dynamics(engine, simulate_motion=False)
    slope = spec.motor_slope if spec.motor_slope is not None else (dyn.spec.motor_slope,)
    torque = (dyn.driving_moment + slope[0] * dyn.spec.omega_mean,)   # M_dr − slope·(q̇ − ω_m)
    omega = spec.omega if spec.omega is not None else (dyn.spec.omega_mean,)
    return replace(spec, torque=torque, motor_slope=slope, omega=omega, input_inertia=inertia), dyn


def _check_cycle(engine, dyn, J_in: float, phi0: float, omega0: float):
    """Refuse, at once, a machine of `[dynamics]` that stalls within its first cycle (`stall_ahead`)."""
    from ._dynamics import stall_ahead
    hit = stall_ahead(dyn, J_in + dyn.input_link_inertia, phi0, omega0)
    if hit is not None:
        phi, t = hit
        raise _stall_error(engine, None, np.array([J_in]), dyn, 0, t, phi,
                           f"started at {omega0:.6g} rad/s with the drive of [dynamics] (M_dr = "
                           f"{dyn.driving_moment:.6g} N·m), the machine slows to a stop there, before the end of "
                           "its first cycle, and the drive cannot carry it through the loads",
                           approximate=True)


def _stall_error(engine, spec, J_in, dyn, k, t, q, how, approximate=False) -> MotionError:
    """The one-line stall message: when, where, how, and what the model lacks."""
    inp = engine.inputs[k]
    about = "≈ " if approximate else "= "
    where = f"{inp.name} {about}{inp.from_si(q):.6g} {inp.unit}"
    kind = "kg" if engine.mech.joints[inp.joint].kind == "P" else "kg·m²"
    if dyn is None and engine.mech.dynamics is not None and len(engine.inputs) == 1:
        from ._dynamics import machine_dynamics
        try:
            dyn = machine_dynamics(engine, simulate_motion=False)
        except MbplanarError:
            dyn = None
    if dyn is not None:
        J_I = dyn.inertia_first_group - dyn.input_link_inertia
        sized = f"; `mbplanar dynamics` sizes J_I = {J_I:.6g} kg·m² for δ = {dyn.spec.delta:g}"
    else:
        sized = ""
    if t == 0:
        lacks = ("give a drive that overcomes the loads there (--torque, [simulate] torque) or a start speed "
                 f"(--omega){sized}")
    elif J_in[k] == 0:
        lacks = (f"the model has no flywheel on input '{inp.name}' (input inertia 0): give --input-inertia J "
                 f"({kind}), [simulate] input_inertia or [dynamics.flywheel] inertia{sized}")
    else:
        lacks = (f"its input inertia {J_in[k]:.6g} {kind} is too small or the drive too weak: give a larger "
                 f"--input-inertia or --torque{sized}")
    return MotionError(f"{inp.name} stalls at t {about}{t:.6g} s ({where}): {how}; {lacks}",
                       source=engine.mech.source)


def _kinetic(engine, motion, omega, J_in) -> np.ndarray:
    """Kinetic energy (B,) of every heavy link and the input inertias (J)."""
    heavy = heavy_links(engine.mech)
    out = 0.5 * np.sum(J_in[None, :] * omega * omega, axis=1)
    if not heavy:
        return out
    ks = np.array([engine.link_index[name] for name, _, _ in heavy], int)
    at = np.array([centre for _, _, centre in heavy], float)
    f = motion.frames
    w = motion.w
    if f.analogues:
        v = f.v * motion.omega[:, :1, None]
    else:
        w, v, _, _ = real_frames(engine, motion)
    _, vel, _ = material_points(f.th, f.r, w, v, np.zeros_like(w), np.zeros_like(v), ks, at)
    for i, (_, lk, _) in enumerate(heavy):
        out += 0.5 * (lk.mass * np.einsum("bi,bi->b", vel[:, i], vel[:, i]) + lk.inertia * w[:, ks[i]] ** 2)
    return out


def _potential(engine, motion) -> np.ndarray:
    """Potential energy (B,) of the springs and of gravity (J)."""
    out = np.zeros(len(motion.phi))
    for load in read_loads(engine.mech):
        if load.kind == "spring":
            out += spring_energy(engine, motion, load)
    g = read_gravity(engine.mech)
    if g is not None:
        for name, lk, centre in heavy_links(engine.mech):
            if lk.mass:
                xy = world_points(motion, engine.link_index[name], np.asarray(centre, float))
                out -= lk.mass * (xy @ g.vector)
    return out
