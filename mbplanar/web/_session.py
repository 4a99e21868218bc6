"""One page's model: its text and table, its history, its engine, and what the page draws.

A `Workbench` answers the page's messages (plain dicts, the same over a WebSocket and in Jupyter) with
messages: ``document`` (the text, the table, errors located at their rows), ``picture`` (the scene of
the cycle's positions as the CLI's diagram draws it, with the vectors, centres and reactions of every
position), ``series`` (the columns of `mbplanar sweep` and of the machine dynamics, for the plots),
``marks`` (motion limits, change points and dead centres, from `mbplanar check`) and ``pose`` (one
position solved where the page asks, with `mbplanar solve`'s document). The page draws what it
receives: every pose it shows is one the engine solved here.

`Workbench.handle(message, stale)` is a generator: the server sends each answer as soon as it is made,
and `stale()` (a newer edit waiting) stops the work on a state that is already out of date.
"""

from __future__ import annotations

import math
import threading
from pathlib import Path
import time
import warnings
from collections import OrderedDict

import numpy as np

from ..engine import Engine
from ..kinematics import analyse, position
from ..errors import MbplanarError, ModelError, ModelWarning, MotionError
from ..model import parse_model
from ._document import EditError, ModelDocument, locate

__all__ = ["Workbench", "Later", "FRAMES", "HISTORY"]

FRAMES = 360          # positions of the cycle drawn and plotted
HISTORY = 200         # undo steps kept
TYPING_PAUSE = 1.0    # text edits closer than this (s) are one undo step
_ENGINES = OrderedDict()  # (source, text) → (engine, warnings): the states met lately, for undo and reopening
_ENGINES_KEPT = 24


class Later:
    """A state's slow answers (the plots' columns, the check's marks, the machine dynamics), made after the
    others and beside what comes next: the server makes each in a worker process from the state's text
    (`slow_answer`), so that the poses asked for meanwhile do not wait; the widget makes them in turn
    (`answers`)."""

    KINDS = ("series", "marks", "dynamics")

    def __init__(self, bench, version: int):
        self.text, self.name, self.frames, self.version = bench.text, bench.name, bench.frames, version
        self.fixed, self.folder = bench.fixed, bench.folder
        self._state = (bench.engine, bench.cycle)

    @property
    def answers(self):
        engine, cycle = self._state
        for kind in self.KINDS:
            yield {**_stage(kind, engine, cycle), "version": self.version}


_SLOW = {}   # in a worker process: the last state's (engine, cycle), made once for its three answers
_SLOW_LOCK = threading.Lock()


def slow_answer(kind: str, text: str, name: str, frames: int, version: int, folder=None) -> dict:
    """One slow answer of the state of `text` (in a worker process: it builds the state's engine and cycle
    from the text, as the session did, and keeps them for the next answer)."""
    key = (text, name, frames, folder)
    with _SLOW_LOCK:                      # (a server without its worker process makes them in threads)
        if key not in _SLOW:
            _SLOW.clear()
            data = ModelDocument(text, name).data
            engine = _engine(text, data, name, folder)[0]
            _SLOW[key] = (engine, _cycle(engine, frames))
        return {**_stage(kind, *_SLOW[key]), "version": version}


def _stage(kind: str, engine, cycle) -> dict:
    make = {"series": series, "marks": marks, "dynamics": dynamics_series}[kind]
    try:
        return make(engine, cycle)
    except MbplanarError as exc:
        return {"type": "marks" if kind == "marks" else "series", "more": kind == "dynamics", "groups": [],
                "marks": [], "error": _one_line(exc)}


