"""Results as data for people and files: JSON-ready documents, CSV tables, shared by the command line
and the report.

`document(result)` and `table(result)` pick the builder for the result's type (an `Engine`: the model;
a `Motion`: one position, or the sweep table; a `Kinetostatics`; a `Dynamics`; a `CheckReport`; an
`Accuracy`, which builds its own with `Accuracy.document` and `Accuracy.table`); the
builders are public too, for their options. Documents hold plain floats (non-finite → None), ready for
`json.dumps`; tables are (header, columns (B, k)), written by `write_csv`.

The builders are found by the module and name of the result's class (`_builder_of`), not by importing the
classes: a command that prints one kind of result (``mbplanar solve``) then loads neither the forces nor
the analysis code, and this module imports nothing from the layers below it at its own import.
"""

from __future__ import annotations

import math
import sys
from dataclasses import asdict
from typing import TYPE_CHECKING

import numpy as np

from ._tables import dynamics_table, forces_columns, sweep_table
from ._units import (convert_check, convert_dynamics, convert_forces, convert_info, convert_solution,
                     convert_table, display_units)

if TYPE_CHECKING:
    from ..forces import Kinetostatics
    from ..kinematics import Motion, Position

__all__ = ["document", "table", "engine_for", "plain", "write_csv", "info_document", "solve_document",
           "partials_document",
           "forces_document", "dynamics_document"]

#: where each result type a builder takes is defined: "module:name" (the module that defines the class,
#: so that an instance implies that module is loaded)
ENGINE = "mbplanar.engine._solver:Engine"
MOTION = "mbplanar.kinematics._motion:Motion"
POSITION = "mbplanar.kinematics._single:Position"
KINETOSTATICS = "mbplanar.forces._kinetostatics:Kinetostatics"
DYNAMICS = "mbplanar.forces._dynamics:Dynamics"
CHECK_REPORT = "mbplanar.analysis._check:CheckReport"
ACCURACY = "mbplanar.accuracy.run:Accuracy"


def is_a(obj, home: str) -> bool:
    """isinstance(obj, the class at `home` ("module:name")), without importing its module: an instance
    of a class exists only once the module defining it is loaded."""
    module, name = home.split(":")
    loaded = sys.modules.get(module)
    return loaded is not None and isinstance(obj, getattr(loaded, name))


def _builder_of(result, builders: dict, what: str):
    """The builder of `builders` (home → function) whose class `result` is an instance of."""
    for home, build in builders.items():
        if is_a(result, home):
            return build
    raise TypeError(f"no {what} for a {type(result).__name__}")


def document(result, *args, **options) -> dict:
    """The JSON-ready document of a result (the CLI's ``--json``); `options` go to its builder, and
    ``units="si"`` or ``"model"`` converts it as ``--units`` does (adding its "units" object).

    Parameters
    ----------
    result : Engine, Motion, Position, Kinetostatics, Dynamics, CheckReport or Accuracy
        What to write: an engine gives the model (`info_document`), a motion one of its positions
        (`solve_document`), a kinetostatic result one position (`forces_document`), a `Dynamics` the
        cycle (`dynamics_document`), a `CheckReport` its findings.
    *args
        The builder's options by position (a motion's `row`, then `values`).
    options
        The builder's options by name: ``row=`` (the position of a batch), ``values=`` (the inputs as
        asked for, model units), ``engine=`` (else one is made from the model the result holds; a
        `Dynamics` and a `CheckReport` in units need it), ``at=`` (a `Dynamics`' input values, SI),
        ``units=``.

    Returns
    -------
    dict
        Plain floats, lists and dicts (non-finite values None), ready for `json.dumps`.

    Raises
    ------
    TypeError
        A result of another type, or a `Dynamics` without ``engine=``.
    ValueError
        ``units=`` neither "si" nor "model".

    Examples
    --------
    >>> import json, numpy as np, mbplanar
    >>> from mbplanar.io import document
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> doc = document(mbplanar.analyse(engine, np.radians([30.0])), values=[30.0])
    >>> doc["input"]["value"], {k: round(v, 6) for k, v in doc["points"]["B"].items()}
    (30.0, {'x': 0.310403, 'y': 0.249783, 'vx': 0.028363, 'vy': -0.001181, 'ax': -0.197573, 'ay': 0.005002})
    >>> document(engine)["count"]["chebyshev"], len(json.dumps(doc)) > 1000
    (1, True)
    """
    return _builder_of(result, DOCUMENTS, "document")(result, *args, **options)


