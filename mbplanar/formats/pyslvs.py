"""Pyslvs: its mechanism expression and its YAML project.

The expression (Pyslvs' "mechanism expression", written by the program and by hand) lists the points
of a mechanism, each a joint on some links::

    M[
      J[R, color[Green], P[0.0, 0.0], L[ground, L1]],
      J[R, P[12.92, 32.53], L[L1, L2]],
      J[P, A[30.0], P[51.38, -12.63], L[ground, L2]],
      J[RP, A[0.0], P[11.88, 0.0], L[ground, L2, L3]],
    ]

`R` is a revolute pin joining every link listed (one link: a point on it); `P` and `RP` are sliders
whose first link carries the slot, at the angle `A[deg]` in the drawing: with `P` the next link slides
without turning, with `RP` the links turn on a pin that slides in the slot. `ground` is the frame.
`# ...` and `#[ ... #]` are comments. A YAML project (``.pyslvs``, ``.yml``; plain or "compressed" YAML)
holds the expression under `mechanism`, the links' colours under `links` and the input pairs under
`input`: [base point, drive point] indices, the base a ground pivot whose link turns with the line to
the drive point, or a slider's own index twice (its offset).

Pyslvs stores no unit: the lengths are taken as millimetres. Colours are not carried over.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import ModelError
from ._sketch import Sketch, Slide

__all__ = ["Joint", "parse_expression", "read_expression", "read_project"]

FRAME = "ground"  # Pyslvs' name of the frame link


@dataclass(frozen=True)
class Joint:
    """One `J[...]` of an expression: type ("R", "P", "RP"), slider angle (deg), colour, x, y, links."""

    type: str
    angle: float | None
    color: str | None
    x: float
    y: float
    links: tuple


class _Reader:
    """A small recursive-descent reader of the expression grammar, with errors that name the place."""

    def __init__(self, text: str, source: str):
        self.text, self.source, self.pos = text, source, 0

    def fail(self, what: str):
        line = self.text.count("\n", 0, self.pos) + 1
        column = self.pos - (self.text.rfind("\n", 0, self.pos) + 1) + 1
        found = self.text[self.pos:self.pos + 12].split("\n")[0]
        raise ModelError(f"Pyslvs expression, line {line}, column {column}: expected {what}, found "
                         f"{found!r}" if found else f"Pyslvs expression, line {line}, column {column}: expected "
                         f"{what}, found the end", source=self.source)

    def skip(self):
        text = self.text
        while self.pos < len(text):
            c = text[self.pos]
            if c.isspace():
                self.pos += 1
            elif text.startswith("#[", self.pos):           # a block comment, up to '#]'
                end = text.find("#]", self.pos + 2)
                if end < 0:
                    self.fail("'#]' closing the comment")
                self.pos = end + 2
            elif c == "#":
                end = text.find("\n", self.pos)
                self.pos = len(text) if end < 0 else end
            else:
                return

    def peek(self, literal: str) -> bool:
        self.skip()
        return self.text.startswith(literal, self.pos)

    def expect(self, literal: str):
        if not self.peek(literal):
            self.fail(f"'{literal}'")
        self.pos += len(literal)

    def take(self, literal: str) -> bool:
        if self.peek(literal):
            self.pos += len(literal)
            return True
        return False

    def number(self) -> float:
        self.skip()
        start = self.pos
        text = self.text
        if self.pos < len(text) and text[self.pos] in "+-":
            self.pos += 1
        digits = self.pos
        while self.pos < len(text) and (text[self.pos].isdigit() or text[self.pos] == "."):
            self.pos += 1
        if self.pos < len(text) and text[self.pos] in "eE" and self.pos > digits:
            self.pos += 1
            if self.pos < len(text) and text[self.pos] in "+-":
                self.pos += 1
            while self.pos < len(text) and text[self.pos].isdigit():
                self.pos += 1
        try:
            value = float(text[start:self.pos])
        except ValueError:
            self.pos = start
            self.fail("a number")
        if not math.isfinite(value):
            self.pos = start
            self.fail("a finite number")
        return value

    def name(self) -> str:
        self.skip()
        start, text = self.pos, self.text
        if self.pos < len(text) and (text[self.pos].isalpha() or text[self.pos] == "_") and text[self.pos].isascii():
            self.pos += 1
            while self.pos < len(text) and (text[self.pos].isalnum() or text[self.pos] == "_") and text[self.pos].isascii():
                self.pos += 1
            return text[start:self.pos]
        self.fail("a name (letters, digits, _)")

    def joint(self) -> Joint:
        self.expect("J[")
        for kind in ("RP", "R", "P"):
            if self.take(kind):
                break
        else:
            self.fail("a joint type R, P or RP")
        angle = color = None
        self.expect(",")
        if self.take("A["):
            angle = self.number()
            self.expect("]")
            self.expect(",")
        if self.take("color["):
            if self.take("("):
                rgb = [self.number()]
                for _ in range(2):
                    self.expect(",")
                    rgb.append(self.number())
                self.expect(")")
                color = "(" + ", ".join(f"{v:g}" for v in rgb) + ")"
            else:
                color = self.name()
            self.expect("]")
            self.expect(",")
        self.expect("P[")
        x = self.number()
        self.expect(",")
        y = self.number()
        self.expect("]")
        self.expect(",")
        self.expect("L[")
        links = []
        while not self.take("]"):
            links.append(self.name())
            if not self.take(","):
                self.expect("]")
                break
        self.expect("]")
        if kind != "R" and angle is None:
            self.fail(f"A[angle] after the type of a {kind} joint")
        return Joint(kind, angle, color, x, y, tuple(links))

    def mechanism(self) -> list[Joint]:
        self.expect("M[")
        joints = []
        while not self.take("]"):
            joints.append(self.joint())
            if not self.take(","):
                self.expect("]")
                break
        self.skip()
        if self.pos != len(self.text):
            self.fail("the end of the expression")
        return joints


def parse_expression(text: str, source: str = "<expression>") -> list[Joint]:
    """The joints of a Pyslvs mechanism expression, or a `ModelError` naming the line and column."""
    return _Reader(text, source).mechanism()


def _sketch(joints: list[Joint], source: str, name: str, pairs) -> Sketch:
    sk = Sketch(source, name, title=f"{name} (imported from Pyslvs)", unit="mm", ground=FRAME)
    sk.notes.append("Pyslvs stores no unit: lengths taken as mm")
    if any(j.color for j in joints):
        sk.notes.append("colours are not carried over")
    slide_of = {}
    for i, j in enumerate(joints):
        p = f"P{i}"
        sk.points[p] = (j.x, j.y)
        links = list(dict.fromkeys(j.links))
        if len(links) < len(j.links):
            sk.notes.append(f"point {p} lists a link twice: once kept")
        for link in links:
            sk.bodies.setdefault(link, [])
        if j.type == "R":
            if j.angle is not None:
                sk.notes.append(f"point {p}: the angle of a revolute joint means nothing; left out")
            for link in links:
                sk.bodies[link].append(p)
            continue
        if len(links) < 2:
            raise ModelError(f"Pyslvs point {i} ({j.type} joint at ({j.x:g}, {j.y:g})): a slider needs its slot's "
                             f"link and at least one link on the pin, it lists {links or 'none'}", source=source)
        for link in links[1:]:
            sk.bodies[link].append(p)
        slide_of[i] = len(sk.slides)
        sk.slides.append(Slide(p, links[0], links[1:], guide_deg=j.angle, turns=j.type == "RP"))
        if j.type == "P" and len(links) > 2:
            sk.notes.append(f"point {p}: a P joint on {len(links) - 1} links: {links[1]} slides on {links[0]}, "
                            f"the others turn on {links[1]} at the pin")
    if pairs is None:
        pairs = _guess_inputs(joints, sk)
    for base, drive in pairs:
        for k in (base, drive):
            if not (isinstance(k, int) and not isinstance(k, bool) and 0 <= k < len(joints)):
                raise ModelError(f"Pyslvs input pair [{base}, {drive}]: {k!r} is not a point of the expression "
                                 f"(0 … {len(joints) - 1})", source=source)
        if base == drive:
            if base not in slide_of:
                raise ModelError(f"Pyslvs input pair [{base}, {drive}]: point {base} is not a slider", source=source)
            sk.inputs.append(("P", slide_of[base]))
            continue
        if joints[base].type != "R":
            raise ModelError(f"Pyslvs input pair [{base}, {drive}]: the base point {base} is a slider; a "
                             "slider's input names it twice", source=source)
        common = [link for link in joints[base].links if link in joints[drive].links and link != FRAME]
        if not common:
            raise ModelError(f"Pyslvs input pair [{base}, {drive}]: points {base} and {drive} share no moving link",
                             source=source)
        sk.inputs.append(("R", f"P{base}", common[0], f"P{drive}"))
    return sk


def _guess_inputs(joints: list[Joint], sk: Sketch) -> list:
    """As many ground pivots as the chain's degrees of freedom (Pyslvs' count), first ones first, each
    turning its first moving link, measured towards that link's next point."""
    links = {FRAME} | {link for j in joints if len(j.links) >= 2 for link in j.links}
    j1 = sum(len(j.links) - (2 if j.type == "RP" else 1) for j in joints if len(j.links) >= 2)
    j2 = sum(1 for j in joints if j.type == "RP" and len(j.links) >= 2)
    dof = 3 * (len(links) - 1) - 2 * j1 - j2
    pairs, turned, guessed = [], set(), []
    for i, j in enumerate(joints):
        if len(pairs) >= dof:
            break
        moving = [link for link in j.links if link != FRAME]
        if j.type != "R" or FRAME not in j.links or not moving or moving[0] in turned:
            continue
        other = next((k for k, o in enumerate(joints) if k != i and moving[0] in o.links), None)
        if other is None:
            continue
        turned.add(moving[0])
        pairs.append((i, other))
        guessed.append(f"ground pivot P{i} turns link {moving[0]}")
    if pairs:
        sk.notes.append(f"the expression names no input: {', '.join(guessed)} (guessed; a YAML project's "
                        "'input' says it)")
    return pairs