class Workbench:
    """The state of one workbench page (one browser tab, or one Jupyter widget), answering its messages.

    `handle(message)` yields the answers (dicts) to one message of the page: "hello" (the document,
    the picture, the forces), "text" (the edited text, checked and solved), "cell", "add_row",
    "delete_row", "move" (table edits), "undo", "redo", "solve" (one position: `pose`). Errors come
    back as messages naming the file, the table and the row, never as exceptions.

    Parameters
    ----------
    text : str, optional
        The model's TOML text.
    name : str
        The file name the text is known by (it names the file in every message, as the CLI's do).
    engine : Engine, optional
        A model without text (the widget of an engine made in Python): drawn and plotted, not edited.
    frames : int
        Positions of the cycle.
    folder : path, optional
        The served folder `name` is relative to (the files a model names are read beside it there);
        None: `name` is a path.

    Examples
    --------
    >>> from mbplanar.web import Workbench
    >>> bench = Workbench(open("models/fourbar.toml").read(), "fourbar.toml", frames=12)
    >>> [a["type"] for a in bench.handle({"type": "hello"}) if isinstance(a, dict)]
    ['document', 'picture', 'forces']
    >>> typed = bench.text.replace("length = 0.10", "length = -0.10")
    >>> [a["errors"] for a in bench.handle({"type": "text", "text": typed})]
    [[{'message': "fourbar.toml: links[0] '1': 'length' must be positive, got -0.1", 'section': 'links', 'row': 0}]]
    >>> next(bench.handle({"type": "undo"}))["errors"]
    []
    """

    def __init__(self, text: str | None = None, name: str = "model.toml", *, engine=None, frames: int = FRAMES,
                 folder=None):
        self.name, self.frames, self.folder = name, int(frames), folder
        self.text = text if text is not None else ""
        self.history, self.at = [], -1
        self._last_edit = (None, 0.0)
        self.document = None            # the last ModelDocument that parsed
        self.engine, self.cycle = engine, None
        self.fixed = engine is not None and text is None
        self.saved_text = self.text
        self.version = 0                # of the engine: a pose names the picture it belongs to
        if text is not None:
            self._record(text, "open")

    # -- messages ----------------------------------------------------------------------------------
    def handle(self, message: dict, stale=lambda: False):
        """The answers (dicts) to one message of the page; see the module's docstring."""
        kind = message.get("type")
        try:
            if kind == "hello":
                yield from self.refresh(stale)
            elif kind == "load":
                self.open(_text_of(message), str(message.get("name") or "model.toml"))
                yield from self.refresh(stale)
            elif kind == "text":
                text = _text_of(message)
                if text != self.text:
                    self._record(text, "typing")
                    yield from self.refresh(stale)
            elif kind in ("cell", "add_row", "delete_row", "move"):
                yield from self._edit(message, stale)
            elif kind in ("undo", "redo"):
                step = -1 if kind == "undo" else 1
                if 0 <= self.at + step < len(self.history):
                    self.at += step
                    self.text = self.history[self.at]
                    self._last_edit = (None, 0.0)
                    yield from self.refresh(stale)
            elif kind == "solve":
                yield self.pose(message)
            else:
                yield {"type": "error", "message": f"unknown message type {kind!r}"}
        except EditError as exc:
            yield {"type": "edit_error", "message": str(exc), "section": exc.section, "row": exc.row}
        except (ModelError, TypeError, ValueError, KeyError) as exc:
            yield {"type": "error", "message": _one_line(exc)}

    def answers(self, message: dict):
        """Every answer to `message` in turn, the slow ones (`Later`) included: the widget's way."""
        for answer in self.handle(message):
            if isinstance(answer, Later):
                yield from answer.answers
            else:
                yield answer

    def open(self, text: str, name: str):
        """Start over with another file's text (a history of its own)."""
        self.name, self.text, self.history, self.at = name, text, [], -1
        self.saved_text, self.fixed = text, False
        self.engine, self.cycle, self.document = None, None, None
        self._record(text, "open")

    def saved(self, name: str):
        self.name, self.saved_text = name, self.text

    def _record(self, text: str, kind: str):
        now = time.monotonic()
        last_kind, last_time = self._last_edit
        if kind == "typing" and last_kind == "typing" and now - last_time < TYPING_PAUSE and self.at >= 0:
            self.history[self.at] = text
        else:
            del self.history[self.at + 1:]
            self.history.append(text)
            if len(self.history) > HISTORY:
                del self.history[0]
            self.at = len(self.history) - 1
        self.text, self._last_edit = text, (kind, now)

    def _edit(self, message: dict, stale):
        if self.document is None:
            raise EditError("the text does not parse: correct it in the text first")
        doc = ModelDocument(self.text, self.name)
        kind = message["type"]
        if kind == "cell":
            text = doc.set_cell(str(message["section"]), _row(message), str(message["key"]),
                                str(message.get("value", "")))
        elif kind == "add_row":
            text = doc.add_row(str(message["section"]))
        elif kind == "delete_row":
            text = doc.delete_row(str(message["section"]), int(message["row"]))
        else:
            text = self._moved(doc, str(message["name"]), message["xy"])
        self._record(text, kind)
        yield from self.refresh(stale)

    def _moved(self, doc: ModelDocument, name: str, xy) -> str:
        """The text with a joint or point dragged to xy (SI) in the drawing (edit mode)."""
        engine = self.engine
        if engine is None:
            raise EditError("no model to edit: correct the errors first")
        mech = engine.mech
        xy = [float(v) for v in xy]
        if len(xy) != 2 or not all(math.isfinite(v) for v in xy):
            raise EditError("a drawn position is two finite numbers")
        exact = {n: j.at for n, j in mech.joints.items()}
        exact.update({n: p.at for n, p in mech.points.items() if p.at is not None})
        scale = mech.units.length_scale
        angles = {}
        for k, inp in enumerate(mech.inputs):
            joint = mech.joints[inp.joint]
            if joint.kind == "R":
                where = locate(f"inputs[{k}]", "", doc.data)
                if where:
                    angles[(where["section"], where["row"])] = _turn_of(mech, inp, exact)
        return doc.move_point(name, [xy[0] / scale, xy[1] / scale], exact=exact, units=scale,
                              input_angles=angles)

    # -- a new state of the text -------------------------------------------------------------------
    def refresh(self, stale=lambda: False):
        """document, then picture, series and marks of the current text (each skipped once stale)."""
        if self.fixed:
            yield self._document_message([], [])
            yield from self._views(stale)
            return
        errors, notes = [], []
        try:
            doc = ModelDocument(self.text, self.name)
        except ModelError as exc:
            yield self._document_message([_located(exc, None)], [])
            return
        self.document = doc
        if _is_cam_file(doc.data):
            self.engine, self.cycle = None, None
            yield self._document_message([], [], note="a cam file: design its cam in the cam panel")
            return
        try:
            engine, notes = _engine(self.text, doc.data, self.name, self.folder)
            cycle = _cycle(engine, self.frames)
        except MbplanarError as exc:
            errors.append(_located(exc, doc.data))
            yield self._document_message(errors, [_warning(w, doc.data) for w in notes])
            return
        self.engine, self.cycle = engine, cycle
        self.version += 1
        yield self._document_message(errors, [_warning(w, doc.data) for w in notes])
        yield from self._views(stale)

    def _views(self, stale):
        if self.cycle is None:
            self.cycle = _cycle(self.engine, self.frames)
        yield {**picture(self.engine, self.cycle), "version": self.version}
        yield {**forces(self.engine, self.cycle), "version": self.version}
        if not stale():
            yield Later(self, self.version)

    def _document_message(self, errors, notes, note=None) -> dict:
        sections = self.document.sections() if self.document is not None else []
        return {"type": "document", "name": self.name, "text": self.text, "sections": sections,
                "errors": errors, "warnings": notes, "note": note, "fixed": self.fixed,
                "parsed": not any("line" in e for e in errors),
                "undo": self.at > 0, "redo": self.at < len(self.history) - 1,
                "dirty": self.text != self.saved_text}

    # -- one position ------------------------------------------------------------------------------
    def pose(self, message: dict) -> dict:
        """One position where the page asks: the scene there and `mbplanar solve`'s document."""
        engine = self.engine
        request = message.get("id")
        if engine is None:
            return {"type": "pose", "id": request, "error": "no model to solve: correct the errors first"}
        values = [float(v) for v in message.get("values", [])]
        if len(values) != len(engine.inputs) or not all(math.isfinite(v) for v in values):
            return {"type": "pose", "id": request,
                    "error": f"a position needs {len(engine.inputs)} finite input value(s)"}
        phi = np.array([inp.to_si(v) for inp, v in zip(engine.inputs, values)])
        speed = message.get("speed", "analogues")
        omega, epsilon = (1.0, 0.0) if speed == "analogues" else (None, None)
        numbers = message.get("why") != "drag"   # a drag's poses are drawn; its numbers come when it stops
        try:
            one = position(engine, phi if len(phi) > 1 else phi[0], omega, epsilon) if numbers else None
            shown = analyse(engine, phi[None, :] if len(phi) > 1 else phi)
        except MotionError as exc:
            return {"type": "pose", "id": request, "values": values, "error": _one_line(exc), "version": self.version}
        if len(shown.phi) == 0:
            return {"type": "pose", "id": request, "values": values, "version": self.version,
                    "error": f"{engine.mech.source}: cannot reach {_values_text(engine, values)}: {shown.message}"}
        from ..io import document
        return {"type": "pose", "id": request, "values": values, "speed": speed, "version": self.version,
                "frame": frames_of(engine, shown, self.cycle, forces=bool(message.get("forces", True))),
                "numbers": document(one, values=values, units="si") if numbers else None}