def _in_units(convert, engine, doc: dict, units: str | None) -> dict:
    return doc if units is None else convert(engine, doc, display_units(engine.mech, units))


def _engine_document(result, units: str | None = None) -> dict:
    return _in_units(convert_info, result, info_document(result), units)


def engine_for(result, engine=None):
    """The engine a result's documents, tables and pictures are made with: `engine` when given, else one
    made from the model the result holds (`Motion.model`: a record holds no engine).

    Parameters
    ----------
    result : Motion, Position, Kinetostatics or another result
        A result holding its model (`model`, or `motion.model`).
    engine : Engine or None
        The engine the result was made with, returned as it is when given.

    Returns
    -------
    Engine
        `engine`, or a new engine of the result's model (the model compiled again: pass the engine
        where you have it).

    Raises
    ------
    TypeError
        No `engine` and a result without its model.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.io import engine_for
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> motion = mbplanar.analyse(engine, [0.5])
    >>> engine_for(motion, engine) is engine, engine_for(motion).mech.name
    (True, 'fourbar')
    """
    if engine is not None:
        return engine
    model = getattr(result, "model", None)
    if model is None and hasattr(result, "motion"):
        model = result.motion.model
    if model is None:
        raise TypeError(f"a {type(result).__name__} without its model needs its engine: engine=...")
    from ..engine import Engine
    return Engine(model)


def _motion_document(result, row: int = 0, values=None, units: str | None = None, engine=None) -> dict:
    engine = engine_for(result, engine)
    return _in_units(convert_solution, engine, solve_document(engine, result, row, values), units)


def _position_document(result, values=None, units: str | None = None, engine=None) -> dict:
    engine = engine_for(result, engine)
    return _in_units(convert_solution, engine, solve_document(engine, result, 0, values), units)


def _forces_document(result, row: int = 0, values=None, units: str | None = None, engine=None) -> dict:
    engine = engine_for(result, engine)
    return _in_units(convert_forces, engine, forces_document(engine, result.motion, result, row, values), units)


def _dynamics_document(result, engine=None, at=None, units: str | None = None) -> dict:
    if engine is None:
        raise TypeError("the document of a Dynamics needs its engine: document(dyn, engine=engine)")
    return _in_units(convert_dynamics, engine, dynamics_document(engine, result, at), units)


def _check_document(result, engine=None, units: str | None = None) -> dict:
    doc = plain(result.as_dict())
    if units is not None and engine is None:
        raise TypeError("a check document in units needs its engine: document(report, engine=engine, units=...)")
    return _in_units(convert_check, engine, doc, units)


def _accuracy_document(result, units: str | None = None) -> dict:
    return result.as_dict() if units is None else result.document(units)


def _accuracy_table(result, units: str | None = None):
    return result.table(units)


#: the builder of `document` for each result type (home → function)
DOCUMENTS = {ENGINE: _engine_document, MOTION: _motion_document, POSITION: _position_document,
             KINETOSTATICS: _forces_document, DYNAMICS: _dynamics_document, CHECK_REPORT: _check_document,
             ACCURACY: _accuracy_document}