def read_expression(text: str, source: str, name: str) -> Sketch:
    """The sketch of an expression (no inputs: guessed from the ground pivots, with a note)."""
    return _sketch(parse_expression(text, source), source, name, None)


def read_project(text: str, source: str, name: str) -> Sketch:
    """The sketch of a Pyslvs YAML project (needs PyYAML: ``pip install 'mbplanar[yaml]'``)."""
    try:
        import yaml
    except ImportError:
        raise ModelError("reading a Pyslvs YAML project needs PyYAML: pip install 'mbplanar[yaml]'",
                         source=source) from None
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        raise ModelError(f"YAML syntax error{where}: {getattr(exc, 'problem', None) or exc}", source=source) from None
    if not isinstance(data, dict) or not isinstance(data.get("mechanism", "M[]"), str):
        raise ModelError("not a Pyslvs project: expected a mapping with a 'mechanism' expression", source=source)
    expression = data.get("mechanism", "M[]")
    pairs = data.get("input", None)
    if pairs is not None:
        if not isinstance(pairs, list) or not all(isinstance(p, list) and len(p) >= 2 for p in pairs):
            raise ModelError(f"Pyslvs project: 'input' must be a list of [base, drive] point pairs, got {pairs!r}",
                             source=source)
        pairs = [(p[0], p[1]) for p in pairs] or None
    sk = _sketch(parse_expression(expression, source), source, name, pairs)
    dropped = sorted(set(data) - {"mechanism", "input", "links", "pyslvs_ver", "file_type"})
    if dropped:
        sk.notes.append(f"not carried over: the project's {', '.join(dropped)}")
    return sk