# -- the engine of a text ----------------------------------------------------------------------------
def _engine(text: str, data: dict, source: str, folder=None):
    """The engine of a model's text and the warnings its build gave, from the states met lately. The files
    the text names (a cam's profile) are read beside `source` in the served `folder` (None: the working
    folder), a gallery model's from the gallery."""
    key = (source, text, folder)
    if key in _ENGINES:
        _ENGINES.move_to_end(key)
        return _ENGINES[key]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ModelWarning)
        engine = Engine(parse_model(data, source=source, folder=_files_folder(source, folder)))
    notes = [str(w.message) for w in caught if issubclass(w.category, ModelWarning)]
    _ENGINES[key] = (engine, notes)
    while len(_ENGINES) > _ENGINES_KEPT:
        _ENGINES.popitem(last=False)
    return engine, notes


def _files_folder(source: str, folder):
    """Where the files of model `source` (a name the page sent) are: the gallery's for gallery/NAME (unless
    the served folder holds a gallery of its own), else beside it in `folder`; None when no folder is
    served (the name is a path)."""
    from pathlib import PurePosixPath
    from ._files import GALLERY
    if folder is None:
        return None
    parts = PurePosixPath(str(source).replace("\\", "/")).parts
    if parts and parts[0] == GALLERY and not (Path(folder) / GALLERY).exists():
        from ..formats import examples_folder
        gallery = examples_folder()
        return Path(str(gallery.joinpath(*parts[1:-1]))) if len(parts) > 2 else Path(str(gallery))
    return Path(folder).joinpath(*parts[:-1])