def table(result, *args, **options):
    """(header, columns (B, k)) of a result over its batch (the CLI's CSV); `options` go to its builder,
    and ``units=`` converts the columns as ``--units`` does (`mech`: the model, for a Dynamics).

    Parameters
    ----------
    result : Motion, Kinetostatics, Dynamics or Accuracy
        A motion gives the sweep's columns (`sweep_table`), a kinetostatic result the reactions and
        balancing loads (`forces_columns`), a `Dynamics` the cycle (`dynamics_table`).
    *args
        The builder's options by position (a motion's `angle_unit`).
    options
        The builder's options by name: ``angle_unit=`` ("deg" or "rad", a motion's angles), ``engine=``
        (else one is made from the model the result holds), ``mech=`` (a `Dynamics` in units), ``units=``.

    Returns
    -------
    header : list of str
        The columns' names, "quantity[unit]".
    columns : ndarray, shape (B, k)
        One row per position (per step of a cycle).

    Raises
    ------
    TypeError
        A result of another type, or a `Dynamics` in units without ``mech=``.
    ValueError
        ``units=`` neither "si" nor "model".

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> from mbplanar.io import table
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> header, columns = table(mbplanar.analyse(engine, np.radians([0.0, 30.0, 60.0])), engine=engine)
    >>> header[:4], columns.shape, columns[:, 0].round(9)
    (['phi[deg]', '1.angle[deg]', '1.omega[rad/s]', '1.epsilon[rad/s^2]'], (3, 53), array([ 0., 30., 60.]))
    """
    return _builder_of(result, TABLES, "table")(result, *args, **options)


def _table_in_units(header, cols, mech, units):
    return (header, cols) if units is None else convert_table(header, cols, display_units(mech, units))


def _motion_table(result, angle_unit: str = "deg", units: str | None = None, engine=None):
    engine = engine_for(result, engine)
    return _table_in_units(*sweep_table(engine, result, angle_unit), engine.mech, units)


def _forces_table(result, units: str | None = None, engine=None):
    engine = engine_for(result, engine)
    return _table_in_units(*forces_columns(engine, result), engine.mech, units)


def _dynamics_table(result, mech=None, units: str | None = None):
    if units is not None and mech is None:
        raise TypeError("a dynamics table in units needs its model: table(dyn, mech=engine.mech, units=...)")
    return _table_in_units(*dynamics_table(result), mech, units)


#: the builder of `table` for each result type (home → function)
TABLES = {MOTION: _motion_table, KINETOSTATICS: _forces_table, DYNAMICS: _dynamics_table,
          ACCURACY: _accuracy_table}


def _finite(x):
    x = float(x)
    return x if math.isfinite(x) else None


