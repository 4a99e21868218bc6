"""Reading a mechanism from its TOML table of kinematic pairs.

The format (documented in README.md) has a few top-level keys (`name`, `title`, `ground`,
`length_unit`), a `links` list, a `joints` list (one row per pair), a `points` list, one `[input]`
table or an `inputs` list, and optional `loads`. Every problem is reported as a `ModelError` that names
the file and the row ("joints[3] 'Ap'") at fault. Lengths are converted to metres here, at the edge.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

from ..errors import ModelError, ModelWarning, did_you_mean
from ._keys import (DOCUMENT, DYNAMICS, FLYWHEEL, GRAVITY, GUIDE_LOADS, HIGHER, INPUT, JOINT, LINK, LOADS, MISSING,
                    POINT, SWITCH, Section)
from ._model import (ANGLE_UNITS, ELEMENT_TYPES, LENGTH_UNITS, LOAD_TYPES, DynamicsSpec, FlywheelSpec, Gravity, Input,
                     Load, Mechanism, Units, unit_spelling)
from ._scale import SCALE_FACTOR, SLACK, drawing_size, out_of_scale, scale_message

__all__ = ["read_model", "read_model_text", "read_text", "parse_model", "Row", "read_load_row", "rpm_or_omega",
           "crank_input", "read_gravity_section", "read_dynamics_section"]


def read_model(path) -> Mechanism:
    """Read a TOML model file into an (unassembled) `Mechanism`.

    Parameters
    ----------
    path : str or Path
        The model file (the table of kinematic pairs, docs/format.md).

    Returns
    -------
    Mechanism
        SI inside (m, rad, N, kg) whatever units the file is written in; the drawn pose is the file's
        sketch until `assemble` (or `Engine`) closes it.

    Raises
    ------
    ModelError
        The file cannot be read, is not TOML, or a row is wrong: the message names the file, the row and
        the value.

    Examples
    --------
    >>> import mbplanar
    >>> mech = mbplanar.read_model("models/fourbar.toml")
    >>> mech.name, sorted(mech.joints)
    ('fourbar', ['A', 'B', 'C', 'O'])
    >>> mech.joints["B"].at                     # the sketch's B, m
    (0.3016, 0.25)
    """
    return read_model_text(read_text(path), source=str(path))


def read_text(path, what: str = "the model file") -> str:
    """The UTF-8 text of a file a model names, read with the errors a user can act on.

    Parameters
    ----------
    path : str or Path
        The file.
    what : str, optional
        What the file is, for the message ("the model file", "the profile", ...).

    Returns
    -------
    str
        Its text (a byte-order mark, as Excel and Notepad write, is dropped).

    Raises
    ------
    ModelError
        The file cannot be read (missing, a folder, no permission) or is not UTF-8: the message names
        the file, `what` it is and why.

    Examples
    --------
    >>> from mbplanar.model import read_text
    >>> read_text("models/fourbar.toml").splitlines()[0]
    '# Crank-rocker four-bar (Grashof): crank OA, coupler AB, rocker BC, coupler point M.'
    >>> read_text("no/such/profile.csv", "the profile")
    Traceback (most recent call last):
    mbplanar.errors.ModelError: no/such/profile.csv: cannot read the profile (No such file or directory)
    """
    path = Path(path)
    try:
        return path.read_text(encoding="utf-8-sig")  # (a byte-order mark, as Excel and Notepad write, is read)
    except OSError as exc:
        raise ModelError(f"cannot read {what} ({exc.strerror or exc})", source=str(path)) from None
    except UnicodeDecodeError as exc:
        raise ModelError(f"{what} is not UTF-8 text ({exc.reason} at byte {exc.start})", source=str(path)) from None


def read_model_text(text: str, source: str = "<table>", folder=None) -> Mechanism:
    """A `Mechanism` from the TOML text of a model (as `read_model` reads a file).

    Parameters
    ----------
    text : str
        The table of kinematic pairs (docs/format.md).
    source : str, optional
        What the messages call it (a file name).
    folder : str or Path, optional
        Where the files the table names (a cam's profile) are looked for, as in `parse_model`.

    Returns
    -------
    Mechanism
        SI inside; the drawn pose is the table's sketch until `assemble` closes it.

    Raises
    ------
    ModelError
        A TOML syntax error (naming the line and column) or a wrong row (naming it and the value).

    Examples
    --------
    >>> from mbplanar.model import read_model_text
    >>> text = '''
    ... ground = "0"
    ... links = [{ name = "1" }, { name = "2" }]
    ... joints = [
    ...   { name = "O", type = "R", links = ["0", "1"], at = [0, 0] },
    ...   { name = "A", type = "R", links = ["1", "2"], at = [0.1, 0] },
    ...   { name = "B", type = "P", links = ["2", "0"], at = [0.4, 0], guide = 0 },
    ... ]
    ... input = { joint = "O" }
    ... '''
    >>> mech = read_model_text(text, source="slider.toml")
    >>> sorted(mech.joints), mech.joints["B"].kind
    (['A', 'B', 'O'], 'P')
    >>> read_model_text("links = [", source="broken.toml")
    Traceback (most recent call last):
    mbplanar.errors.ModelError: broken.toml: TOML syntax error: ...
    """
    import tomllib  # (here: an engine read from the cache needs no parser)
    try:
        data = tomllib.loads(text.removeprefix("\ufeff"))  # (a byte-order mark, as Excel and Notepad write)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"TOML syntax error: {exc}", source=source) from None
    return parse_model(data, source=source, folder=folder)


_MISSING = object()


class Row:
    """Typed access to one table row, with errors that name the file (`source`) and row (`where`).

    With a `section` (`Section`), a key is read as the section declares it (`get`: its kind,
    default and bounds), and reading a key the section does not declare is a programming error
    (`KeyError`): the keys the reader accepts are the declared ones, which the JSON Schema describes.

    `data` is the row (a dict; anything else is refused with a `ModelError`), `where` how the messages
    name it ("joints[2]"), `used` the keys read so far (`check_unknown_keys` refuses the others).
    Readers of their own sections (the cam's, the friction's, the accuracy's) read through it too.

    Examples
    --------
    >>> from mbplanar.model import CLEARANCE, Row
    >>> row = Row({"joint": "A", "clearance": 2e-5}, "clearances[0]", "fourbar.toml", CLEARANCE)
    >>> row.get("joint"), row.get("clearance")
    ('A', 2e-05)
    >>> Row({"joint": "A", "clearance": -1}, "clearances[0]", "fourbar.toml", CLEARANCE).get("clearance")
    Traceback (most recent call last):
    mbplanar.errors.ModelError: fourbar.toml: clearances[0]: 'clearance' must not be negative, got -1
    """

    def __init__(self, data, where: str, source: str | None = None, section: Section | None = None):
        self.source, self.where, self.section = source, where, section
        if not isinstance(data, dict):
            self.fail(f"expected a table {{...}}, got {type(data).__name__}")
        self.data = data
        self.used: set[str] = set()

    def fail(self, msg: str):
        raise ModelError(msg, source=self.source, where=self.where)

    def warn(self, msg: str):
        """A `ModelWarning` naming the file and row."""
        warnings.warn(ModelWarning(str(ModelError(msg, source=self.source, where=self.where))), stacklevel=3)

    def has(self, key) -> bool:
        return key in self.data

    def _declared(self, key):
        if self.section is not None and key not in self.section:
            raise KeyError(f"'{key}' is read but not declared in the {self.section.title} section (model/_keys.py)")

    def raw(self, key, default=None):
        """The value of `key` as written (marked as read), `default` when absent."""
        self._declared(key)
        self.used.add(key)
        return self.data.get(key, default)

    def get(self, key):
        """`key` read as its section declares it: its kind, default, bounds (with the section's words)."""
        k = self.section[key]
        default = None if k.default is MISSING else k.default
        if k.kind in ("number", "integer"):
            value = self.number(key, default, required=k.required, positive=k.positive, nonzero=k.nonzero)
            return self.bounded(key, value)
        if k.kind in ("text", "choice"):
            return self.text(key, default, required=k.required)
        if k.kind == "pair":
            return self.pair(key, required=k.required)
        if k.kind == "names":
            return self.names(key, k.count, required=k.required)
        if k.kind == "numbers":
            return self.numbers(key, required=k.required)
        return self.raw(key, default)

    def bounded(self, key, value):
        """A number `value` of `key` checked against its declared bounds (None passes)."""
        k = self.section[key]
        if value is None:
            return None
        low = k.minimum is not None and (value <= k.minimum if k.exclusive else value < k.minimum)
        high = k.maximum is not None and (value >= k.maximum if k.exclusive else value > k.maximum)
        whole = k.kind != "integer" or value == int(value)
        if low or high or not whole:
            self.fail(k.message.format(key=key, value=value) if k.message else
                      f"'{key}' must be {'a whole number ' if k.kind == 'integer' else ''}within "
                      f"[{k.minimum}, {k.maximum}], got {value:g}")
        return int(value) if k.kind == "integer" else value

    def _value(self, key, required, hint=""):
        """The raw value of `key` (marked as used), `_MISSING` when absent and not required."""
        self._declared(key)
        self.used.add(key)
        if key not in self.data:
            if required:
                self.fail(f"missing '{key}'{hint}")
            return _MISSING
        return self.data[key]

    def text(self, key, default=None, required=False) -> str | None:
        value = self._value(key, required)
        if value is _MISSING:
            return default
        if isinstance(value, bool) or not isinstance(value, (str, int)):
            self.fail(f"'{key}' must be a name (text), got {value!r}")
        return str(value)

    def number(self, key, default=None, required=False, positive=False, nonzero=False) -> float | None:
        value = self._value(key, required)
        return default if value is _MISSING else self._check_number(key, value, positive, nonzero)

    def _check_number(self, key, value, positive=False, nonzero=False) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(f"'{key}' must be a number, got {value!r}")
        value = float(value)
        if not math.isfinite(value):
            self.fail(f"'{key}' must be finite, got {value}")
        if positive and value <= 0:
            self.fail(f"'{key}' must be positive, got {value}")
        if nonzero and value == 0:
            self.fail(f"'{key}' must not be zero")
        return value

    def pair(self, key, required=False) -> tuple[float, float] | None:
        value = self._value(key, required, " (drawn coordinates [x, y])")
        if value is _MISSING:
            return None
        if not isinstance(value, list) or len(value) != 2:
            self.fail(f"'{key}' must be [x, y], got {value!r}")
        return (self._check_number(key, value[0]), self._check_number(key, value[1]))

    def numbers(self, key, required=False) -> tuple[float, ...] | None:
        """A list of finite numbers."""
        value = self._value(key, required)
        if value is _MISSING:
            return None
        if not isinstance(value, list):
            self.fail(f"'{key}' must be a list of numbers, got {value!r}")
        return tuple(self._check_number(f"{key}[{k}]", v) for k, v in enumerate(value))

    def unit(self, key, allowed, default=None) -> str | None:
        """The unit named by `key`, spelt as in `allowed` whatever its case (see `unit_spelling`)."""
        name = self.text(key, default)
        if name is None:
            return None
        unit = unit_spelling(name, allowed)
        if unit is None:
            self.fail(f"{key} must be one of {', '.join(repr(a) for a in allowed)} (in any case), got {name!r}")
        return unit

    def names(self, key, count=2, required=False) -> tuple[str, ...] | None:
        value = self._value(key, required)
        if value is _MISSING:
            return None
        if not isinstance(value, list) or len(value) != count or not all(
                isinstance(v, (str, int)) and not isinstance(v, bool) for v in value):
            self.fail(f"'{key}' must be a list of {count} names, got {value!r}")
        return tuple(str(v) for v in value)

    def check_unknown_keys(self, extra: set[str] = frozenset()):
        unknown = set(self.data) - self.used - set(extra)
        if unknown:
            self.fail(f"unknown key(s) {', '.join(sorted(unknown))}")


def _rows(data, key, source) -> list:
    rows = data.get(key, [])
    if isinstance(rows, dict):  # [links.1] style tables: name = key
        rows = [dict(v, name=k) if isinstance(v, dict) else v for k, v in rows.items()]
    if not isinstance(rows, list):
        raise ModelError(f"'{key}' must be a list of rows", source=source)
    return rows


def parse_model(data: dict | str, source: str = "<table>", folder=None) -> Mechanism:
    """Build a `Mechanism` from the parsed TOML document `data`, or from TOML text.

    Every section is read and checked here, once: links, joints, points, inputs, then `loads`,
    `[gravity]` and `[dynamics]` into `Mechanism.loads`, `.gravity` and `.dynamics` (SI units).

    Parameters
    ----------
    data : dict or str
        The parsed TOML document, or its text.
    source : str
        What the messages call the table (a file's name).
    folder : path, optional
        Where the files the table names (a curve's `file`) are read; by default the folder of `source`
        (the working folder for a table without a file).

    Returns
    -------
    Mechanism
        SI inside, not yet assembled (`assemble`).

    Raises
    ------
    ModelError
        A missing or wrong row, named with `source`, the row and the value.

    Examples
    --------
    >>> import mbplanar
    >>> crank = mbplanar.parse_model('''
    ... name = "crank"
    ... ground = "0"
    ... links = [{ name = "1", length = 0.1 }]
    ... joints = [{ name = "O", type = "R", links = ["0", "1"], at = [0.0, 0.0] }]
    ... points = [{ name = "A", link = "1", at = [0.1, 0.0] }]
    ... [input]
    ... joint = "O"
    ... ''')
    >>> crank.name, list(crank.links), crank.inputs[0].joint
    ('crank', ['1'], 'O')
    """
    if isinstance(data, str):
        return read_model_text(data, source, folder)
    if isinstance(data, dict) and "joints" not in data:  # a [table] header above the lists takes them in
        inside = next((k for k, v in data.items() if isinstance(v, dict) and "joints" in v), None)
        if inside is not None:
            raise ModelError(f"the 'joints' list is inside [{inside}]: a [table] header takes every key below it; "
                             f"move [{inside}] after the lists", source=source)
    if isinstance(data, dict) and "cam" in data and not data.get("joints"):
        command = f"mbplanar cam {'FILE' if source.startswith('<') else source}"
        raise ModelError(f"this is a cam file: use `{command}` (the linkage commands read a table of pairs)",
                         source=source)
    if isinstance(data, dict) and _has_parameters(data):
        from ._parameters import Template  # named dimensions and polar placements, bound to their values
        data = Template(data, source).bind()
    top = Row(data, None, source, DOCUMENT)
    units = _read_units(top)
    unit = units.length_scale
    mech = Mechanism(name=top.text("name", Path(source).stem), ground=top.get("ground"),
                     title=top.get("title"), source=source, units=units)
    link_rows = _read_links(mech, _rows(data, "links", source), unit)
    higher = _read_joints(mech, _rows(data, "joints", source), unit)
    _read_points(mech, _rows(data, "points", source), unit)
    _read_higher(mech, higher, unit, folder)
    _check_links(mech, link_rows)
    _read_inputs(mech, data, source, unit)
    mech.loads = _read_loads(mech, data.get("loads", []))
    if "gravity" in data:
        mech.gravity = read_gravity_section(mech, data["gravity"])
    if "dynamics" in data:
        mech.dynamics = read_dynamics_section(mech, data["dynamics"])
    for key in ("links", "joints", "points", "input", "inputs", "loads", "gravity", "dynamics"):
        top.raw(key)
    mech.extras = {k: top.raw(k) for k in data if k not in top.used and k in _EXTRA_SECTIONS}
    for key in data:
        if key not in top.used:
            top.fail(f"unknown key '{key}'")
    return mech


def _has_parameters(data: dict) -> bool:
    """Whether the table declares [parameters] or places a joint by a length and an angle."""
    joints = data.get("joints")
    rows = joints.values() if isinstance(joints, dict) else joints if isinstance(joints, list) else []
    return "parameters" in data or any(isinstance(r, dict) and isinstance(r.get("at"), dict) for r in rows)


def _read_units(top: Row) -> Units:
    """The table's `length_unit`, `inertia_unit` and `moment_unit` (see `mbplanar.model.Units`), in any
    case ("MM" is "mm")."""
    chosen = []
    for key in ("length_unit", "inertia_unit", "moment_unit"):
        chosen.append(top.unit(key, DOCUMENT[key].choices, DOCUMENT[key].default))
    return Units(*chosen)


# Sections kept raw in `Mechanism.extras` for the pictures, the report, the cam, the gears, friction,
# simulate and the tolerances (mbplanar.cam, mbplanar.gears, mbplanar.forces.read_friction and
# read_simulate, mbplanar.accuracy read and check theirs); `synthesis`: the summary a synthesised model
# carries (mbplanar.synthesis.report shows it in the report).
_EXTRA_SECTIONS = ("plot", "description", "cam", "gears", "friction", "simulate", "synthesis", "tolerances")


def _read_links(mech: Mechanism, rows, unit) -> dict[str, str]:
    """Add the links; return each link's row label (for later checks)."""
    labels = {}
    for i, raw in enumerate(rows):
        row = Row(raw, f"links[{i}]", mech.source, LINK)
        name = row.get("name")
        row.where = f"links[{i}] '{name}'"
        labels[name] = row.where
        lengths = []
        if row.has("length"):
            lengths.append(("", "", row.get("length") * unit))
        raw_lengths = row.raw("lengths", [])
        if not isinstance(raw_lengths, list):
            row.fail(f"'lengths' must be a list of [P, Q, length], got {raw_lengths!r}")
        for k, item in enumerate(raw_lengths):
            if not (isinstance(item, list) and len(item) == 3):
                row.fail(f"lengths[{k}] must be [P, Q, length], got {item!r}")
            p, q, value = item
            if not all(isinstance(v, (str, int)) and not isinstance(v, bool) for v in (p, q)):
                row.fail(f"lengths[{k}] must be [P, Q, length] with P, Q point names, got {item!r}")
            if str(p) == str(q):
                row.fail(f"lengths[{k}] joins point '{p}' to itself")
            length = row._check_number(f"lengths[{k}]", value, positive=True) * unit
            lengths.append((str(p), str(q), length))
        angle = row.get("angle")
        angle_offset = math.radians(row.get("angle_offset"))
        mass = row.get("mass")
        inertia = row.get("inertia")
        centre, centre_at = _centre(row, name, unit)
        row.check_unknown_keys({"comment"})
        if name == mech.ground:
            if lengths:
                row.fail("the ground's geometry is its drawn coordinates; it takes no lengths")
            continue
        try:
            mech.add_link(name, lengths=tuple(lengths), angle=angle, mass=mass,
                          inertia=inertia * mech.units.inertia_scale, centre=centre, angle_offset=angle_offset)
            if centre_at is not None:
                mech.add_point(centre, name, at=centre_at)
        except ModelError as exc:
            row.fail(exc.message)
    return labels


def _check_links(mech: Mechanism, labels: dict[str, str]):
    """Each link's centre is one of its points, a link with mass has one, and a link whose revolute
    joints all sit at one drawn point (a zero-length link) is refused."""
    for name, link in mech.links.items():
        where = labels.get(name, f"link '{name}'")
        own = {j.name for j in mech.joints_of(name)} | {p.name for p in mech.points.values() if p.link == name}
        if link.centre is not None and link.centre not in own:
            raise ModelError(f"centre '{link.centre}' is not a joint or point of this link; "
                             f"{did_you_mean(link.centre, own, 'joints and points of the link')}",
                             source=mech.source, where=where)
        if link.mass and link.centre is None:
            raise ModelError(f"a link with mass ({link.mass:g} kg) needs a 'centre' point",
                             source=mech.source, where=where)
        _check_extent(mech, name, where)
        _warn_link_scale(mech, name, where)


def _warn_link_scale(mech: Mechanism, name: str, where: str):
    """Warn when a link's given lengths, or its drawn extent, are 1/100 of the drawing or less (a 0.1 mm
    crank in a machine drawn in metres), or 100 times or more."""
    size, units = drawing_size(mech), mech.units
    row = Row({}, where, mech.source)
    for p, q, value in mech.links[name].lengths:
        if out_of_scale(value, size):
            between = f" {p}-{q}" if p else ""
            row.warn(scale_message(f"its length{between} =", value, size, units.length, units.length_scale))
            return
    spots = [(j.name, j.at) for j in mech.joints_of(name)]
    spots += [(p.name, p.at) for p in mech.points.values() if p.link == name and p.at is not None]
    extent, pair = max(((math.dist(a, b), (m, n)) for m, a in spots for n, b in spots), default=(0.0, None))
    if out_of_scale(extent, size):
        row.warn(scale_message(f"it is drawn {pair[0]}-{pair[1]} =", extent, size, units.length, units.length_scale))
        return
    for p in mech.points.values():
        for key in ("distance", "offset"):
            value = getattr(p, key) if p.link == name else None
            if value and abs(value) > size and out_of_scale(value, size):     # (a small offset is a detail)
                row.warn(scale_message(f"point '{p.name}' has {key} =", value, size, units.length, units.length_scale))
                return
    link = mech.links[name]
    if link.mass > 0 and link.inertia > 0 and size > 0 and out_of_scale(math.sqrt(link.inertia / link.mass), size):
        k = math.sqrt(link.inertia / link.mass)
        row.warn(f"its radius of gyration sqrt(inertia/mass) = {k:.4g} m while the drawing spans {size:.4g} m "
                 f"({k / size:.3g} times that): is 'inertia' in another unit? (inertias here are read in "
                 f"{units.inertia}; inertia_unit says otherwise)")


def _check_extent(mech: Mechanism, name: str, where: str):
    """A link with two or more revolute joints, no guide and no other point, all drawn at one place,
    has zero length: its angle is undefined. "One place" is relative to the drawing (its extent, or the
    rounding of its coordinates), whatever its scale or distance from the origin: a 1e-13 m four-bar, or
    a 0.1 m one 1e11 m out, is no zero-length link."""
    joints = mech.joints_of(name)
    revolute = [j for j in joints if j.kind == "R"]
    if len(revolute) < 2 or len(revolute) < len(joints):
        return
    spots = [j.at for j in revolute] + [p.at for p in mech.points.values() if p.link == name and p.at]
    size = max((math.dist(a, b) for a in spots for b in spots), default=0.0)
    drawing = [j.at for j in mech.joints.values()] + [p.at for p in mech.points.values() if p.at]
    span = max(max(xy[0] for xy in drawing) - min(xy[0] for xy in drawing),
               max(xy[1] for xy in drawing) - min(xy[1] for xy in drawing))
    # at one place: within 1e-12 of the drawing's own size, or within the rounding of its coordinates
    # (~1e-16 of them: a link far from the origin is judged by its own length, not by the distance)
    if size <= max(1e-12 * span, 8 * 2.0 ** -52 * max(abs(c) for xy in drawing for c in xy)):
        raise ModelError(f"zero-length link: its joints {', '.join(j.name for j in revolute)} are drawn at "
                         f"the same point", source=mech.source, where=where)


def _centre(row: Row, link: str, unit: float) -> tuple[str | None, tuple[float, float] | None]:
    """A link's `centre`: a point's name, or coordinates [x, y] in the drawn pose, which make a point
    of the link named `<link>:centre` (its drawn coordinates in metres)."""
    value = row.raw("centre")
    if not isinstance(value, list):
        return row.text("centre"), None
    x, y = row.pair("centre")
    return f"{link}:centre", (x * unit, y * unit)


def _read_joints(mech: Mechanism, rows, unit):
    if not rows:
        raise ModelError("no joints (a 'joints' list of pairs is required)", source=mech.source)
    higher = []
    for i, raw in enumerate(rows):
        row = Row(raw, f"joints[{i}]", mech.source, JOINT)
        kind = row.data.get("type")
        if isinstance(kind, str) and kind.lower() in HIGHER:
            higher.append((i, raw, kind.lower()))  # (after the lower pairs: they may name their joints)
            continue
        name = row.get("name")
        row.where = f"joints[{i}] '{name}'"
        kind = (row.get("type") or "").upper()
        if kind not in JOINT["type"].choices:
            row.fail(f"type must be 'R' (revolute), 'P' (prismatic) or a higher pair ({', '.join(HIGHER)}), "
                     f"got '{kind}'")
        links = joined_links(mech, row)
        x, y = row.pair("at", required=JOINT["at"].required)
        guide = guide_points = None
        carrier = row.get("carrier")
        if kind == "P":
            if carrier is not None:
                if carrier not in links:
                    row.fail(f"carrier '{carrier}' is not one of its links {list(links)}")
                links = (carrier, links[1] if links[0] == carrier else links[0])
            value = row.raw("guide")
            if value is None:
                row.fail("a prismatic pair needs 'guide': an angle in degrees or two points [P, Q] "
                         "of the carrier link")
            if isinstance(value, list):
                guide_points = row.names("guide")
            else:
                guide = row.number("guide")
        else:
            if row.has("guide") or carrier is not None:
                row.fail("'guide' and 'carrier' belong to prismatic (P) pairs only")
        row.check_unknown_keys({"comment"})
        try:
            mech.add_joint(name, kind, links[0], links[1], (x * unit, y * unit), guide, guide_points)
        except ModelError as exc:
            row.fail(exc.message)
    return higher


def joined_links(mech: Mechanism, row: Row) -> tuple[str, str]:
    """A pair's `links`: two links of the model, not one link twice."""
    links = row.get("links")
    if links[0] == links[1]:
        row.fail(f"joins link '{links[0]}' to itself")
    for link in links:
        if link != mech.ground and link not in mech.links:
            row.fail(f"link '{link}' is not in the links list (ground is '{mech.ground}'); "
                     f"{did_you_mean(link, mech.all_links, 'links')}")
    return links


def _read_higher(mech: Mechanism, rows, unit, folder=None):
    """The higher pairs (gear, rack, cam, slot rows), after the joints and points they may name."""
    from ._pairs import read_higher_row
    for i, raw, kind in rows:
        row = Row(raw, f"joints[{i}]", mech.source, HIGHER[kind])
        row.where = f"joints[{i}] '{row.get('name')}'"
        read_higher_row(mech, row, kind, unit, folder)


def _read_points(mech: Mechanism, rows, unit):
    for i, raw in enumerate(rows):
        row = Row(raw, f"points[{i}]", mech.source, POINT)
        name = row.get("name")
        row.where = f"points[{i}] '{name}'"
        link = row.get("link")
        if link != mech.ground and link not in mech.links:
            row.fail(f"link '{link}' is not in the links list (ground is '{mech.ground}'); "
                     f"{did_you_mean(link, mech.all_links, 'links')}")
        at = row.pair("at")
        along = row.get("along")
        fraction = row.get("fraction")
        distance = row.get("distance")
        offset = row.get("offset")
        if (at is None) == (along is None):
            row.fail("give either 'at' = [x, y] or 'along' = [P, Q] with 'fraction' or 'distance'")
        if along is not None and (fraction is None) == (distance is None):
            row.fail("'along' needs exactly one of 'fraction' or 'distance'")
        row.check_unknown_keys({"comment"})
        try:
            mech.add_point(name, link, None if at is None else (at[0] * unit, at[1] * unit),
                           along=along, fraction=fraction,
                           distance=None if distance is None else distance * unit,
                           offset=offset * unit)
        except ModelError as exc:
            row.fail(exc.message)


def rpm_or_omega(row: Row, omega_key: str, rpm_key: str, default: float | None) -> float | None:
    """A speed given as `omega_key` (rad/s) or `rpm_key` (rev/min), never both; in rad/s."""
    if row.has(omega_key) and row.has(rpm_key):
        row.fail(f"give either '{omega_key}' (rad/s) or '{rpm_key}' (rev/min), not both")
    rpm = row.number(rpm_key)
    return row.number(omega_key, default) if rpm is None else rpm * math.pi / 30.0


def _speed(row: Row, kind: str) -> float:
    """The input's default speed dφ/dt: `omega` (rad/s, or m/s for a prismatic input) or `rpm`."""
    if kind == "P" and row.has("rpm"):
        row.fail("'rpm' is a revolute input's speed; a prismatic input takes 'omega' in m/s")
    return rpm_or_omega(row, "omega", "rpm", INPUT["omega"].default)


def _read_inputs(mech: Mechanism, data, source, unit):
    rows = data.get("inputs")
    if rows is None:
        rows = [data["input"]] if "input" in data else []
    elif "input" in data:
        raise ModelError("give either [input] or an 'inputs' list, not both", source=source)
    if not isinstance(rows, list):
        raise ModelError("'inputs' must be a list of tables", source=source)
    if not rows:
        raise ModelError("no input: add an [input] table naming the driving joint", source=source)
    for i, raw in enumerate(rows):
        row = Row(raw, f"inputs[{i}]", source, INPUT)
        joint_name = row.get("joint")
        row.where = f"inputs[{i}] (joint '{joint_name}')"
        joint = mech.joints.get(joint_name)
        if joint_name in mech.higher:
            row.fail(f"'{joint_name}' is a higher pair ({mech.higher[joint_name].kind}): an input drives a revolute "
                     "or prismatic joint")
        if joint is None:
            row.fail(f"'{joint_name}' is not a joint of the table; {did_you_mean(joint_name, mech.joints, 'joints')}")
        if any(inp.joint == joint_name for inp in mech.inputs):
            row.fail(f"joint '{joint_name}' is driven twice")
        default_unit = "deg" if joint.kind == "R" else mech.units.length
        allowed = tuple(ANGLE_UNITS) if joint.kind == "R" else tuple(LENGTH_UNITS)
        in_unit = unit_spelling(row.text("unit", default_unit), allowed)
        if in_unit is None:
            row.fail(f"unit of a {'revolute' if joint.kind == 'R' else 'prismatic'} input must be "
                     f"one of {', '.join(allowed)}, got '{row.data.get('unit')}'")
        sense = row.get("sense")
        if isinstance(sense, str):
            sense = {"ccw": 1.0, "cw": -1.0}.get(sense, sense)
        if isinstance(sense, bool) or sense not in (1, -1, 1.0, -1.0):
            row.fail(f"sense must be 1, -1, 'ccw' or 'cw', got {sense!r}")
        sweep = row.raw("sweep")
        if sweep is not None:
            if not (isinstance(sweep, list) and len(sweep) == 2):
                row.fail(f"sweep must be [from, to], got {sweep!r}")
            sweep = (row._check_number("sweep", sweep[0]), row._check_number("sweep", sweep[1]))
            if sweep[0] == sweep[1]:
                row.fail("sweep range is empty")
        omega, epsilon = _speed(row, joint.kind), row.get("epsilon")
        for key, value, bound in (("omega", omega, 1e100), ("epsilon", epsilon, 1e200)):
            if abs(value) > bound:  # (as analyse's own check: squares and products must stay finite)
                row.fail(f"{key} must be at most {bound:g} in size, got {value:g}")
        if joint.kind == "P" and sweep is not None:
            k = LENGTH_UNITS[in_unit]
            _warn_length(mech, row, f"the sweep [{sweep[0]:g}, {sweep[1]:g}] {in_unit} spans",
                         abs(sweep[1] - sweep[0]) * k, Units(in_unit), "is it")
        inp = Input(joint=joint_name, name=row.get("name"), unit=in_unit, zero=row.get("zero"), sense=float(sense),
                    omega=omega, epsilon=epsilon, drawn_at=row.get("drawn_at"), sweep=sweep, steps=row.get("steps"))
        row.check_unknown_keys({"comment"})
        mech.inputs.append(inp)


# -- loads ------------------------------------------------------------------------------------------
_WHEN = LOADS["resistance"]["when"].choices
_SWITCH_KEYS = frozenset(k.name for k in SWITCH)


def _read_loads(mech: Mechanism, rows) -> tuple[Load, ...]:
    """The `loads` rows as `Load`s (SI), names unique."""
    if not isinstance(rows, list):
        raise ModelError("'loads' must be a list of rows", source=mech.source)
    loads = tuple(read_load_row(mech, i, raw, mech.units) for i, raw in enumerate(rows))
    seen = {}
    for ld in loads:
        if ld.name in seen or ld.name.startswith("gravity on "):
            why = f"is also loads[{seen[ld.name]}]'s" if ld.name in seen else "is kept for gravity"
            raise ModelError(f"the name '{ld.name}' {why}", source=mech.source, where=f"loads[{ld.index}]")
        seen[ld.name] = ld.index
    return loads


def read_load_row(mech: Mechanism, i: int, raw, units: Units) -> Load:
    """One `loads` row (index `i`) of `mech`, its numbers in `units`, as a checked `Load` in SI."""
    row = Row(raw, f"loads[{i}]", mech.source)
    kind = row.data.get("type")
    if kind not in LOAD_TYPES:
        row.fail(f"'type' must be one of {', '.join(LOAD_TYPES)}, got {kind!r}")
    row.section = LOADS[kind]
    label = row.raw("name")
    if label is not None and (not isinstance(label, str) or not label.strip()):
        row.fail(f"'name' must be a non-empty text, got {label!r}")
    row.where = f"loads[{i}] '{label}'" if label else f"loads[{i}] ({kind})"
    switched = row.has("switch")
    allowed = set(row.section.names)
    if kind in GUIDE_LOADS and switched:
        allowed |= _SWITCH_KEYS       # (refused below, with the reason)
    elif kind not in GUIDE_LOADS and not switched:
        allowed -= _SWITCH_KEYS
    unknown = set(row.data) - allowed
    if unknown:
        row.fail(f"unknown key(s) {', '.join(sorted(unknown))}")
    if kind in GUIDE_LOADS:
        if switched:
            row.fail("a guide force is switched by its own joint ('when'); no 'switch'")
        load = _guide_load(mech, i, row, kind, units)
    elif kind in ELEMENT_TYPES:
        load = _element_load(mech, i, row, kind, units)
    else:
        load = _link_load(mech, i, row, kind, units)
    if switched:
        load.update(_switch(mech, row))
    for key in ("at", "other_at"):
        if load.get(key) is not None:
            _warn_far(mech, row, load[key], units)
    return Load(**{**load, "label": label})


def _warn_far(mech, row: Row, at, units: Units):
    """Warn when a load's drawn point lies `SCALE_FACTOR` drawings or more away from every joint."""
    size = drawing_size(mech)
    far = min((math.dist(at, j.at) for j in mech.joints.values()), default=0.0)
    if size > 0 and far >= SCALE_FACTOR * size * (1 - SLACK):
        u, k = units.length, units.length_scale
        row.warn(f"'at' = [{at[0] / k:.6g}, {at[1] / k:.6g}] {u} lies {far / k:.6g} {u} from the nearest joint while "
                 f"the drawing spans {size / k:.6g} {u} ({far / size:.3g} times that): is it in another unit? "
                 f"(lengths here are read in {u})")


def _switch(mech, row: Row) -> dict:
    """`switch` (a joint or point), `switch_direction` (degrees, points) and `when` of any row."""
    name = row.get("switch")
    if name not in mech.joints and name not in mech.points:
        row.fail(f"'switch' = '{name}' is neither a joint nor a point of the model; "
                 f"{did_you_mean(name, [*mech.joints, *mech.points], 'joints and points')}")
    if row.has("switch_direction") and name not in mech.points:
        row.fail(f"'switch_direction' applies to a point; '{name}' is a joint")
    direction = math.radians(row.get("switch_direction"))
    when = row.get("when")
    if when not in ("forward", "backward"):
        row.fail(f'a switched row needs \'when\' = "forward" (active while the velocity is >= 0) or '
                 f'"backward" (<= 0), got {when!r}')
    return {"switch": name, "switch_direction": direction, "when": when}


def _element_load(mech, i, row: Row, kind, units: Units) -> dict:
    """A spring, damper or torque between two links (lengths in the table's unit, moments in its
    moment unit, stiffness N/m, damping N·s/m or, in a joint, N·m·s/rad in the moment unit)."""
    if kind == "damper" and row.has("joint"):
        if row.has("at") or row.has("links"):
            row.fail("a rotational damper takes 'joint' only (no 'at' or 'links')")
        joint = row.get("joint")
        j = mech.joints.get(joint)
        if j is None or j.kind != "R":
            row.fail(f"joint '{joint}' is not a revolute joint of the model; "
                     f"{did_you_mean(joint, [n for n, o in mech.joints.items() if o.kind == 'R'], 'revolute joints')}")
        c = row.get("damping")
        return dict(index=i, kind=kind, link=j.links[1], other=j.links[0], joint=joint,
                    damping=c * units.moment_scale)
    if kind == "torque":
        a, b = _two_links(mech, row, required=True)
        return dict(index=i, kind=kind, link=b, other=a, moment=row.get("moment") * units.moment_scale)
    ends = row.raw("at")
    if not isinstance(ends, list) or len(ends) != 2:
        row.fail(f"'at' must be [P, Q], two points (names or [x, y]), got {ends!r}")
    a, b = _end_links(mech, row, ends)
    fields = dict(index=i, kind=kind, link=b, other=a, **_end(mech, row, b, ends[1], units),
                  **{f"other_{k}": v for k, v in _end(mech, row, a, ends[0], units).items()})
    if kind == "damper":
        return dict(fields, damping=row.get("damping"))
    if row.has("length") or isinstance(row.data.get("force"), list):
        if {"stiffness", "free_length", "preload"} & set(row.data):
            row.fail("give either a table (length, force) or stiffness/free_length/preload")
        ls = tuple(x * units.length_scale for x in row.numbers("length", required=True))
        fs = row.numbers("force", required=True)
        if len(ls) != len(fs) or len(ls) < 2 or any(q <= p for p, q in zip(ls, ls[1:])) or ls[0] < 0:
            row.fail(f"'length' (increasing, >= 0) and 'force' must be lists of equal length (at least 2), "
                     f"got {len(ls)} and {len(fs)}")
        _warn_length(mech, row, "the spring's 'length' table reaches", ls[-1], units)
        return dict(fields, s=ls, table=fs)
    k = row.bounded("stiffness", row.number("stiffness", required=True))
    free = row.get("free_length")
    if free is not None:
        _warn_length(mech, row, "free_length =", free * units.length_scale, units)
    return dict(fields, stiffness=k, free_length=None if free is None else free * units.length_scale,
                preload=row.get("preload"))


def _two_links(mech, row: Row, required=False) -> tuple[str, str] | None:
    value = row.raw("links")
    if value is None and not required:
        return None
    if not isinstance(value, list) or len(value) != 2 or str(value[0]) == str(value[1]):
        row.fail(f"'links' must be two different links [a, b], got {value!r}")
    for name in value:
        if str(name) not in mech.links and str(name) != mech.ground:
            row.fail(f"'{name}' in 'links' is not a link of the model; {did_you_mean(name, mech.all_links, 'links')}")
    return str(value[0]), str(value[1])


def _end_links(mech, row: Row, ends) -> tuple[str, str]:
    """The links of a two-point element's ends: `links` if given, else each named point's own link."""
    given = _two_links(mech, row)
    if given is not None:
        return given
    out = []
    for end in ends:
        if isinstance(end, str) and end in mech.joints:
            row.fail(f"'{end}' in 'at' is a joint, of links {' and '.join(mech.joints[end].links)}: say on which "
                     "links the ends lie ('links = [a, b]')")
        if isinstance(end, str) and end not in mech.points:
            row.fail(f"'{end}' in 'at' is neither a point nor a joint of the model; "
                     f"{did_you_mean(end, [*mech.points, *mech.joints], 'points and joints')}")
        if not (isinstance(end, str) and end in mech.points):
            row.fail(f"say on which links the ends lie ('links = [a, b]'): {end!r} is not a named point of "
                     "one link")
        out.append(mech.points[end].link)
    if out[0] == out[1]:
        row.fail(f"both ends are on link '{out[0]}'")
    return out[0], out[1]


def _end(mech, row: Row, link: str, end, units: Units) -> dict:
    """One end of an element on `link`: {"at": drawn coordinates (m)} or {"point": a point or joint}."""
    if isinstance(end, list):
        if len(end) != 2:
            row.fail(f"an end in 'at' must be a name or [x, y], got {end!r}")
        x, y = (row._check_number("at", v) for v in end)
        return {"at": (x * units.length_scale, y * units.length_scale)}
    if not isinstance(end, str):
        row.fail(f"an end in 'at' must be a name or [x, y], got {end!r}")
    return {"point": _named_on(mech, row, link, end, f"'{end}' in 'at'")}


def _named_on(mech, row: Row, link: str, name: str, what: str) -> str:
    """`name`, checked to be a point of `link` or a joint of it (`what` names it in the error)."""
    if name in mech.points:
        if mech.points[name].link != link:
            row.fail(f"point '{name}' is on link '{mech.points[name].link}', not '{link}'")
    elif name in mech.joints:
        if link not in mech.joints[name].links:
            row.fail(f"joint '{name}' does not belong to link '{link}'")
    else:
        row.fail(f"{what} is neither a point nor a joint of the model; "
                 f"{did_you_mean(name, [*mech.points, *mech.joints], 'points and joints')}")
    return name


def _link_load(mech, i, row: Row, kind, units: Units) -> dict:
    link = row.get("link")
    if link not in mech.links:
        row.fail(f"'{link}' is not a moving link of the model; {did_you_mean(link, mech.moving_links, 'moving links')}")
    fields = dict(index=i, kind=kind, link=link)
    if kind == "force":
        fields["force"] = row.get("force")
    elif kind == "weight":
        fields["magnitude"] = row.get("weight")
    else:
        fields["moment"] = row.get("moment") * units.moment_scale
    return dict(fields, **_where_on(mech, row, link, units, kind))


def _guide_load(mech, i, row: Row, kind, units: Units) -> dict:
    joint = row.get("joint")
    j = mech.joints.get(joint)
    if j is None or j.kind != "P":
        row.fail(f"joint '{joint}' is not a prismatic joint of the model; "
                 f"{did_you_mean(joint, [n for n, o in mech.joints.items() if o.kind == 'P'], 'prismatic joints')}")
    link = row.text("link", j.slider)
    if link not in j.links or link == mech.ground:
        row.fail(f"link '{link}' must be the moving link of joint '{joint}' the force acts on")
    fields = dict(index=i, kind=kind, link=link, joint=joint, **_where_on(mech, row, link, units, kind, joint))
    if kind == "friction":
        return dict(fields, magnitude=row.get("force"), when="always")
    when = row.get("when")
    if when not in _WHEN:
        row.fail(f"'when' must be one of {', '.join(_WHEN)}, got {when!r}")
    fields.update(when=when, zero_at=row.get("zero_at"))
    if fields["zero_at"] is not None and len(mech.inputs) != 1:
        row.fail("'zero_at' (an input value) needs a model with one input")
    if not isinstance(row.data.get("force"), list):
        if row.has("s") or row.has("stroke"):
            row.fail("with 's' the 'force' must be a list of the same length")
        return dict(fields, magnitude=row.number("force", required=True))
    table = row.numbers("force", required=True)
    s = row.numbers("s", required=True)
    if len(s) != len(table) or len(s) < 2:
        row.fail(f"'s' and 'force' must be lists of equal length (at least 2), got {len(s)} and {len(table)}")
    stroke = row.get("stroke")
    s = tuple(x * stroke * units.length_scale for x in s)
    if any(b <= a for a, b in zip(s, s[1:])):
        row.fail("'s' (times 'stroke') must increase strictly")
    _check_diagram_scale(mech, row, s, units)
    return dict(fields, s=s, table=table)


def _check_diagram_scale(mech, row: Row, s, units: Units):
    """Warn when a resistance diagram spans 1/100 of the drawing or less, or 100 times or more: a stroke
    written in metres in a mm table, or the reverse (`mbplanar.model._scale`)."""
    _warn_length(mech, row, "the s diagram spans", s[-1] - s[0], units, "is 's' or 'stroke' (s × stroke)")


def _warn_length(mech, row: Row, what: str, value: float, units: Units, which: str = "is it"):
    """A `ModelWarning` on `row` when the length `value` (m) is out of scale with the drawing."""
    size = drawing_size(mech)
    if out_of_scale(value, size):
        message = scale_message(what, value, size, units.length, units.length_scale)
        row.warn(message.replace(": is it in another unit?", f": {which} in another unit?"))


def _where_on(mech, row: Row, link: str, units: Units, kind: str, joint: str | None = None) -> dict:
    """Where a load acts: `at` = [x, y] (length unit) or a point or joint name on `link`; by default
    the joint's slider point (guide loads), else the link's centre, else (a moment) its first joint."""
    if isinstance(row.data.get("at"), list):
        x, y = row.pair("at")
        return {"at": (x * units.length_scale, y * units.length_scale)}
    name = row.text("at") if row.has("at") else None
    if name is None:
        if joint is not None:
            return {"point": joint}
        centre = mech.links[link].centre
        if centre is None and kind != "moment":
            row.fail(f"no 'at' and link '{link}' has no 'centre'")
        if centre is None and not mech.joints_of(link):
            row.fail(f"link '{link}' has no joint to put the moment on")
        return {"point": centre if centre is not None else mech.joints_of(link)[0].name}
    return {"point": _named_on(mech, row, link, name, f"'at' = '{name}'")}


# -- gravity and dynamics ----------------------------------------------------------------------------
def read_gravity_section(mech: Mechanism, raw) -> Gravity:
    """`[gravity]`: g (m/s², ≥ 0) and its direction (degrees, default −90)."""
    row = Row(raw, "gravity", mech.source, GRAVITY)
    g = row.get("g")
    if out_of_scale(g, 9.81):
        row.warn(f"g = {g:g} m/s² is {g / 9.81:.3g} times the earth's 9.81 m/s²: is it in another unit? "
                 "(g is in m/s² whatever the length_unit)")
    direction = row.get("direction")
    row.check_unknown_keys({"comment"})
    return Gravity(g, math.radians(direction))


def crank_input(mech: Mechanism, where: str = "dynamics") -> Input:
    """The one input of a machine driven by a crank: a revolute input joint with the ground.

    Machine dynamics (the energy–mass method, the flywheel) reduces a machine to its crank.

    Parameters
    ----------
    mech : Mechanism
        The model.
    where : str, optional
        The section the messages name (the one that needs the crank).

    Returns
    -------
    Input
        The crank's input.

    Raises
    ------
    ModelError
        The model has several inputs, or its input is not a revolute joint with the ground.

    Examples
    --------
    >>> from mbplanar.model import crank_input, read_model
    >>> crank_input(read_model("models/shaper.toml")).joint
    'O'
    >>> crank_input(read_model("models/five_bar.toml"))
    Traceback (most recent call last):
    mbplanar.errors.ModelError: models/five_bar.toml: dynamics: machine dynamics ... this model has 2 inputs ...
    """
    if len(mech.inputs) != 1:
        raise ModelError(f"machine dynamics (the energy–mass method, the flywheel) reduces a machine to its one "
                         f"crank; this model has {len(mech.inputs)} inputs "
                         f"({', '.join(i.name for i in mech.inputs)}): `mbplanar simulate` gives the motion of "
                         "a machine with several inputs", source=mech.source, where=where)
    inp = mech.inputs[0]
    if mech.joints[inp.joint].kind != "R" or mech.ground not in mech.joints[inp.joint].links:
        raise ModelError(f"machine dynamics needs a crank (a revolute input joint with the ground); "
                         f"input '{inp.joint}' is not one", source=mech.source, where=where)
    return inp


def read_dynamics_section(mech: Mechanism, raw) -> DynamicsSpec:
    """`[dynamics]` (and `[dynamics.flywheel]`) as a `DynamicsSpec` in SI units."""
    row = Row(raw, "dynamics", mech.source, DYNAMICS)
    inp = crank_input(mech)
    delta = row.get("delta")
    omega = rpm_or_omega(row, "omega_mean", "rpm_mean", inp.omega)
    if not omega > 0:
        row.fail(f"the mean speed (ω_m = {omega:g} rad/s) must be positive")
    units = mech.units
    driving = row.get("driving_moment")
    driving = None if driving is None else driving * units.moment_scale
    slope = row.get("motor_slope") * units.moment_scale
    fly = Row(row.raw("flywheel", {}), "dynamics.flywheel", mech.source, FLYWHEEL)
    link = fly.get("link")
    if link is not None:
        if link not in mech.links:
            fly.fail(f"'link' = '{link}' is not a moving link of the model")
        if fly.has("motor_rpm"):
            fly.fail("give either 'link' (the gears give its speed) or 'motor_rpm', not both")
    flywheel = FlywheelSpec(shaft_inertia=fly.get("shaft_inertia") * units.inertia_scale,
                            motor_rpm=fly.get("motor_rpm"),
                            motor_inertia=fly.get("motor_inertia") * units.inertia_scale,
                            density=fly.get("density"),
                            inertia=_scaled(fly.get("inertia"), units.inertia_scale), link=link)
    row.check_unknown_keys({"comment"})
    fly.check_unknown_keys({"comment"})
    return DynamicsSpec(delta, omega, driving, slope, flywheel)


def _scaled(value: float | None, scale: float) -> float | None:
    return None if value is None else value * scale