def _cycle(engine, frames: int):
    from ..viz import cycle_motion
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelWarning)
        return cycle_motion(engine, frames)


def _is_cam_file(data: dict) -> bool:
    return "cam" in data and "joints" not in data


def _text_of(message) -> str:
    text = message.get("text")
    if not isinstance(text, str):
        raise ModelError("a text message needs the text")
    return text


def _row(message):
    row = message.get("row")
    return None if row is None else int(row)


def _one_line(exc) -> str:
    return " ".join(str(exc).split())


def _located(exc, data) -> dict:
    return {"message": _one_line(exc), **locate(getattr(exc, "where", None), str(exc), data)}


def _warning(text: str, data) -> dict:
    """A warning's message located at its row: its `where` follows the file's name ("f.toml: links '2': ...")."""
    parts = text.split(": ")
    where = parts[1] if len(parts) > 2 else None
    return {"message": " ".join(text.split()), **locate(where, text, data)}


def _values_text(engine, values) -> str:
    return ", ".join(f"{inp.name} = {v:g} {inp.unit}" for inp, v in zip(engine.inputs, values))


def _turn_of(mech, inp, exact):
    """A function (moved name, its new xy (SI)) → the change of `inp`'s value (its unit) that moving it
    makes: the turn of the links its joint joins, measured between their reference points."""
    from ..model import reference_points
    joint = mech.joints[inp.joint]

    def angle_change(link, name, xy):
        if link == mech.ground:
            return 0.0
        ref = reference_points(mech, link)
        if ref is None or name not in ref or any(r not in exact for r in ref):
            return 0.0
        old = [exact[r] for r in ref]
        new = [xy if r == name else exact[r] for r in ref]
        turn = (math.atan2(new[1][1] - new[0][1], new[1][0] - new[0][0])
                - math.atan2(old[1][1] - old[0][1], old[1][0] - old[0][0]))
        return math.remainder(turn, 2 * math.pi)

    def change(name, xy):
        a, b = joint.links
        relative = angle_change(b, name, xy) - angle_change(a, name, xy)
        return inp.from_si(relative / inp.sense) if relative else 0.0
    return change


# -- what the page draws ------------------------------------------------------------------------------
def _array(a) -> np.ndarray:
    """Numbers sent to the page: float64, NaN where missing (see `_wire`)."""
    return np.asarray(a, dtype=float)


