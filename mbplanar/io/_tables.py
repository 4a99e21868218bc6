"""Results as tables: the columns of the CSV files the command line writes (`mbplanar sweep`, `mbplanar dynamics
-o`), named ``quantity[unit]``, shared by the command line and `to_frame()`."""

from __future__ import annotations

import numpy as np

__all__ = ["sweep_table", "forces_table", "forces_columns", "dynamics_table"]


def sweep_table(engine, motion, angle_unit):
    """Header (quantity[unit]) and columns of a sweep, as `mbplanar sweep` writes them: the inputs, every
    moving link's angle, ω, ε, every point's x, y, velocity and acceleration, every joint's value, rate
    and acceleration, then the transmission and pressure angles.

    Parameters
    ----------
    engine : Engine
        The mechanism.
    motion : Motion
        Its positions, with rates (batch B).
    angle_unit : str
        "deg" or "rad": the unit of the angles (links, revolute joints, transmission and pressure angles);
        the inputs are in their model units, rates in SI.

    Returns
    -------
    header : list of str
        The columns' names, "quantity[unit]".
    columns : ndarray, shape (B, k)
        One row per position.

    Raises
    ------
    TypeError
        A motion solved without rates.

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> from mbplanar.io import sweep_table
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/slider_crank.toml"))
    >>> header, columns = sweep_table(engine, mbplanar.analyse(engine, np.radians([0.0, 90.0])), "deg")
    >>> header[-1], columns[:, -1].round(4)
    ('pressure.Bp.A-B[deg]', array([ 0.    , 19.4712]))
    """
    to_angle = (lambda x: np.degrees(x)) if angle_unit == "deg" else (lambda x: x)
    au = "deg" if angle_unit == "deg" else "rad"
    header = [f"{inp.name}[{inp.unit}]" for inp in engine.inputs]  # every input, in its own unit
    cols = [inp.from_si(motion.phi[:, k]) for k, inp in enumerate(engine.inputs)]
    for k, name in enumerate(motion.link_names[1:], start=1):
        header += [f"{name}.angle[{au}]", f"{name}.omega[rad/s]", f"{name}.epsilon[rad/s^2]"]
        cols += [to_angle(motion.angle[:, k]), motion.w[:, k], motion.e[:, k]]
    for k, name in enumerate(motion.point_names):
        header += [f"{name}.{q}" for q in ("x[m]", "y[m]", "vx[m/s]", "vy[m/s]", "ax[m/s^2]", "ay[m/s^2]")]
        cols += [motion.xy[:, k, 0], motion.xy[:, k, 1], motion.v[:, k, 0], motion.v[:, k, 1],
                 motion.a[:, k, 0], motion.a[:, k, 1]]
    for k, name in enumerate(motion.joint_names):
        if engine.mech.joints[name].kind == "R":
            header += [f"{name}.value[{au}]", f"{name}.rate[rad/s]", f"{name}.accel[rad/s^2]"]
            cols += [to_angle(motion.value[:, k]), motion.rate[:, k], motion.accel[:, k]]
        else:
            header += [f"{name}.value[m]", f"{name}.rate[m/s]", f"{name}.accel[m/s^2]"]
            cols += [motion.value[:, k], motion.rate[:, k], motion.accel[:, k]]
    from ..analysis import contact_angles, pressure_angles, transmission_angles
    labels, angles = transmission_angles(engine, motion)          # at J between J→P and J→Q: P-J-Q
    header += [f"transmission.{p}-{j}-{q}[{au}]" for p, j, q in labels]
    cols += [to_angle(angles[:, k]) for k in range(len(labels))]
    labels, angles = pressure_angles(engine, motion)              # slider S driven by rod A-B: S.A-B
    header += [f"pressure.{s}.{a}-{b}[{au}]" if a != b else f"pressure.{s}.normal-{a}[{au}]" for a, b, s in labels]
    cols += [to_angle(angles[:, k]) for k in range(len(labels))]
    if engine.mech.higher:
        names, angles = contact_angles(engine, motion)            # a cam's or a slot's contact C
        header += [f"pressure.{n}.contact[{au}]" for n in names]
        cols += [to_angle(angles[:, k]) for k in range(len(names))]
    return header, np.column_stack(cols) if cols else np.zeros((0, 0))