def plain(obj):
    """A value made ready for JSON: numpy scalars and arrays as floats, ints and lists, non-finite
    floats as None, through dicts, lists and tuples (tuples become lists).

    Parameters
    ----------
    obj : object
        A number, an array, or dicts and lists of them; anything else is returned as it is.

    Returns
    -------
    object
        The same structure with plain Python numbers.

    Raises
    ------
    Nothing: what it does not know it leaves alone (`json.dumps` then says what it cannot write).

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.io import plain
    >>> plain({"a": np.float64(1.5), "b": np.array([np.nan, 2.0]), "c": (np.int64(3), np.inf)})
    {'a': 1.5, 'b': [None, 2.0], 'c': [3, None]}
    """
    if isinstance(obj, dict):
        return {k: plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [plain(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return [plain(v) for v in obj.tolist()]
    if isinstance(obj, (float, np.floating)):
        return _finite(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    return obj


def write_csv(path, header, rows):
    """A table as CSV to `path` (standard output when None), numbers with 12 significant digits;
    non-finite cells are left empty.

    Parameters
    ----------
    path : str, path-like or None
        The file to write (UTF-8), or None for standard output.
    header : list of str
        The columns' names.
    rows : iterable of sequences of float
        The rows, each as long as `header` (the columns (B, k) of `table`).

    Returns
    -------
    None

    Raises
    ------
    OSError
        The file cannot be written.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.io import write_csv
    >>> write_csv(None, ["phi[deg]", "x[m]"], np.array([[0.0, 1 / 3], [30.0, np.nan]]))
    phi[deg],x[m]
    0,0.333333333333
    30,
    """
    import csv
    out = open(path, "w", newline="", encoding="utf-8") if path else sys.stdout
    try:
        writer = csv.writer(out)
        writer.writerow(header)
        for row in rows:
            writer.writerow(["" if not math.isfinite(x) else f"{x:.12g}" for x in row])
    finally:
        if path:
            out.close()


# -- the model ---------------------------------------------------------------------------------------
def info_document(engine) -> dict:
    """The model as `mbplanar info --json` prints it: links, joints, points, inputs, DOF, loops, Assur groups.

    Parameters
    ----------
    engine : Engine
        The mechanism.

    Returns
    -------
    dict
        "links", "joints", "points", "inputs", "dof", "loops", "loop_joints", "count" (Chebyshev's
        3n − 2p₅ − p₄ and the engine's own count), "groups", "mechanism_class", "formula", and for
        higher pairs "higher_pairs" and "replaced" (their equivalent lower-pair links).

    Raises
    ------
    Nothing for an `Engine`.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.io import info_document
    >>> doc = info_document(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")))
    >>> doc["links"], doc["dof"], doc["count"]["chebyshev"], doc["formula"]
    (['0', '1', '2', '3'], 1, 1, 'I(0,1) → II(2,3)')
    """
    mech, topo = engine.mech, engine.topology
    doc = {
        "model": mech.name, "title": mech.title,
        "links": [mech.ground] + mech.moving_links,
        "joints": {j.name: {"type": j.kind, "links": list(j.links), "at": list(j.at),
                            **({"guide_deg": j.guide_deg} if j.kind == "P" else {})}
                   for j in mech.joints.values()},
        "points": {p.name: {"link": p.link, "at": list(p.at)} for p in mech.points.values()},
        "inputs": [{"joint": i.joint, "name": i.name, "unit": i.unit} for i in mech.inputs],
        "dof": topo.dof,
        "loops": len(topo.loops),
        "loop_joints": [list(loop) for loop in topo.loops],
    }
    n, p5, p4 = len(mech.moving_links), len(mech.joints), len(mech.higher)
    doc["count"] = {"n": n, "p5": p5, "p4": p4, "chebyshev": 3 * n - 2 * p5 - p4, **_engine_count(engine)}
    if mech.higher:
        doc["higher_pairs"] = {name: _higher_document(engine, name) for name in mech.higher}
    s = topo.structure
    if s is not None:
        doc["groups"] = [{"class": g.group_class, "order": g.order, "kind": g.kind, "links": list(g.links),
                          "joints": list(g.joints), "external": list(g.external)} for g in s.groups]
        doc["mechanism_class"] = s.mechanism_class
        doc["formula"] = s.formula
        if s.replaced:
            doc["replaced"] = dict(s.replaced)   # the links of the equivalent mechanism that replace higher pairs
    return doc


def _engine_count(engine) -> dict:
    """The count the engine solves by: a variable per tree joint (the links' placings, inputs among
    them) and per contact parameter, less the closure equations; their difference is the DOF."""
    tree = sum(len(b.tree) for b in engine.topology.blocks)
    params = sum(len(bp.params) for bp in engine.blocks)
    equations = sum(b.counts(engine.mech)[0] for b in engine.topology.blocks)
    return {"joint_variables": tree, "contact_parameters": params, "closure_equations": equations,
            "engine": tree + params - equations}


def _higher_document(engine, name: str) -> dict:
    """A higher pair for `info`: its type, links and data, where it touches in the drawn pose, and the
    pairs of the link that replaces it in the equivalent lower-pair mechanism."""
    from ..model import replacement
    law = engine.laws[name]
    h, g = law.pair, law.geometry
    out = {"type": h.kind, "links": list(h.links), "contact": [float(x) for x in g.pitch]}
    if h.kind == "gear":
        out.update(radii=list(h.radii), mesh="internal" if h.internal else "external", carrier=g.carrier,
                   centres=[[float(x) for x in c] for c in g.centres], ratio=(-1 if not h.internal else 1) * h.radii[1] / h.radii[0])
    elif h.kind == "rack":
        out.update(radius=h.radius, centre=[float(x) for x in g.centres[0]])
    elif h.kind == "cam":
        out.update(follower=h.follower, at=list(h.at), **({"radius": h.radius} if h.radius else {}))
    else:
        out.update(at=list(h.at))
    if h.kind in ("gear", "rack"):
        out["pressure_angle_deg"] = math.degrees(h.pressure_angle)
    if h.curve is not None:
        c = h.curve
        out["curve"] = (("arc" if c.arc else "circle") if c.kind == "circle" else
                        ("closed spline" if c.closed else "open spline"))
    pairs = replacement(g, engine.size).pairs
    out["equivalent"] = [{"type": kind, "link": link, **({"at": [float(x) for x in where]} if kind == "R" else
                                                        {"at": [float(x) for x in where[0]],
                                                         "guide_deg": math.degrees(where[1])})}
                         for kind, link, where in pairs]
    return out


# -- kinematics --------------------------------------------------------------------------------------
def _row_of(result, row: int):
    """The arrays of one position by name: a `Position`'s own, or row `row` of a `Motion`'s (None where
    the result has none)."""
    if is_a(result, POSITION):
        return lambda name: getattr(result, name)

    def get(name):
        arr = getattr(result, name)
        return None if arr is None else arr[row]
    return get


def _input_documents(engine, motion, row, values=None) -> list[dict]:
    """Each input at `row`: its value in the model's unit (as requested, when given, so that 30° is not
    printed back as 29.999999999999996), in SI, and its speed and acceleration."""
    get = _row_of(motion, row)
    phi, omega, epsilon = get("phi"), get("omega"), get("epsilon")
    values = values or [inp.from_si(float(phi[k])) for k, inp in enumerate(engine.inputs)]
    return [{"name": inp.name, "joint": inp.joint, "unit": inp.unit, "value": float(values[k]),
             "value_si": float(phi[k]), "omega": float(omega[k]),
             "epsilon": float(epsilon[k])} for k, inp in enumerate(engine.inputs)]


def solve_document(engine, motion: Motion | Position, row: int = 0, values=None) -> dict:
    """One position of a motion (or a `Position`) as `mbplanar solve --json` prints it, SI.

    Parameters
    ----------
    engine : Engine
        The mechanism the motion belongs to.
    motion : Motion or Position
        The solved positions (a `Motion` with rates) or one `Position`.
    row : int
        The position of a `Motion`'s batch to write (a `Position` has one).
    values : list of float or None
        The inputs as requested (model units), written as they are so that 30° is not printed back as
        29.999999999999996; None: from the motion.

    Returns
    -------
    dict
        "model", "input" (the first) and "inputs", "points" (x, y, vx, vy, ax, ay), "links" (angle, omega,
        epsilon), "joints" (value, rate, accel), "instant_centres", and "analogues" where the motion has them.

    Raises
    ------
    IndexError
        `row` past the batch.
    TypeError
        A motion solved without rates (``rates=False``).

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.io import solve_document
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> doc = solve_document(engine, mbplanar.position(engine, 0.5))
    >>> doc["input"]["value_si"], round(doc["links"]["1"]["omega"], 9), sorted(doc["points"])
    (0.5, 1.0, ['A', 'B', 'C', 'M', 'O'])
    """
    inputs = _input_documents(engine, motion, row, values)
    doc = {"model": engine.mech.name, "input": inputs[0], "inputs": inputs,
           "points": {}, "links": {}, "joints": {}, "instant_centres": {}}
    get = _row_of(motion, row)
    xy, v, a, angle, w, e, ic = (get(n) for n in ("xy", "v", "a", "angle", "w", "e", "ic"))
    for k, name in enumerate(motion.point_names):
        (x, y), (vx, vy), (ax, ay) = xy[k], v[k], a[k]
        doc["points"][name] = {"x": x, "y": y, "vx": vx, "vy": vy, "ax": ax, "ay": ay}
    for k, name in enumerate(motion.link_names):
        doc["links"][name] = {"angle": angle[k], "omega": w[k], "epsilon": e[k]}
        doc["instant_centres"][name] = None if not np.all(np.isfinite(ic[k])) else [ic[k][0], ic[k][1]]
    value, rate, accel = get("value"), get("rate"), get("accel")
    for k, name in enumerate(motion.joint_names):
        doc["joints"][name] = {"type": engine.mech.joints[name].kind, "value": value[k],
                               "rate": rate[k], "accel": accel[k]}
    vq, aq, wq, eq = (get(n) for n in ("vq", "aq", "wq", "eq"))
    if vq is not None:
        doc["analogues"] = {
            "points": {n: {"vx": vq[k, 0], "vy": vq[k, 1], "ax": aq[k, 0], "ay": aq[k, 1]}
                       for k, n in enumerate(motion.point_names)},
            "links": {n: {"omega": wq[k], "epsilon": eq[k]} for k, n in enumerate(motion.link_names)},
        }
    return plain(doc)


_RATES = ("v", "a", "w", "e", "rate", "accel")
_ANALOGUES = ("vq", "aq", "wq", "eq", "rate_q", "accel_q")  # the same for ω = 1, ε = 0


def partials_document(engine, phi, position: Position | None = None) -> dict:
    """First, second and mixed partial analogues at one position phi (1, n_in) (SI): ∂x/∂φ_k and
    ∂²x/∂φ_k∂φ_l of every point (x, y), link angle and joint value. The second derivative along a
    direction u is the acceleration for ω = u, ε = 0, a quadratic form in u, so the mixed partial is
    (a(e_k + e_l) − a(e_k) − a(e_l)) / 2 (exact: the same solved position, no differencing). With one
    input they are the analogues, read from `position` (of phi) when it is given.

    Parameters
    ----------
    engine : Engine
        The mechanism.
    phi : array_like, shape (1, n_in)
        The position's inputs (SI).
    position : Position or None
        The `Position` of `phi`, when already solved (used with one input).

    Returns
    -------
    dict
        "inputs" (names), "first" (per input: points x, y, links, joints) and "second" (per pair of
        inputs "a,b", the same), plain floats.

    Raises
    ------
    IndexError
        `phi` cannot be reached on the drawn branch (no position to differentiate: the command line
        checks the position first).

    Examples
    --------
    The five-bar's point P moves with both cranks: ∂²P/∂φ₁∂φ₂ in the drawn pose (a central difference
    with h = 1e-4 rad gives (0, 0.0076236) m/rad² too):

    >>> import numpy as np, mbplanar
    >>> from mbplanar.io import partials_document
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/five_bar.toml"))
    >>> doc = partials_document(engine, engine.phi_drawn[None, :])
    >>> doc["inputs"], sorted(doc["second"])
    (['phi1', 'phi2'], ['phi1,phi1', 'phi1,phi2', 'phi2,phi2'])
    >>> {k: round(v, 9) + 0.0 for k, v in doc["second"]["phi1,phi2"]["points"]["P"].items()}
    {'x': 0.0, 'y': 0.007623597}
    """
    from ..kinematics import analyse
    n_in = len(engine.inputs)
    eye = np.eye(n_in)

    def along(u):
        """Rates and accelerations of points, links and joints for ω = u, ε = 0."""
        if n_in == 1 and position is not None:  # the analogues are these rates for ω = 1, ε = 0
            m, get = position, {r: getattr(position, q) for r, q in zip(_RATES, _ANALOGUES)}
        else:
            m = analyse(engine, phi, omega=u[None, :], epsilon=np.zeros((1, n_in)))
            get = {r: getattr(m, r)[0] for r in _RATES}
        return {"points": {n: np.array([get["v"][k], get["a"][k]]) for k, n in enumerate(m.point_names)},
                "links": {n: np.array([get["w"][k], get["e"][k]]) for k, n in enumerate(m.link_names)},
                "joints": {n: np.array([get["rate"][k], get["accel"][k]]) for k, n in enumerate(m.joint_names)}}

    single = [along(eye[k]) for k in range(n_in)]
    names = [i.name for i in engine.inputs]
    doc = {"inputs": names, "first": {}, "second": {}}

    def pack(table, which):
        return {"points": {n: {"x": v[which][0], "y": v[which][1]} for n, v in table["points"].items()},
                "links": {n: v[which] for n, v in table["links"].items()},
                "joints": {n: v[which] for n, v in table["joints"].items()}}

    for k in range(n_in):
        doc["first"][names[k]] = pack(single[k], 0)
        doc["second"][f"{names[k]},{names[k]}"] = pack(single[k], 1)
        for j in range(k + 1, n_in):
            both = along(eye[k] + eye[j])
            mixed = {part: {n: (both[part][n] - single[k][part][n] - single[j][part][n]) / 2
                            for n in both[part]} for part in both}
            doc["second"][f"{names[k]},{names[j]}"] = pack(mixed, 1)
    return plain(doc)


# -- forces ------------------------------------------------------------------------------------------
def forces_document(engine, motion: Motion, result: Kinetostatics, row: int = 0, values=None) -> dict:
    """One position of a kinetostatic result as `mbplanar forces --json` prints it, SI.

    Parameters
    ----------
    engine : Engine
        The mechanism.
    motion : Motion
        The positions the result was solved at.
    result : Kinetostatics
        The reactions and balancing loads (`kinetostatics`).
    row : int
        The position of the batch to write.
    values : list of float or None
        The inputs as requested (model units); None: from the motion.

    Returns
    -------
    dict
        "model", "input" and "inputs", "reactions" (per pair: the links it acts on and from, fx, fy,
        moment, magnitude, direction in degrees, a higher pair's contact force), "balancing" (per input,
        N·m or N), "virtual_power_residual" and the "loads" that acted.

    Raises
    ------
    IndexError
        `row` past the batch.

    Examples
    --------
    The heavy four-bar's links under gravity at a crank angle of 90°:

    >>> import numpy as np, mbplanar
    >>> from mbplanar.io import forces_document
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/heavy_fourbar.toml"))
    >>> motion = mbplanar.analyse(engine, np.radians([0.0, 90.0]))
    >>> doc = forces_document(engine, motion, mbplanar.kinetostatics(engine, motion), row=1)
    >>> round(doc["balancing"]["O"], 6), round(doc["reactions"]["O"]["magnitude"], 6), doc["reactions"]["O"]["on"]
    (4.683435, 113.376531, '1')
    """
    reactions = {}
    for name, r in result.reactions.items():
        fx, fy = float(r.fx[row]), float(r.fy[row])
        reactions[name] = {"type": engine.mech.kind_of(name), "on": r.on, "from": r.source,
                           "fx": fx, "fy": fy, "moment": float(r.moment[row]),
                           "magnitude": math.hypot(fx, fy), "direction_deg": math.degrees(math.atan2(fy, fx)) % 360}
        if name in result.contact_forces:   # a higher pair: the signed size along its direction
            reactions[name]["contact_force"] = float(result.contact_forces[name][row])
    inputs = _input_documents(engine, motion, row, values)
    doc = {"model": engine.mech.name,
           "input": inputs[0], "inputs": inputs,           # one balancing load per input
           "reactions": reactions,
           "balancing": {name: float(q[row]) for name, q in result.balancing.items()},
           "virtual_power_residual": float(result.virtual_power_residual[row]),
           "loads": [{"name": ld.name, "link": motion.link_names[ld.link], "fx": ld.force[row, 0],
                      "fy": ld.force[row, 1], "x": ld.point[row, 0], "y": ld.point[row, 1],
                      "moment": ld.moment[row]} for ld in result.loads]}
    return plain(doc)


# -- machine dynamics --------------------------------------------------------------------------------
def dynamics_document(engine, dyn, at=None) -> dict:
    """The JSON document of `mbplanar dynamics`, SI.

    Parameters
    ----------
    engine : Engine
        The mechanism.
    dyn : Dynamics
        Its machine dynamics (`machine_dynamics`).
    at : array_like or None
        Input values (SI) where the reduced model and the true motion are also written ("at").

    Returns
    -------
    dict
        The cycle's figures ("omega_mean", "driving_moment", the works, ΔT_I's extremes, ω and ε
        extremes, the simulated δ), "simulation" (None when not simulated) and "flywheel".

    Raises
    ------
    MotionError
        A value of `at` that cannot be reached.

    Examples
    --------
    The shaper's flywheel (without the simulation, on a coarse cycle):

    >>> import mbplanar
    >>> from mbplanar.io import dynamics_document
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/shaper.toml"))
    >>> dyn = mbplanar.machine_dynamics(engine, steps=360, simulate_motion=False)
    >>> doc = dynamics_document(engine, dyn, at=[0.0])
    >>> doc["steps"], doc["delta_target"], doc["simulation"], round(doc["flywheel"]["inertia"], 4), len(doc["at"])
    (360, 0.05, None, 0.3051, 1)
    """
    inp = engine.inputs[0]
    sim = dyn.simulation
    doc = {"model": engine.mech.name,
           "input": {"name": inp.name, "joint": inp.joint, "unit": inp.unit},
           "steps": len(dyn.phi) - 1,
           "delta_target": dyn.spec.delta,
           "omega_mean": dyn.omega_mean,
           "driving_moment": dyn.driving_moment,
           "resistance_work": dyn.resistance_work,
           "work_by_kind": dyn.work_by_kind(),
           "inertia_first_group": dyn.inertia_first_group,
           "input_link_inertia": dyn.input_link_inertia,
           "dT_I_max": dyn.dT_I_max, "dT_I_max_at": inp.from_si(dyn.phi_dT_max),
           "dT_I_min": dyn.dT_I_min, "dT_I_min_at": inp.from_si(dyn.phi_dT_min),
           "omega_min": dyn.omega_min, "omega_max": dyn.omega_max,
           "epsilon_min": dyn.epsilon_min, "epsilon_max": dyn.epsilon_max,
           "delta_simulated": dyn.delta_simulated,
           "simulation": None if sim is None else {
               "omega_min": sim.omega_min, "omega_max": sim.omega_max, "omega_time_mean": sim.omega_time_mean,
               "period": sim.period, "success": sim.success, "message": sim.message},
           "flywheel": {k: v for k, v in asdict(dyn.flywheel).items() if v is not None}}
    if at is not None:
        state = dyn.state_at(engine, at)
        doc["at"] = [{"value": inp.from_si(float(p)), "J_II": state["J_II"][k], "dJ_II": state["dJ_II"][k],
                      "M_red": state["M_red"][k],
                      "M_red_by_load": {name: m[k] for name, m in state["moments"].items()},
                      "A_c": state["A_c"][k], "dT_I": state["dT_I"][k],
                      "omega": state["omega"][k], "epsilon": state["epsilon"][k]}
                     for k, p in enumerate(state["phi"])]
    return plain(doc)