def frames_of(engine, motion, cycle, forces: bool = True, scene=None) -> dict:
    """The shapes of `motion`'s positions as the CLI's diagram draws them (`mbplanar.viz.build_scene`),
    with the vectors of the moving points (at the motion's speed), the instantaneous centres and, for a
    model with loads or masses, the reactions and balancing loads."""
    from ..viz import build_scene, moving_points
    scene = build_scene(engine, motion, cycle) if scene is None else scene
    moving = moving_points(engine, scene)
    index = [motion.point(n) for n in moving]
    out = {
        "count": len(motion.phi),
        "phi": _array(np.column_stack([inp.from_si(motion.phi[:, k]) for k, inp in enumerate(engine.inputs)])),
        "joint_xy": _array(scene.joint_xy), "point_xy": _array(scene.point_xy),
        "links": [{"name": lk.name, "kind": lk.kind, "outline": _array(lk.outline), "label": _array(lk.label),
                   "stubs": _array(lk.stubs)} for lk in scene.links],
        "sliders": [{"joint": s.joint, "slider": s.slider, "carrier": s.carrier, "grounded": bool(s.grounded),
                     "corners": _array(s.corners), "guide": _array(s.guide)} for s in scene.sliders],
        "moving": moving, "v": _array(motion.v[:, index]), "a": _array(motion.a[:, index]),
        "ic": _array(motion.ic[:, 1:]), "ic_links": list(motion.link_names[1:]),
        "omega": _array(np.atleast_1d(motion.omega).reshape(len(motion.phi), -1)),
        "pairs": [{"name": pr.name, "kind": pr.kind, "marks": _array(pr.marks), "contact": _array(pr.contact),
                   "lines": [{"kind": kind, "closed": bool(closed), "xy": _array(xy)} for kind, _, xy, closed in pr.lines]}
                  for pr in scene.pairs],
    }
    if forces:
        out.update(reactions(engine, motion))
    return out


def reactions(engine, motion) -> dict:
    """The reactions (force on `on` from `from` at each pair, (B, 2)), the moments in prismatic pairs and
    the balancing loads of `motion`'s positions, for a model with loads or masses ({} otherwise)."""
    from ..forces import has_force_data, kinetostatics
    from ..viz import reaction_label
    out = {}
    if has_force_data(engine.mech):
        result = kinetostatics(engine, motion)
        contact = {}
        if engine.mech.higher:   # a higher pair's force acts at its contact
            from ..kinematics import contact_geometry
            contact = {n: _array(g.point) for n, g in contact_geometry(engine, motion).items()}
        out["reactions"] = {name: {"label": reaction_label(r), "on": r.on, "from": r.source,
                                   "f": _array(np.column_stack([r.fx, r.fy])),
                                   "moment": _array(r.moment) if engine.mech.kind_of(name) == "P" else None,
                                   **({"at": contact[name]} if name in contact else {})}
                            for name, r in result.reactions.items()}
        out["balancing"] = {name: {"values": _array(q), "unit": "N·m" if engine.mech.joints[name].kind == "R"
                                   else "N"} for name, q in result.balancing.items()}
        out["forces_message"] = None if result.success else result.message
    return out


def picture(engine, cycle) -> dict:
    """The ``picture`` message: the model's drawing conventions (names, pairs, pivots, labels, size and
    frame of the whole cycle) and the frames of the cycle."""
    from ..viz import build_scene
    mech = engine.mech
    scene = build_scene(engine, cycle, cycle)
    x0, x1, y0, y1 = scene.extent()
    inputs = []
    for k, inp in enumerate(engine.inputs):
        joint = mech.joints[inp.joint]
        lo, hi = (float(v) for v in (inp.from_si(cycle.phi[:, k].min()), inp.from_si(cycle.phi[:, k].max())))
        inputs.append({"name": inp.name, "unit": inp.unit, "joint": inp.joint, "kind": joint.kind,
                       "links": list(joint.links), "sense": float(inp.sense), "scale": float(inp.scale),
                       "lo": lo, "hi": hi, "drawn": float(inp.from_si(engine.phi_drawn[k]))})
    elements = [{"kind": ld.kind, "name": ld.name} for ld in mech.loads if ld.kind in ("spring", "damper", "torque")]
    return {"type": "picture", "model": mech.name, "title": mech.title or mech.name, "source": mech.source,
            "size": float(scene.size), "extent": [float(x0), float(x1), float(y0), float(y1)],
            "joints": scene.joint_names, "revolute": scene.revolute, "pivots": scene.pivots,
            "labels": scene.labels, "points": scene.point_names, "centres": sorted(scene.centres),
            "ground": mech.ground, "inputs": inputs, "elements": elements,
            "length_unit": mech.units.length, "length_scale": float(mech.units.length_scale),
            "full_turn": bool(_full_turn(engine)), "message": cycle.message if not cycle.success else None,
            "frames": frames_of(engine, cycle, cycle, forces=False, scene=scene), "drawn": _drawn(engine, cycle)}


