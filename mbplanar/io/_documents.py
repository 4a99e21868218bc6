"""Documents of the motion under given forces (`simulate_document`, `simulate_table`) and of a balancing
(`balance_document`): JSON-ready dicts in SI, as `mbplanar simulate` and `mbplanar balance` print them."""

from __future__ import annotations

import math

import numpy as np

from ._export import plain

__all__ = ["simulate_document", "simulate_table", "balance_document"]


def simulate_document(engine, tr) -> dict:
    """The simulated motion as a JSON-ready document (SI).

    Per time: the inputs' φ, ω, ε, every link's angle, ω, ε, every joint's value, rate, acceleration and
    reaction (on `on` from `from`), the balancing load at each input (it equals the drive), the
    energies; and the solver's settings and statistics.

    Parameters
    ----------
    engine : Engine
        The model's engine.
    tr : Trajectory
        The motion, from `mbplanar.forces.simulate_motion`.

    Returns
    -------
    dict
        Keys ``model``, ``t``, ``solver``, ``inputs``, ``links``, ``joints``, ``energy`` (docs/forces.md);
        arrays as lists of floats.

    Raises
    ------
    AttributeError
        `tr` is not a trajectory of the simulation.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.forces import read_simulate, simulate_motion
    >>> from mbplanar.io import simulate_document
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/squeezer.toml"))
    >>> tr = simulate_motion(engine, read_simulate(engine.mech, t=0.01, steps=4))
    >>> doc = simulate_document(engine, tr)
    >>> sorted(doc), len(doc["t"]), doc["solver"]["success"]
    (['energy', 'inputs', 'joints', 'links', 'model', 'solver', 't'], 5, True)
    """
    m, ks, spec = tr.motion, tr.kinetostatics, tr.spec
    doc = {"model": engine.mech.name, "t": tr.t,
           "solver": {"method": spec.method, "rtol": spec.rtol, "atol": spec.atol, "evaluations": tr.nfev,
                      "success": tr.success, "message": tr.message},
           "inputs": {inp.name: {"joint": inp.joint, "phi": tr.phi[:, k], "omega": tr.omega[:, k],
                                 "epsilon": tr.epsilon[:, k], "drive": tr.drive[:, k],
                                 "balancing": ks.balancing[inp.joint]}
                      for k, inp in enumerate(engine.inputs)},
           "links": {name: {"angle": m.angle[:, k], "omega": m.w[:, k], "epsilon": m.e[:, k]}
                     for k, name in enumerate(m.link_names) if name != engine.mech.ground},
           "joints": {}, "energy": tr.energy}
    for k, name in enumerate(m.joint_names):
        r = ks.reactions[name]
        doc["joints"][name] = {"value": m.value[:, k], "rate": m.rate[:, k], "accel": m.accel[:, k],
                               "on": r.on, "from": r.source, "fx": r.fx, "fy": r.fy, "moment": r.moment}
    return plain(doc)


def simulate_table(doc, engine=None) -> tuple[list, np.ndarray]:
    """The simulated motion as a CSV table (SI).

    Parameters
    ----------
    doc : dict
        A `simulate_document`.
    engine : Engine, optional
        The model's engine: its sliders' columns get lengths (m, m/s, N) instead of angles.

    Returns
    -------
    header : list of str
        Each column's name with its unit in brackets.
    columns : numpy.ndarray
        The values (N, k), one row per time.

    Raises
    ------
    KeyError
        `doc` is not a `simulate_document`.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.forces import read_simulate, simulate_motion
    >>> from mbplanar.io import simulate_document, simulate_table
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/squeezer.toml"))
    >>> doc = simulate_document(engine, simulate_motion(engine, read_simulate(engine.mech, t=0.01, steps=4)))
    >>> header, columns = simulate_table(doc, engine)
    >>> header[:2], columns.shape[0]
    (['t[s]', 'beta[rad]'], 5)
    """
    prismatic = {} if engine is None else {n: j.kind == "P" for n, j in engine.mech.joints.items()}
    header, cols = ["t[s]"], [doc["t"]]
    for name, d in doc["inputs"].items():
        p = prismatic.get(d["joint"], False)
        units = ("m", "m/s", "m/s^2", "N") if p else ("rad", "rad/s", "rad/s2", "N*m")
        header += [f"{name}[{units[0]}]", f"{name}.omega[{units[1]}]", f"{name}.epsilon[{units[2]}]",
                   f"{name}.drive[{units[3]}]"]
        cols += [d["phi"], d["omega"], d["epsilon"], d["drive"]]
    for name, d in doc["links"].items():
        header += [f"angle.{name}[rad]", f"omega.{name}[rad/s]", f"epsilon.{name}[rad/s2]"]
        cols += [d["angle"], d["omega"], d["epsilon"]]
    for name, d in doc["joints"].items():
        header += [f"{name}.value[{'m' if prismatic.get(name) else 'rad'}]", f"F{name}.x[N]", f"F{name}.y[N]"]
        cols += [d["value"], d["fx"], d["fy"]]
    header += ["kinetic[J]", "potential[J]", "drive_work[J]"]
    cols += [doc["energy"]["kinetic"], doc["energy"]["potential"], doc["energy"]["drive_work"]]
    return header, np.column_stack([np.asarray(c, float) for c in cols])


def balance_document(engine, bal, count: int = 360) -> dict:
    """Counterweights and what they change, as a JSON-ready document (SI).

    Before and after, at the model's speed over a turn: the RMS and largest shaking force and the largest
    shaking moment (the resultant of the links' inertia forces, `inertia_shaking`: the counterweights'
    static weight is no shaking), the largest reaction in every pair, the largest balancing moment (or
    force).

    Parameters
    ----------
    engine : Engine
        The model's engine, without the counterweights.
    bal : Balancing
        The counterweights, from `mbplanar.forces.balance`.
    count : int
        Positions over the turn.

    Returns
    -------
    dict
        Keys ``model``, ``counterweights``, ``rms_unit_speed``, ``before``, ``after`` (docs/forces.md).

    Raises
    ------
    MotionError
        The balanced mechanism cannot make the turn.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.forces import balance
    >>> from mbplanar.io import balance_document
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar_loaded.toml"))
    >>> doc = balance_document(engine, balance(engine, ["1", "3"]), count=36)
    >>> doc["after"]["shaking_force_max"] < 1e-6 * doc["before"]["shaking_force_max"]
    True
    """
    from ..engine import Engine
    from ..forces import inertia_shaking, kinetostatics
    from ..kinematics import analyse
    doc = {"model": engine.mech.name, "counterweights": [vars(cw) for cw in bal.counterweights],
           "rms_unit_speed": {"before": bal.rms_before, "after": bal.rms_after}}
    phi = engine.phi_drawn[0] + np.linspace(0.0, 2 * math.pi, count, endpoint=False)
    balanced = Engine(bal.mechanism, backend=engine.backend, threads=engine.threads)
    for when, eng in (("before", engine), ("after", balanced)):
        motion = analyse(eng, phi)
        ks = kinetostatics(eng, motion)
        sh = inertia_shaking(eng, motion)
        doc[when] = {"shaking_force_max": float(np.max(sh.magnitude)),
                     "shaking_force_rms": float(np.sqrt(np.mean(sh.magnitude ** 2))),
                     "shaking_moment_max": float(np.max(np.abs(sh.moment))),
                     "reaction_max": {n: float(np.max(r.magnitude)) for n, r in ks.reactions.items()},
                     "balancing_max": {n: float(np.max(np.abs(q))) for n, q in ks.balancing.items()}}
    return plain(doc)
