"""Machine dynamics of a machine driven by one crank: reduced inertia and moments, work and energy,
the flywheel for a coefficient of speed fluctuation δ, and the true motion ω(φ), ε(φ) of the crank.

The machine is reduced to its input link (the crank, generalized coordinate φ in rad):

* second group, the links whose reduced inertia varies: J_II(φ) = Σ(m·v_qS² + I_S·ω_q²) over every
  moving link except the input link, and dJ_II/dφ = 2·Σ(m·v_qS·a_qS + I_S·ω_q·ε_q);
* reduced moment of each load: M_red(φ) = F·v_q + M·ω_q (the power of the load per unit of dφ/dt);
* first group: everything with a constant reduced inertia (the input link itself, shafts, the flywheel),
  J_I = (ΔT_I,max − ΔT_I,min)/(ω_m²·δ) — the energy–mass method of the course books (seeds 000, 003):
  A_c(φ) = ∫₀^φ M_red dφ (trapezoid rule on the cycle grid), M_dr = −A_c(2π)/2π (a constant driving
  moment that balances the cycle), A_Σ = A_c + M_dr·φ, T_II = J_II·ω_m²/2, ΔT_I = A_Σ − T_II,
  ω(φ) = ω_m + (ΔT_I − (ΔT_I,max + ΔT_I,min)/2)/(J_I·ω_m),
  ε(φ) = (M_red + M_dr)/(J_I + J_II) − ω²·J_II′/(2(J_I + J_II)).

Beyond the seeds, `simulate` integrates the exact equation of motion
(J_I + J_II)·φ̈ + ½·J_II′·φ̇² = M_dr(φ̇) + M_red(φ) with scipy's solve_ivp (φ as the independent
variable) to a periodic steady state and reports the δ it achieves.

The `[dynamics]` section of a model (all keys optional but `delta`)::

    [dynamics]
    delta = 0.05              # coefficient of speed fluctuation (ω_max − ω_min)/ω_m
    omega_mean = 7.64         # ω_m in rad/s (default: the input's omega)
    driving_moment = 102.0    # N·m along φ (default: the constant that balances the cycle)
    motor_slope = 0.0         # N·m·s/rad: motor characteristic M_dr(ω) = M_dr − slope·(ω − ω_m)
    [dynamics.flywheel]
    shaft_inertia = 0.1625    # kg·m² already on the crank shaft (gears, couplings)
    motor_rpm = 1412.4        # put the flywheel on the motor shaft turning this fast (rev/min)
    motor_inertia = 0.0875    # kg·m² of the motor rotor, on the motor shaft
    density = 7800            # kg/m³ of the flywheel

Flywheel sizes follow the course books' formulas for steel (ρ₀ = 7800 kg/m³), scaled to `density`
(J ∝ ρ·D⁵): a rim D₂ = 0.437·(J·ρ₀/ρ)^(1/5), D₁ = 0.8·D₂, b = 0.2·D₂, m = 6123·(ρ/ρ₀)·(D₂² − D₁²)·b;
a disc D = 0.366·(J·ρ₀/ρ)^(1/5), b = 0.2·D, m = 1230·(ρ/ρ₀)·D³.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..errors import ModelError, MotionError
from ..kinematics import analyse, material_points
from ._loads import centre_of, evaluate_loads, load_power, warn_idle_resistances
from ..model import RHO_STEEL, DynamicsSpec, FlywheelSpec, crank_input

__all__ = ["DynamicsSpec", "FlywheelSpec", "Reduced", "Dynamics", "Simulation", "Flywheel", "Rim", "Disc",
           "read_dynamics", "reduce", "machine_dynamics", "true_motion", "simulate", "stall_ahead", "flywheel_sizes",
           "summary"]

_RIM = (0.437, 6123.0)    # D₂ = c·J^(1/5), m = k·(D₂² − D₁²)·b at ρ₀ (course-book constants)
_DISC = (0.366, 1230.0)   # D = c·J^(1/5), m = k·D³ at ρ₀


def read_dynamics(mech, delta: float | None = None) -> DynamicsSpec | None:
    """The model's dynamics data (`Mechanism.dynamics`, read with the table), None when there is none
    and no `delta` is given; `delta` overrides the model's δ (a model without `[dynamics]` then runs at
    the input's ω).

    Parameters
    ----------
    mech : Mechanism
        The model.
    delta : float, optional
        The coefficient of speed fluctuation (ω_max − ω_min)/ω_m to use instead of the model's, in (0, 1).

    Returns
    -------
    DynamicsSpec or None
        The section, with `delta` when given; None without a section and without `delta`.

    Raises
    ------
    ModelError
        `delta` outside (0, 1), or `delta` on a model without `[dynamics]` whose input has no positive omega.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.forces import read_dynamics
    >>> read_dynamics(mbplanar.read_model("models/shaper.toml"), delta=0.02).delta
    0.02
    >>> spec = read_dynamics(mbplanar.read_model("models/fourbar_loaded.toml"), delta=0.1)
    >>> spec.delta, spec.omega_mean                   # at the input's omega
    (0.1, 10.0)
    >>> read_dynamics(mbplanar.read_model("models/fourbar_loaded.toml")) is None
    True
    """
    spec = mech.dynamics
    if delta is None:
        return spec
    if not (math.isfinite(delta) and 0 < delta < 1):
        raise ModelError(f"delta = {delta} must be between 0 and 1 (it is (ω_max − ω_min)/ω_m)",
                         source=mech.source, where="dynamics")
    if spec is None:
        omega = crank_input(mech).omega
        if not omega > 0:
            raise ModelError(f"--delta without a [dynamics] section runs at the input's omega, which is {omega:g} "
                             "rad/s: give the input's omega (or [dynamics] omega_mean), positive",
                             source=mech.source, where="dynamics")
        return DynamicsSpec(delta, omega)
    return replace(spec, delta=delta)


# -- reduction to the crank -------------------------------------------------------------------------
@dataclass(frozen=True, eq=False, repr=False)
class Reduced:
    """The machine reduced to its crank over a batch of positions φ (B,), rad.

    Attributes
    ----------
    phi : ndarray (B,)
    J_II, dJ_II : ndarray (B,)
        Reduced inertia of the second group (kg·m²) and its derivative dJ_II/dφ.
    J_input : ndarray (B,)
        Reduced inertia of the input link (constant for a crank; part of the first group).
    moments : dict of str to ndarray (B,)
        Load name → its reduced moment (N·m).
    kinds : dict of str to str
        Load name → its kind (resistance, friction, gravity (weights too), force, moment).
    motion : Motion
        The positions (at ω = 1, ε = 0: the analogues).
    M_red : ndarray (B,)
        The reduced moments' sum (N·m).

    Examples
    --------
    The shaper at crank angles 0° and 90°: its ram stands still at 0°, so nothing of the second group
    moves and no load is reduced; `by_kind` sums the moments per kind of load.

    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/shaper.toml"))
    >>> from mbplanar.forces import reduce
    >>> red = reduce(engine, np.radians([0.0, 90.0]))
    >>> red.J_II.round(4), red.M_red.round(3) + 0.0
    (array([0.   , 2.327]), array([   0.   , -229.539]))
    >>> {kind: m.round(3) + 0.0 for kind, m in red.by_kind().items()}
    {'resistance': array([   0.   , -197.373]), 'friction': array([  0.   , -30.503]), 'gravity': array([ 0.   ,
    -1.662])}
    """

    phi: np.ndarray
    J_II: np.ndarray
    dJ_II: np.ndarray
    J_input: np.ndarray
    moments: dict
    kinds: dict
    motion: object = None
    M_red: np.ndarray | None = None

    def __repr__(self) -> str:
        return f"Reduced({len(self.phi)} positions, loads {', '.join(self.moments)})"

    def by_kind(self) -> dict:
        """Reduced moment (B,) summed per kind of load."""
        out = {}
        for name, m in self.moments.items():
            out[self.kinds[name]] = out.get(self.kinds[name], 0.0) + m
        return out


def reduce(engine, phi, omega: float = 1.0) -> Reduced:
    """Reduced inertia (and its derivative) and reduced moments of the loads at the input values `phi`
    (SI, (B,)); MotionError if a position cannot be reached on the drawn branch. Loads that depend on
    the speed (dampers) are evaluated at the input speed `omega` (rad/s).

    J_II = Σ m·v_S,q² + I_S·ω_q² over the links outside the first group (v_q, ω_q the analogues),
    dJ_II/dφ its exact derivative from the second analogues, and per load its power at unit input
    speed (its reduced moment).

    Parameters
    ----------
    engine : Engine
        A one-input mechanism.
    phi : array_like, shape (B,)
        The input's values (SI).
    omega : float
        The input speed the speed-dependent loads are evaluated at (rad/s).

    Returns
    -------
    Reduced
        J_II, dJ_II, J_input and the reduced moments (per load and in sum) over the B positions.

    Raises
    ------
    MotionError
        A position that cannot be reached on the drawn branch.

    Examples
    --------
    dJ_II/dφ agrees with a central difference of J_II (h = 1e-5 rad):

    >>> import numpy as np, mbplanar
    >>> from mbplanar.forces import reduce
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> red = reduce(engine, [1.0 - 1e-5, 1.0, 1.0 + 1e-5])
    >>> round(float(red.dJ_II[1]), 7), round(float(red.J_II[2] - red.J_II[0]) / 2e-5, 7)
    (0.0220615, 0.0220615)
    """
    phi = np.asarray(phi, float).reshape(-1)
    motion = analyse(engine, phi, omega=1.0, epsilon=0.0)
    if not motion.success:
        raise MotionError("machine dynamics needs every position of the cycle: "
                          f"{motion.message}", source=engine.mech.source)
    J_II, dJ_II, J_input = _reduced_inertia(engine, motion)
    dampers = any(ld.kind == "damper" for ld in engine.mech.loads)
    at_speed = analyse(engine, phi, omega=omega, epsilon=0.0) if dampers and omega != 1.0 else motion
    loads = evaluate_loads(engine, at_speed)
    kinds = {ld.name: ld.kind for ld in engine.mech.loads}  # LoadValue names are the rows' names
    moments, kind_of = {}, {}
    w, v, r = motion.frames.w, motion.frames.v, motion.frames.r
    for ld in loads:
        moments[ld.name] = moments.get(ld.name, 0.0) + load_power(ld, w, v, r)  # a spring: both ends
        kind = kinds.get(ld.name, "gravity")
        kind_of[ld.name] = "gravity" if kind == "weight" else kind
    return Reduced(phi, J_II, dJ_II, J_input, moments, kind_of, motion, sum(moments.values(), np.zeros(len(phi))))


def _input_links(engine) -> set:
    mech = engine.mech
    return {n for inp in engine.inputs for n in mech.joints[inp.joint].links if n != mech.ground}


def first_group(engine) -> frozenset:
    """The links of the first group, whose reduced inertia is constant: the input link, and the wheels
    (gears turning about their centre of mass, `engine._solver.wheels`) that the gears turn at a constant
    ratio to it (their reduced inertia I·(ω_wheel/ω)² + m·v² is the same all round the cycle; a planet on a
    carrier that a linkage swings is not). Found once per engine, on 16 positions of a turn."""
    def find():
        inputs = _input_links(engine)
        wheels = [w for w in getattr(engine.solver, "wheels", ()) if w not in inputs]
        if not wheels:
            return frozenset(inputs)
        phi = float(engine.phi_drawn[0]) + np.linspace(0.0, 2 * math.pi, 16, endpoint=False)
        motion = analyse(engine, phi, omega=1.0, epsilon=0.0)
        if not motion.success:
            return frozenset(inputs)
        k = np.array([engine.link_index[w] for w in wheels])
        centres = np.array([engine.mech.joints_of(w)[0].at for w in wheels], float)
        f = motion.frames
        _, v, _ = material_points(f.th, f.r, f.w, f.v, f.e, f.a, k, centres)
        wq = f.w[:, k]
        speed = np.hypot(v[..., 0], v[..., 1])
        steady = [w for j, w in enumerate(wheels)
                  if np.ptp(np.abs(wq[:, j])) <= 1e-9 * (1 + np.abs(wq[:, j]).max())
                  and np.ptp(speed[:, j]) <= 1e-9 * (engine.size + speed[:, j].max())]
        return frozenset(inputs) | frozenset(steady)
    return engine.prepare("first group", find)


def _reduced_inertia(engine, motion):
    """J_II, dJ_II over the links other than those of the first group, and J of the first group's links
    (the input link and the wheels geared to it, `first_group`), (B,) each."""
    mech, f = engine.mech, motion.frames
    batch = len(motion.phi)
    J_II, dJ_II, J_input = np.zeros(batch), np.zeros(batch), np.zeros(batch)
    inputs = first_group(engine) if mech.higher else _input_links(engine)
    for name, lk in mech.links.items():
        if name == mech.ground or not (lk.mass or lk.inertia):
            continue
        k = engine.link_index[name]
        at = np.array([centre_of(mech, name)]) if lk.mass else np.zeros((1, 2))
        _, vq, aq = material_points(f.th, f.r, f.w, f.v, f.e, f.a, np.array([k]), at)
        vq, aq, wq, eq = vq[:, 0], aq[:, 0], f.w[:, k], f.e[:, k]
        J = lk.mass * np.einsum("bi,bi->b", vq, vq) + lk.inertia * wq * wq
        if name in inputs:
            J_input += J
            continue
        J_II += J
        dJ_II += 2.0 * (lk.mass * np.einsum("bi,bi->b", vq, aq) + lk.inertia * wq * eq)
    return J_II, dJ_II, J_input


# -- the energy–mass method -------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class Simulation:
    """The exact steady-state motion over the cycle grid (`simulate`, `Dynamics.simulation`).

    Attributes
    ----------
    omega, epsilon : ndarray, shape (N,)
        ω(φ), ε(φ) of the crank on the cycle grid (rad/s, rad/s²).
    delta : float
        Its coefficient of speed fluctuation (ω_max − ω_min)/ω_m.
    omega_min, omega_max : float
        Its speed range (rad/s).
    omega_time_mean : float
        The mean speed over time, 2π / period (rad/s).
    period : float
        The time of one cycle (s).
    success : bool
        The periodic state was found.
    message : str
        "periodic steady state", or why not.

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/shaper.toml"))
    >>> dyn = mbplanar.machine_dynamics(engine, steps=360, simulate_motion=False)     # a coarse cycle
    >>> from mbplanar.forces import simulate
    >>> sim = simulate(dyn, rtol=1e-6)
    >>> sim.success, round(sim.delta, 3), round(float(sim.period), 3), sim.omega.shape
    (True, 0.048, 0.819, (361,))
    """

    omega: np.ndarray
    epsilon: np.ndarray
    delta: float
    omega_min: float
    omega_max: float
    omega_time_mean: float
    period: float
    success: bool
    message: str


@dataclass(frozen=True)
class Rim:
    """A flywheel rim (m, kg): outer and inner diameter, width, mass."""

    outer_diameter: float
    inner_diameter: float
    width: float
    mass: float


@dataclass(frozen=True)
class Disc:
    """A flywheel disc (m, kg): diameter, width, mass."""

    diameter: float
    width: float
    mass: float


@dataclass(frozen=True)
class Flywheel:
    """The flywheel the energy–mass method asks for (`flywheel_sizes`).

    Attributes
    ----------
    inertia : float
        J of the flywheel on its shaft (kg·m²).
    inertia_on_crank_shaft : float
        The same on the crank shaft (kg·m²).
    shaft : str
        "crank", "motor" (``motor_rpm`` given), or the link of the model it is on (``link`` given).
    speed_ratio : float
        Its shaft's speed over the crank's (1 on the crank shaft; from the gears on a link).
    density : float
        Of its material (kg/m³).
    needed : bool
        False when the machine's own first-group inertia is enough (no rim, no disc).
    rim, disc : Rim, Disc or None
        Its sizes as a rim and as a disc (None where not needed).
    """

    inertia: float
    inertia_on_crank_shaft: float
    shaft: str
    speed_ratio: float
    density: float
    needed: bool
    rim: Rim | None = None
    disc: Disc | None = None


@dataclass(frozen=True, eq=False, repr=False)
class Dynamics:
    """Machine dynamics over one cycle φ = 0 … 2π (grid `phi` (N,), rad), by the energy–mass method.

    Attributes
    ----------
    spec : DynamicsSpec
        The `[dynamics]` section it was computed for.
    reduced : Reduced
        Reduced inertias and moments over the grid (per load in ``reduced.moments``).
    phi : ndarray (N,)
        The grid (rad).
    A_c : ndarray (N,)
        Work of the loads from φ = 0 (J).
    driving_moment : float
        M_dr (N·m along φ).
    inertia_first_group : float
        J_I (kg·m²).
    dT_I_max, dT_I_min : float
        Extremes of ΔT_I (J), at `phi_dT_max`, `phi_dT_min` (rad).
    J_II, dJ_II, M_red : ndarray (N,)
        Second group's reduced inertia and its derivative, the total reduced moment.
    omega_mean : float
        ω_m (rad/s).
    resistance_work : float
        A_c(2π) (J).
    input_link_inertia : float
        The input link's share of J_I (kg·m²).
    A_total, T_II, dT_I : ndarray (N,)
        A_c + M_dr·φ, J_II·ω_m²/2, ΔT_I (J).
    omega, epsilon : ndarray (N,)
        ω(φ), ε(φ) of the crank (rad/s, rad/s²).
    omega_min, omega_max, epsilon_min, epsilon_max : float
        Their extremes.
    simulation : Simulation or None
        The exact steady-state motion (`machine_dynamics(..., simulate_motion=True)`).
    delta_simulated : float or None
        Its δ.
    flywheel : Flywheel
        The flywheel's inertia and sizes.
    success : bool
        The simulation, where asked for, found the periodic motion.
    message : str
        "solved", or the simulation's message.

    Examples
    --------
    >>> import mbplanar
    >>> d = mbplanar.machine_dynamics(mbplanar.Engine(mbplanar.read_model("models/shaper.toml")))
    >>> round(d.inertia_first_group, 2), d.simulation.success            # kg·m² on the crank
    (147.14, True)
    """

    spec: DynamicsSpec
    reduced: Reduced
    phi: np.ndarray
    A_c: np.ndarray
    driving_moment: float
    inertia_first_group: float
    dT_I_max: float
    dT_I_min: float
    phi_dT_max: float
    phi_dT_min: float
    J_II: np.ndarray
    dJ_II: np.ndarray
    M_red: np.ndarray
    omega_mean: float
    resistance_work: float
    input_link_inertia: float
    A_total: np.ndarray
    T_II: np.ndarray
    dT_I: np.ndarray
    omega: np.ndarray
    epsilon: np.ndarray
    omega_min: float
    omega_max: float
    epsilon_min: float
    epsilon_max: float
    simulation: Simulation | None = None
    delta_simulated: float | None = None
    flywheel: Flywheel | None = None
    success: bool = True
    message: str = "solved"

    def __repr__(self) -> str:
        return (f"Dynamics({len(self.phi)} grid points, J_I={self.inertia_first_group:.6g} kg·m², "
                f"omega {self.omega_min:.6g} … {self.omega_max:.6g} rad/s, success={self.success})")

    def work_by_kind(self) -> dict:
        """Work (J) over the cycle of the loads of each kind (resistance, friction, gravity, ...)."""
        return {kind: float(_cumulative_trapezoid(m, self.phi)[-1]) for kind, m in self.reduced.by_kind().items()}

    def omega_at(self, dT_I):
        """ω from ΔT_I (the seeds' linearised relation)."""
        return _omega_at(dT_I, self.omega_mean, self.dT_I_max, self.dT_I_min, self.inertia_first_group)

    def epsilon_at(self, omega, M_red, J_II, dJ_II):
        """ε from the equation of motion with the first group's J_I."""
        return _epsilon_at(omega, M_red, J_II, dJ_II, self.inertia_first_group, self.driving_moment)

    def state_at(self, engine, phi) -> dict:
        """The values at input values `phi` (SI, (B,), any, taken modulo the cycle): J_II, dJ_II, M_red,
        A_c, dT_I, omega, epsilon (B,) each — computed at those positions, with the work integrated
        exactly as on the grid up to the grid node below and by the trapezoid rule from there."""
        phi = np.asarray(phi, float).reshape(-1)
        cyc = np.mod(phi, 2 * math.pi)
        red = reduce(engine, phi, self.omega_mean)
        k = np.clip(np.searchsorted(self.phi, cyc, side="right") - 1, 0, len(self.phi) - 2)
        M = red.M_red
        A_c = self.A_c[k] + (cyc - self.phi[k]) * (self.M_red[k] + M) / 2
        dT = _energy_change(A_c, self.driving_moment, cyc, red.J_II, self.omega_mean)
        omega = self.omega_at(dT)
        return {"phi": phi, "J_II": red.J_II, "dJ_II": red.dJ_II, "M_red": M, "A_c": A_c, "dT_I": dT,
                "omega": omega, "epsilon": self.epsilon_at(omega, M, red.J_II, red.dJ_II),
                "moments": red.moments}

    def to_frame(self):
        """A pandas DataFrame of the cycle, one row per grid position, with the columns of
        `mbplanar dynamics -o` (``phi[rad]``, ``J_II[kg*m2]``, ``omega[rad/s]``, ...). Needs pandas."""
        from ..model import view
        return view("frame", self)

    def _repr_html_(self) -> str:
        from ..model import view
        return view("html", self)


def cycle_grid(steps: int) -> np.ndarray:
    """φ = 0 … 2π in `steps` equal intervals, both ends included (N = steps + 1)."""
    if steps < 36:
        raise ModelError(f"machine dynamics needs at least 36 steps over the cycle, got {steps}")
    return np.linspace(0.0, 2 * math.pi, steps + 1)


def machine_dynamics(engine, spec: DynamicsSpec | None = None, steps: int = 3600,
                     simulate_motion: bool = True) -> Dynamics:
    """Machine dynamics by the energy–mass method over one cycle of the crank, and the flywheel it needs.

    Unless `simulate_motion` is False, also the exact steady-state motion with the flywheel found.

    Parameters
    ----------
    engine : Engine
        A one-input mechanism driven by a crank, with masses or loads.
    spec : DynamicsSpec, optional
        The coefficient of unevenness, mean speed, drive and flywheel data (default: the model's
        `[dynamics]` section).
    steps : int
        Positions over the cycle.
    simulate_motion : bool
        Also the true motion ω(φ) with the flywheel found (`Dynamics.simulation`).

    Returns
    -------
    Dynamics
        The reduced model, the driving moment, the flywheel and, with `simulate_motion`, the true motion.

    Raises
    ------
    ModelError
        No `[dynamics]` section and no `spec`, or a model the method does not apply to (several inputs,
        an input that does not turn).

    Examples
    --------
    >>> import mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/shaper.toml"))
    >>> d = mbplanar.machine_dynamics(engine)
    >>> round(float(d.driving_moment), 3), round(d.simulation.delta, 4)   # N·m; the true unevenness
    (102.058, 0.0481)
    """
    crank_input(engine.mech)  # (a machine of several inputs, or driven by a slider, says so first)
    spec = spec or read_dynamics(engine.mech)
    if spec is None:
        raise ModelError("the model has no [dynamics] section (at least delta = ...)", source=engine.mech.source)
    phi = cycle_grid(steps)
    red = reduce(engine, phi, spec.omega_mean)
    warn_idle_resistances(engine, red.motion)  # (over the cycle only: not at a few positions asked for)
    A_c = _cumulative_trapezoid(red.M_red, phi)
    M_dr = -A_c[-1] / (2 * math.pi) if spec.driving_moment is None else spec.driving_moment
    dT = _energy_change(A_c, M_dr, phi, red.J_II, spec.omega_mean)
    i_max, i_min = int(np.argmax(dT[:-1])), int(np.argmin(dT[:-1]))
    phi_max, dT_max = _parabola_peak(phi, dT, i_max)
    phi_min, dT_min = _parabola_peak(phi, dT, i_min)
    J_I = (dT_max - dT_min) / (spec.omega_mean ** 2 * spec.delta)
    if not J_I > 0:
        raise MotionError("the kinetic energy does not vary over the cycle "
                          "(no loads and no inertia?): nothing for a flywheel to even out", source=engine.mech.source)
    dyn = _dynamics(spec, red, phi, A_c, M_dr, J_I, dT_max, dT_min, phi_max, phi_min)
    dyn = replace(dyn, flywheel=flywheel_sizes(dyn))
    if simulate_motion:
        sim = simulate(dyn)
        dyn = replace(dyn, simulation=sim, delta_simulated=sim.delta, success=sim.success,
                      message="solved" if sim.success else sim.message)
    return dyn


def _dynamics(spec, red, phi, A_c, M_dr, J_I, dT_max, dT_min, phi_max, phi_min) -> Dynamics:
    """The record of the energy–mass method's results, every curve computed (no simulation, no flywheel)."""
    om_m = spec.omega_mean
    dT = _energy_change(A_c, M_dr, phi, red.J_II, om_m)
    omega = _omega_at(dT, om_m, dT_max, dT_min, J_I)
    epsilon = _epsilon_at(omega, red.M_red, red.J_II, red.dJ_II, J_I, M_dr)
    return Dynamics(spec, red, phi, A_c, M_dr, J_I, dT_max, dT_min, phi_max, phi_min, J_II=red.J_II,
                    dJ_II=red.dJ_II, M_red=red.M_red, omega_mean=om_m, resistance_work=float(A_c[-1]),
                    input_link_inertia=float(np.mean(red.J_input)), A_total=A_c + M_dr * phi,
                    T_II=red.J_II * om_m ** 2 / 2, dT_I=dT, omega=omega, epsilon=epsilon,
                    omega_min=_omega_at(dT_min, om_m, dT_max, dT_min, J_I),
                    omega_max=_omega_at(dT_max, om_m, dT_max, dT_min, J_I),
                    epsilon_min=float(np.min(epsilon)), epsilon_max=float(np.max(epsilon)))


def _omega_at(dT_I, omega_mean, dT_max, dT_min, J_I):
    """ω from ΔT_I (the seeds' linearised relation)."""
    return omega_mean + (dT_I - (dT_max + dT_min) / 2) / (J_I * omega_mean)


def _epsilon_at(omega, M_red, J_II, dJ_II, J_I, M_dr):
    """ε from the equation of motion with the first group's J_I."""
    J = J_I + J_II
    return (M_red + M_dr) / J - omega * omega * dJ_II / (2 * J)


def _energy_change(A_c, M_dr, phi, J_II, omega_mean):
    """ΔT_I = A_c + M_dr·φ − J_II·ω_m²/2: the work of loads and drive less the second group's energy."""
    return A_c + M_dr * phi - J_II * omega_mean ** 2 / 2


def _cumulative_trapezoid(y, x):
    out = np.zeros_like(y)
    out[1:] = np.cumsum((y[1:] + y[:-1]) * np.diff(x) / 2)
    return out


def _parabola_peak(x, y, i):
    """Vertex of the parabola through the grid points around index i of a periodic sampling whose
    last point repeats the first (the value of the extremum between grid nodes)."""
    n = len(x) - 1
    i0, i2 = (i - 1) % n, (i + 1) % n
    y0, y1, y2 = y[i0], y[i], y[i2]
    h = x[1] - x[0]
    den = y0 - 2 * y1 + y2
    if den == 0:
        return float(x[i]), float(y1)
    t = float(np.clip(0.5 * (y0 - y2) / den, -1.0, 1.0))
    return float(x[i] + t * h) % (2 * math.pi), float(y1 - 0.25 * (y0 - y2) * t)


# -- flywheel ---------------------------------------------------------------------------------------
def flywheel_sizes(dyn: Dynamics) -> Flywheel:
    """The flywheel's inertia and its size as a rim and as a disc (`Dynamics.flywheel`).

    J_fw (on the crank shaft) = J_I − the first group's own inertia (the input link's, and the gears' turned
    at a constant ratio to it, reduced to the crank) − shaft_inertia − motor_inertia·u², u = motor speed /
    crank speed; on the motor shaft (motor_rpm given) J_fw/u² (seed 000's J_m); on a link of the model
    (`link`) with u its speed ratio, from the gears.

    Parameters
    ----------
    dyn : Dynamics
        A machine dynamics (its J_I and its spec's flywheel data).

    Returns
    -------
    Flywheel
        `inertia` (kg·m², on its shaft), `inertia_on_crank_shaft`, `shaft`, `speed_ratio`, `density`,
        `needed` (False when the machine's own inertia is enough), and its sizes as a `rim` and as a
        `disc` (m, kg).

    Raises
    ------
    Nothing for a `Dynamics`.

    Examples
    --------
    The shaper's flywheel on its motor shaft, which turns 19.35 times as fast as the crank:

    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/shaper.toml"))
    >>> dyn = mbplanar.machine_dynamics(engine, steps=360, simulate_motion=False)     # a coarse cycle
    >>> from mbplanar.forces import flywheel_sizes
    >>> fw = flywheel_sizes(dyn)
    >>> fw.shaft, round(fw.speed_ratio, 4), round(fw.inertia, 4), round(fw.rim.outer_diameter, 3), round(fw.disc.mass, 2)
    ('motor', 19.3479, 0.3051, 0.345, 29.58)
    """
    fs = dyn.spec.flywheel
    crank_rpm = dyn.omega_mean * 60 / (2 * math.pi)
    u = 1.0 if fs.motor_rpm is None else fs.motor_rpm / crank_rpm
    shaft = "crank" if fs.motor_rpm is None else "motor"
    if fs.link is not None:
        u, shaft = _gear_ratio(dyn, fs.link), fs.link
    on_crank = dyn.inertia_first_group - dyn.input_link_inertia - fs.shaft_inertia - fs.motor_inertia * u * u
    J = on_crank / (u * u)
    out = Flywheel(J, on_crank, shaft, u, fs.density, J > 0)
    if J <= 0:
        return out
    scale = (J * RHO_STEEL / fs.density) ** 0.2
    d2 = _RIM[0] * scale
    d1, b = 0.8 * d2, 0.2 * d2
    d = _DISC[0] * scale
    return replace(out, rim=Rim(d2, d1, b, _RIM[1] * fs.density / RHO_STEEL * (d2 * d2 - d1 * d1) * b),
                   disc=Disc(d, 0.2 * d, _DISC[1] * fs.density / RHO_STEEL * d ** 3))


def _gear_ratio(dyn: Dynamics, link: str) -> float:
    """How many times faster than the crank the gears turn `link` (|ω_q|, constant over the cycle, else a
    `ModelError`)."""
    motion = dyn.reduced.motion
    wq = np.abs(motion.frames.w[:, motion.link_names.index(link)])
    if not wq.max() > 0 or np.ptp(wq) > 1e-9 * wq.max():
        raise ModelError(f"the flywheel's link '{link}' does not turn at a constant ratio to the crank "
                         f"(|ω_q| from {wq.min():.6g} to {wq.max():.6g}): put it on a shaft the gears drive",
                         source=motion.model.source, where="dynamics.flywheel")
    return float(np.mean(wq))


def summary(dyn: Dynamics, inp) -> list[tuple[str, object, str]]:
    """The results as (quantity, value, unit or note) rows, for the command line and the report;
    `inp` is the model's input (its name and unit label the positions).

    Parameters
    ----------
    dyn : Dynamics
        A machine dynamics.
    inp : Input
        The model's input (`Engine.inputs[0]`).

    Returns
    -------
    list of tuple
        (quantity, value, unit or note): δ, ω_m, the work per cycle and per kind of load, M_dr, ΔT_I's
        extremes, J_I, the ω and ε ranges, the simulated δ (when simulated) and the flywheel.

    Raises
    ------
    AttributeError
        `inp` is not an `Input`.

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/shaper.toml"))
    >>> dyn = mbplanar.machine_dynamics(engine, steps=360, simulate_motion=False)     # a coarse cycle
    >>> from mbplanar.forces import summary
    >>> for quantity, value, unit in summary(dyn, engine.inputs[0])[:5]:
    ...     print(f"{quantity}: {value:.6g} {unit}".rstrip())
    coefficient of speed fluctuation δ: 0.05
    mean speed ω_m: 7.64454 rad/s
    work of the loads per cycle A_c(2π): -641.221 J
      of which resistance: -471.222 J
      of which friction: -169.999 J
    """
    at = lambda phi: f"at {inp.name} = {inp.from_si(phi):.6g} {inp.unit}"  # noqa: E731
    rows = [("coefficient of speed fluctuation δ", dyn.spec.delta, ""),
            ("mean speed ω_m", dyn.omega_mean, "rad/s"),
            ("work of the loads per cycle A_c(2π)", dyn.resistance_work, "J")]
    rows += [(f"  of which {kind}", work, "J") for kind, work in dyn.work_by_kind().items()]
    rows += [("driving moment M_dr = −A_c(2π)/2π", dyn.driving_moment, "N·m"),
             ("ΔT_I max", dyn.dT_I_max, f"J {at(dyn.phi_dT_max)}"),
             ("ΔT_I min", dyn.dT_I_min, f"J {at(dyn.phi_dT_min)}"),
             ("first-group inertia J_I", dyn.inertia_first_group, "kg·m²"),
             ("ω min … max (energy–mass method)", f"{dyn.omega_min:.6g} … {dyn.omega_max:.6g}", "rad/s"),
             ("ε min … max", f"{dyn.epsilon_min:.6g} … {dyn.epsilon_max:.6g}", "rad/s²")]
    sim, fw = dyn.simulation, dyn.flywheel
    if sim is not None:
        rows += [("simulated δ (solve_ivp)", sim.delta, sim.message),
                 ("simulated ω min … max", f"{sim.omega_min:.6g} … {sim.omega_max:.6g}", "rad/s")]
    if not fw.needed:
        return rows + [("flywheel", "not needed", "the machine's own inertia is enough")]
    rim, disc = fw.rim, fw.disc
    return rows + [
        (f"flywheel on the {fw.shaft} shaft J", fw.inertia, f"kg·m² (speed ratio {fw.speed_ratio:.6g})"),
        ("  rim D2, D1, b", f"{rim.outer_diameter:.5g}, {rim.inner_diameter:.5g}, {rim.width:.5g}",
         f"m; mass {rim.mass:.5g} kg"),
        ("  disc D, b", f"{disc.diameter:.5g}, {disc.width:.5g}", f"m; mass {disc.mass:.5g} kg")]


def true_motion(engine, phi, cache: dict | None = None):
    """ω, ε (B,) of the input at `phi` (SI) from the machine dynamics, and the first group's J_I less the
    input link's own inertia (the constant inertia the force analysis adds on the input link); `cache`
    (a dict) keeps the machine dynamics for later calls (the chunks of a streamed sweep).

    Parameters
    ----------
    engine : Engine
        A crank-driven mechanism with `[dynamics]`.
    phi : array_like, shape (B,)
        The crank's values (SI).
    cache : dict, optional
        Holds the `Dynamics` under "dynamics": made (3600 steps, not simulated) on the first call, read
        on the next ones; put one there to choose it.

    Returns
    -------
    omega, epsilon : ndarray, shape (B,)
        The crank's speed and acceleration (rad/s, rad/s²) by the energy–mass method.
    inertia : float
        J_I less the input link's own inertia (kg·m²).

    Raises
    ------
    ModelError
        A model without `[dynamics]`.

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/shaper.toml"))
    >>> dyn = mbplanar.machine_dynamics(engine, steps=360, simulate_motion=False)     # a coarse cycle
    >>> from mbplanar.forces import true_motion
    >>> omega, epsilon, inertia = true_motion(engine, np.radians([0.0, 90.0]), cache={"dynamics": dyn})
    >>> omega.round(4), epsilon.round(4), round(inertia, 2)
    (array([7.811, 7.743]), array([ 0.6936, -0.9986]), 147.14)
    """
    cache = {} if cache is None else cache
    dyn = cache.get("dynamics") or cache.setdefault("dynamics", machine_dynamics(engine, simulate_motion=False))
    state = dyn.state_at(engine, phi)
    return state["omega"], state["epsilon"], dyn.inertia_first_group - dyn.input_link_inertia


# -- the exact equation of motion -------------------------------------------------------------------
def _cycle_equation(dyn: Dynamics, J_I: float):
    """The equation of motion with φ as the independent variable: rhs(φ, [ω, t]) = [dω/dφ, dt/dφ],
    accel(ω, J_II, J_II', M_red) = φ̈, and the terminal event of ω falling to 1e-6·ω_m."""
    spec, phi = dyn.spec, dyn.phi
    M_dr, slope, om_m = dyn.driving_moment, spec.motor_slope, spec.omega_mean
    period = 2 * math.pi
    # J_II, J_II', M_red by linear interpolation on the uniform grid, in plain floats (the right-hand
    # side is called tens of thousands of times)
    h, n = float(phi[1] - phi[0]), len(phi) - 1
    table = [a.tolist() for a in (dyn.J_II, dyn.dJ_II, dyn.M_red)]

    def accel(om, j, dj, m):
        """φ̈ from the equation of motion, for ω and the reduced quantities at φ."""
        return (M_dr - slope * (om - om_m) + m - 0.5 * dj * om * om) / (J_I + j)

    def rhs(x, y):
        om = float(y[0])
        s = (x % period) / h
        i = min(int(s), n - 1)
        t = s - i
        j, dj, m = (a[i] + t * (a[i + 1] - a[i]) for a in table)
        return [accel(om, j, dj, m) / om, 1.0 / om]

    def stalled(x, y):
        return y[0] - 1e-6 * om_m
    stalled.terminal = True
    return rhs, accel, stalled


def stall_ahead(dyn: Dynamics, J_I: float, phi0: float, omega0: float) -> tuple[float, float] | None:
    """Where (φ, rad) and when (s) the machine of `dyn` with the first-group inertia `J_I` (kg·m², the
    input link's own included), started at φ0 with the speed ω0 > 0, stalls within its first cycle (its
    speed falls to zero: the drive cannot carry it through the loads); None when it passes the cycle.

    Parameters
    ----------
    dyn : Dynamics
        The machine (its reduced model and driving moment).
    J_I : float
        The first group's inertia on the crank (kg·m²).
    phi0 : float
        The start angle (rad).
    omega0 : float
        The start speed (rad/s), > 0.

    Returns
    -------
    tuple of float or None
        (φ, t) where and when it stalls; None when it runs through the cycle.

    Raises
    ------
    ZeroDivisionError
        `omega0` = 0 (it starts stalled).

    Examples
    --------
    The shaper with its flywheel runs through; without (J_I = 1 kg·m²) from half its speed it stops
    within the turn:

    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/shaper.toml"))
    >>> dyn = mbplanar.machine_dynamics(engine, steps=360, simulate_motion=False)     # a coarse cycle
    >>> from mbplanar.forces import stall_ahead
    >>> stall_ahead(dyn, dyn.inertia_first_group, 0.0, dyn.omega_mean) is None
    True
    >>> tuple(round(x, 3) for x in stall_ahead(dyn, 1.0, 0.0, 0.5))
    (1.505, 0.333)
    """
    from scipy.integrate import solve_ivp

    rhs, _, stalled = _cycle_equation(dyn, J_I)
    sol = solve_ivp(rhs, (phi0, phi0 + 2 * math.pi), [omega0, 0.0], rtol=1e-8,
                    atol=1e-12 * dyn.spec.omega_mean, method="RK45", events=stalled)
    if sol.status == 1 and len(sol.t_events[0]):
        return float(sol.t_events[0][0]), float(sol.y_events[0][0][1])
    return None


def simulate(dyn: Dynamics, rtol: float = 1e-10, max_iter: int = 60) -> Simulation:
    """Integrate (J_I + J_II)·φ̈ + ½·J_II′·φ̇² = M_dr(φ̇) + M_red(φ) over the cycle to its periodic
    steady state (scipy.integrate.solve_ivp, φ as the independent variable, ω(φ) as the state, with
    J_II, J_II′ and M_red interpolated periodically from the cycle grid).

    With a constant driving moment every start speed gives a periodic motion; the one whose mean speed
    (ω_max + ω_min)/2 is ω_m is taken. With a motor characteristic (slope > 0) the periodic motion is
    unique: ω(2π) = ω(0). Both conditions are met by a secant iteration on ω(0).

    Parameters
    ----------
    dyn : Dynamics
        The machine, with its first-group inertia J_I (the flywheel found).
    rtol : float
        solve_ivp's relative tolerance.
    max_iter : int
        The most secant steps.

    Returns
    -------
    Simulation
        ω, ε over the cycle grid, δ, the speed range, the period; `success` False (with the reason in
        `message`) when the iteration did not converge.

    Raises
    ------
    MotionError
        The machine stalls: the drive cannot carry it through the cycle.

    Examples
    --------
    The shaper's true δ with the flywheel sized for δ = 0.05 by the energy–mass method:

    >>> import numpy as np, mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/shaper.toml"))
    >>> dyn = mbplanar.machine_dynamics(engine, steps=360, simulate_motion=False)     # a coarse cycle
    >>> from mbplanar.forces import simulate
    >>> sim = simulate(dyn, rtol=1e-6)
    >>> sim.message, round(sim.delta, 4), round(sim.omega_min, 3), round(sim.omega_max, 3)
    ('periodic steady state', 0.0481, 7.461, 7.828)
    """
    from scipy.integrate import solve_ivp

    phi, spec = dyn.phi, dyn.spec
    J_II, dJ, M, om_m = dyn.J_II, dyn.dJ_II, dyn.M_red, spec.omega_mean
    period = 2 * math.pi
    rhs, accel, stalled = _cycle_equation(dyn, dyn.inertia_first_group)

    def cycle(om0):
        """ω over the grid, the period, and the error of the periodicity condition, from ω(0) = om0."""
        sol = solve_ivp(rhs, (0.0, period), [om0, 0.0], t_eval=phi, rtol=rtol, atol=1e-12 * om_m,
                        method="RK45", events=stalled)
        if sol.status != 0:
            raise MotionError("the machine stalls: the driving moment cannot carry it through the cycle "
                              f"(ω falls to 0 near φ = {math.degrees(sol.t[-1]):.4g}°)")
        om = sol.y[0]
        error = om[-1] - om0 if spec.motor_slope > 0 else (om.max() + om.min()) / 2 - om_m
        return om, sol.y[1][-1], error

    x0 = float(dyn.omega_at(dyn.dT_I[0]))
    x1 = x0 * (1 + 1e-3)
    f0 = cycle(x0)[2]
    om, T, f1 = cycle(x1)
    success = False
    for _ in range(max_iter):
        success = bool(abs(f1) < 1e-7 * om_m)
        if success or f1 == f0:
            break
        x0, x1, f0 = x1, x1 - f1 * (x1 - x0) / (f1 - f0), f1
        om, T, f1 = cycle(x1)
    message = "periodic steady state" if success else "the periodic motion was not found"
    eps = accel(om, J_II, dJ, M)
    lo, hi = float(om.min()), float(om.max())
    return Simulation(om, eps, (hi - lo) / ((hi + lo) / 2), lo, hi, period / T, T, success, message)