def _drawn(engine, cycle) -> dict:
    """The drawn pose (the inputs at their drawn values): what edit mode shows and drags."""
    phi = np.asarray(engine.phi_drawn, float)
    motion = analyse(engine, phi[None, :] if len(phi) > 1 else phi)
    return frames_of(engine, motion, cycle)


def forces(engine, cycle) -> dict:
    """The ``forces`` message: the reactions and balancing loads of the cycle's positions."""
    return {"type": "forces", **reactions(engine, cycle)}


def _full_turn(engine) -> bool:
    if len(engine.inputs) != 1:
        return False
    inp = engine.inputs[0]
    lo, hi = inp.default_sweep()
    return inp.unit in ("deg", "rad") and abs(inp.to_si(hi - lo)) >= 2 * math.pi - 1e-9


def series(engine, cycle) -> dict:
    """The ``series`` message: groups of columns against the input, as `mbplanar sweep` names them (the
    cycle at the model's speed, with reactions and balancing loads where the model has force data; the
    analogues; the machine dynamics follow in `dynamics_series`)."""
    from ..io import forces_columns, sweep_table
    n_in = len(engine.inputs)
    header, rows = sweep_table(engine, cycle, "deg")
    groups = []
    columns = [{"name": h, "values": _array(rows[:, k])} for k, h in enumerate(header) if k >= n_in]
    from ..forces import has_force_data, kinetostatics
    if has_force_data(engine.mech):
        f_header, f_rows = forces_columns(engine, kinetostatics(engine, cycle))
        columns += [{"name": h, "values": _array(f_rows[:, k])} for k, h in enumerate(f_header)]
    x = [{"name": h, "values": _array(rows[:, k])} for k, h in enumerate(header[:n_in])]
    groups.append({"name": "cycle at the model's speed", "x": x, "columns": columns, "cursor": "frame"})
    if n_in == 1:
        analogue = analyse(engine, cycle.phi[:, 0], 1.0, 0.0)
        a_header, a_rows = sweep_table(engine, analogue, "deg")
        keep = [k for k, h in enumerate(a_header) if k >= n_in and any(q in h for q in
                (".omega[", ".epsilon[", ".vx[", ".vy[", ".ax[", ".ay[", ".rate[", ".accel["))]
        groups.append({"name": "analogues (ω = 1, ε = 0: d/dφ, d²/dφ²)", "x": x, "cursor": "frame",
                       "columns": [{"name": a_header[k], "values": _array(a_rows[:, k])} for k in keep]})
    return {"type": "series", "groups": groups}


def dynamics_series(engine, cycle) -> dict:
    """The ``series`` message of the machine dynamics (`more`: added to the plots' columns): J_II, the
    reduced moments, the work, ΔT_I and ω(φ), ε(φ) over one cycle, as `mbplanar dynamics -o` writes them;
    none for a model without a [dynamics] section."""
    from ..io import dynamics_table
    groups = []
    if engine.mech.dynamics is not None and len(engine.inputs) == 1:
        from ..forces import machine_dynamics
        dyn = machine_dynamics(engine, steps=FRAMES)
        d_header, d_rows = dynamics_table(dyn)
        inp = engine.inputs[0]
        groups.append({"name": "machine dynamics", "cursor": "value",
                       "x": [{"name": f"{inp.name}[{inp.unit}]", "values": _array(inp.from_si(d_rows[:, 0]))}],
                       "columns": [{"name": h, "values": _array(d_rows[:, k])} for k, h in enumerate(d_header) if k > 0]})
    return {"type": "series", "more": True, "groups": groups}


def marks(engine, cycle) -> dict:
    """The ``marks`` message: motion limits, change points and the dead centres of the outputs (local
    extremes), in the input's unit, from `mbplanar check`; one-input models only."""
    if len(engine.inputs) != 1:
        return {"type": "marks", "marks": []}
    from ..analysis import check
    report = check(engine)
    out = [{"at": float(lim.phi), "kind": "limit", "text": lim.message} for lim in report.limits]
    out += [{"at": float(c.phi), "kind": "change", "text": c.message} for c in report.change_points]
    for ext in report.extremes:
        for loc in ext.local:
            if not loc.end:
                what = f"link {ext.name}" if ext.kind == "link" else f"slider {ext.name}"
                out.append({"at": float(loc.at), "kind": "dead",
                            "text": f"dead centre: {what} at its {loc.kind} ({report.input} = {loc.at:.6g} "
                                    f"{report.unit})"})
    return {"type": "marks", "marks": out, "full_turn": bool(report.full_turn),
            "range": [float(report.range[0]), float(report.range[1])]}