def forces_table(engine, motion, input_inertia=0.0):
    """Header, columns (B, k) and a failure message (or None) of the reactions and balancing loads:
    `kinetostatics` solved and written as `forces_columns` writes it (``mbplanar forces --sweep``).

    Parameters
    ----------
    engine : Engine
        The mechanism.
    motion : Motion
        Its positions, with rates (batch B).
    input_inertia : float or array_like
        The input links' extra moment of inertia (kg·m²), per input.

    Returns
    -------
    header : list of str
        The columns' names, "quantity[unit]".
    columns : ndarray, shape (B, k)
        One row per position.
    message : str or None
        Why a position could not be solved (a singular position), or None.

    Raises
    ------
    ModelError
        A negative or non-finite `input_inertia`.

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> from mbplanar.io import forces_table
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/heavy_fourbar.toml"))
    >>> header, columns, message = forces_table(engine, mbplanar.analyse(engine, np.radians([0.0, 90.0])))
    >>> header[-2:], columns[:, -2].round(6), message
    (['O.balancing[N*m]', 'virtual_power_residual'], array([-17.508396,   4.683435]), None)
    """
    from ..forces import kinetostatics
    result = kinetostatics(engine, motion, input_inertia or 0.0)
    header, cols = forces_columns(engine, result)
    return header, cols, (None if result.success else result.message)


def forces_columns(engine, result):
    """Header and columns (B, k) of a `Kinetostatics`: reactions, balancing loads, virtual-power residual.

    Parameters
    ----------
    engine : Engine
        The mechanism.
    result : Kinetostatics
        Its kinetostatics over B positions.

    Returns
    -------
    header : list of str
        Per pair "J.fx[N]", "J.fy[N]" (and a prismatic pair's "J.moment[N*m]", a higher pair's
        "J.contact[N]"), per input "J.balancing[N*m]" (or [N]), and "virtual_power_residual".
    columns : ndarray, shape (B, k)
        One row per position.

    Raises
    ------
    KeyError
        A `result` of another engine.

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> from mbplanar.io import forces_columns
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/heavy_fourbar.toml"))
    >>> result = mbplanar.kinetostatics(engine, mbplanar.analyse(engine, np.radians([0.0, 90.0])))
    >>> header, columns = forces_columns(engine, result)
    >>> header[:2], header[-2:], columns.shape
    (['O.fx[N]', 'O.fy[N]'], ['O.balancing[N*m]', 'virtual_power_residual'], (2, 10))
    """
    header, cols = [], []
    for name, r in result.reactions.items():
        header += [f"{name}.fx[N]", f"{name}.fy[N]"]
        cols += [r.fx, r.fy]
        if name in result.contact_forces:
            header.append(f"{name}.contact[N]")
            cols.append(result.contact_forces[name])
        elif engine.mech.joints[name].kind == "P":
            header.append(f"{name}.moment[N*m]")
            cols.append(r.moment)
    for name, q in result.balancing.items():
        unit = "N*m" if engine.mech.joints[name].kind == "R" else "N"
        header.append(f"{name}.balancing[{unit}]")
        cols.append(q)
    header.append("virtual_power_residual")
    cols.append(result.virtual_power_residual)
    return header, np.column_stack(cols)


def dynamics_table(dyn):
    """Header and columns (N, k) of the cycle table: φ, J_II, dJ_II, M_red per load and in total, A_c,
    A_total, T_II, ΔT_I, ω, ε (energy–mass method) and the simulated ω, ε (``mbplanar dynamics -o``).

    Parameters
    ----------
    dyn : Dynamics
        A machine dynamics (`machine_dynamics`) over N steps of the cycle.

    Returns
    -------
    header : list of str
        The columns' names, "quantity[unit]", SI.
    columns : ndarray, shape (N, k)
        One row per step.

    Raises
    ------
    AttributeError
        `dyn` is not a `Dynamics`.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.io import dynamics_table
    >>> dyn = mbplanar.machine_dynamics(mbplanar.Engine(mbplanar.read_model("models/shaper.toml")), steps=360,
    ...                                 simulate_motion=False)
    >>> header, columns = dynamics_table(dyn)
    >>> header[:3], header[-2:], columns.shape
    (['phi[rad]', 'J_II[kg*m2]', 'dJ_II[kg*m2]'], ['omega[rad/s]', 'epsilon[rad/s2]'], (361, 14))
    """
    red = dyn.reduced
    header = ["phi[rad]", "J_II[kg*m2]", "dJ_II[kg*m2]"] + [f"M_red.{n}[N*m]" for n in red.moments] + \
        ["M_red[N*m]", "A_c[J]", "A_total[J]", "T_II[J]", "dT_I[J]", "omega[rad/s]", "epsilon[rad/s2]"]
    cols = [dyn.phi, dyn.J_II, dyn.dJ_II, *red.moments.values(), dyn.M_red, dyn.A_c, dyn.A_total,
            dyn.T_II, dyn.dT_I, dyn.omega, dyn.epsilon]
    if dyn.simulation is not None:
        header += ["omega_sim[rad/s]", "epsilon_sim[rad/s2]"]
        cols += [dyn.simulation.omega, dyn.simulation.epsilon]
    return header, np.column_stack(cols)
