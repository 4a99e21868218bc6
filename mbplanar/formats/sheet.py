"""The mechanism at one position as CAD geometry: links, joints, guides, ground, paths and labels on named
layers, in the model's length unit, written as DXF (ezdxf) or SVG by `mbplanar.io._cad`.

The shapes are those of the kinematic diagram (`mbplanar.viz._scene.build_scene`, the figures' and the
animation's): a link with two attachment points is an outline of two semicircles joined by two lines
around its centre line, a link with three or more a polygon through them, a slider a block on its guide.
Every revolute pair is a circle centred on its solved position (the coordinates ``mbplanar solve``
prints, converted to the model's unit); the paths are polylines of chosen points over the input's
sweep.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError, MotionError
from ..io import Layer, Sheet, require_ezdxf, write_dxf, write_svg

__all__ = ["LAYERS", "drawing", "export_drawing", "sweep_values"]

#: the layers, in drawing order: (name, AutoCAD colour index, SVG stroke, SVG fill, relative width)
LAYERS = (Layer("GROUND", 8, "#6b6b6b", width=0.8), Layer("GUIDES", 3, "#2e7d32", width=0.8),
          Layer("PATHS", 5, "#2a6fb0", width=0.8), Layer("LINKS", 7, "#1a1a1a", "#e8edf2", 1.2),
          Layer("JOINTS", 1, "#b03a2e", "#ffffff", 1.0), Layer("LABELS", 7, "#1a1a1a", width=0.5))
#: the layer of the higher pairs (a model with gears, racks, cams or slots)
PAIRS = Layer("PAIRS", 6, "#7a4f9a", width=0.8)


def sweep_values(engine, phi, steps: int) -> np.ndarray:
    """Input values (SI, (steps + 1, n_in)) over the main input's default range (`Input.sweep`, a full
    turn for a crank), the other inputs held at `phi`."""
    inp = engine.inputs[0]
    lo, hi = inp.default_sweep()
    values = np.tile(np.asarray(phi, float), (steps + 1, 1))
    values[:, 0] = np.linspace(inp.to_si(lo), inp.to_si(hi), steps + 1)
    return values


def _stadium(a, b, half):
    """Vertices and bulges of the outline round the segment a→b: two lines and two semicircles."""
    d = b - a
    n = np.array([-d[1], d[0]]) / max(float(np.hypot(*d)), 1e-300) * half
    return np.array([a - n, b - n, b + n, a + n]), np.array([0.0, 1.0, 0.0, 1.0])


def _runs(phi: np.ndarray, step: float) -> list[slice]:
    """The runs of consecutive reached positions (a dropped row, past a motion limit, ends a run)."""
    if len(phi) == 0:
        return []
    cut = np.flatnonzero(np.abs(np.diff(phi)) > 1.5 * step) + 1
    edges = [0, *cut, len(phi)]
    return [slice(a, b) for a, b in zip(edges[:-1], edges[1:]) if b - a >= 2]


def drawing(engine, phi, paths=(), steps: int = 360) -> Sheet:
    """The mechanism at one position as CAD geometry on named layers, in the model's length unit.

    Links as lines and outlines, joints as circles, the ground hatched, labels, and the paths of
    chosen points over the main input's sweep.

    Parameters
    ----------
    engine : Engine
        The model.
    phi : (n_in,) array_like
        Input values, SI, one per input.
    paths : sequence of str
        Joints or points whose paths are drawn.
    steps : int
        Intervals of the sweep for the paths.

    Returns
    -------
    Sheet
        `entities`: (kind, layer, data) rows on the layers LINKS, JOINTS, GROUND, LABELS, PATHS, ...

    Raises
    ------
    MotionError
        A position the model cannot reach on its drawn branch.
    ModelError
        A path asked of a name that is neither a joint nor a point.

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> from mbplanar.formats import drawing
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> sheet = drawing(engine, np.radians([30.0]), paths=["M"])
    >>> sorted({layer for _, layer, _ in sheet.entities})
    ['GROUND', 'JOINTS', 'LABELS', 'LINKS', 'PATHS']
    """
    from ..kinematics import analyse
    from ..viz import build_scene
    mech = engine.mech
    phi = np.asarray(phi, float).reshape(1, -1)
    motion = analyse(engine, phi, rates=False)
    if not motion.success or len(motion.phi) == 0:
        raise MotionError(f"{mech.source}: cannot reach the position asked on the drawn branch: {motion.message}")
    for name in paths:
        if name not in mech.joints and name not in mech.points:
            raise ModelError(f"no joint or point '{name}' to draw the path of", source=mech.source)
    sweep = sweep_values(engine, phi[0], steps)
    cycle = analyse(engine, sweep, rates=False) if steps else None
    scene = build_scene(engine, motion, cycle)
    unit = mech.units.length_scale                  # drawn in the model's length unit
    size = scene.size / unit
    r = 0.025 * size                                # a joint circle's radius
    sheet = Sheet(mech.units.length, mech.title or mech.name)
    for layer in LAYERS:
        sheet.layer(layer)
    if scene.pairs:   # the higher pairs: pitch circles, racks, profiles, followers, slots; tooth marks
        sheet.layer(PAIRS)
        for pair in scene.pairs:
            for _, _, line, closed in pair.lines:
                points = line[0] / unit
                sheet.polyline("PAIRS", points[:-1] if closed else points, closed=closed)
            for a, b in pair.marks[0] / unit:
                sheet.line("PAIRS", a, b)
    for link in scene.links:
        outline = link.outline[0] / unit
        if link.kind == "bar":
            vertices, bulges = _stadium(outline[0], outline[1], 1.6 * r)
            sheet.polyline("LINKS", vertices, closed=True, bulges=bulges)
        elif link.kind == "polygon":
            sheet.polyline("LINKS", outline, closed=True)
        for a, b in link.stubs[0] / unit:
            sheet.line("LINKS", a, b)
        if np.all(np.isfinite(link.label[0])):
            sheet.text("LABELS", link.label[0] / unit, link.name, 1.1 * r)
    for s in scene.sliders:
        sheet.polyline("LINKS", s.corners[0] / unit, closed=True)
        a, b = s.guide[0] / unit
        sheet.line("GUIDES", a, b)
        if s.grounded:
            _hatch(sheet, a, b, r)
    xy = {name: scene.joint_xy[0, k] / unit for k, name in enumerate(scene.joint_names)}
    for name in scene.pivots:
        _pivot(sheet, xy[name], r)
    for name in scene.revolute:
        sheet.circle("JOINTS", xy[name], r)
    for k, name in enumerate(scene.point_names):
        if name not in scene.centres:
            sheet.circle("JOINTS", scene.point_xy[0, k] / unit, 0.4 * r)
    for name, text in scene.labels.items():
        if text:
            sheet.text("LABELS", xy[name] + np.array([1.6 * r, 1.6 * r]), text, 1.1 * r)
    for k, name in enumerate(scene.point_names):
        if name not in scene.centres:
            sheet.text("LABELS", scene.point_xy[0, k] / unit + np.array([1.6 * r, 1.6 * r]), name, 1.1 * r)
    if cycle is not None and paths:
        step = abs(sweep[1, 0] - sweep[0, 0])
        inp = engine.inputs[0]
        full = inp.unit in ("deg", "rad") and np.isclose(abs(np.subtract(*inp.default_sweep())),
                                                         360.0 if inp.unit == "deg" else 2 * math.pi)
        for name in paths:
            pts = cycle.xy[:, cycle.point(name)] / unit
            runs = _runs(cycle.phi[:, 0], step)
            whole = full and len(runs) == 1 and len(cycle.phi) == steps + 1
            for run in runs:
                sheet.polyline("PATHS", pts[run][:-1] if whole else pts[run], closed=whole)
    return sheet


def _pivot(sheet: Sheet, at, r):
    """A ground pivot's symbol below the joint: a triangle on a hatched base."""
    x, y = at
    base = y - 2.6 * r
    sheet.polyline("GROUND", [(x - 1.2 * r, base), (x + 1.2 * r, base), (x, y - r)], closed=True)
    sheet.line("GROUND", (x - 2.0 * r, base), (x + 2.0 * r, base))
    for k in range(5):
        sx = x - 2.0 * r + k * r
        sheet.line("GROUND", (sx, base), (sx - 0.8 * r, base - 0.8 * r))


def _hatch(sheet: Sheet, a, b, r):
    """Short hatch lines on the right of a ground guide a→b."""
    d = b - a
    length = float(np.hypot(*d))
    if length == 0:
        return
    u = d / length
    n = np.array([u[1], -u[0]])                     # the right-hand side
    count = max(2, int(length / (1.5 * r)))
    for t in np.linspace(0.0, length, count):
        p = a + t * u + 1.0 * r * n
        sheet.line("GROUND", p, p + 0.8 * r * (n - u))


def export_drawing(engine, phi, path, paths=(), steps: int = 360) -> Sheet:
    """Write the mechanism's drawing at one position to a DXF or SVG file (``mbplanar export``).

    Parameters
    ----------
    engine : Engine
        The model.
    phi : (n_in,) array_like
        Input values, SI, one per input.
    path : str or Path
        A .dxf file (needs ezdxf, the ``cad`` extra) or an .svg file.
    paths : sequence of str
        Joints or points whose paths are drawn.
    steps : int
        Intervals of the sweep for the paths.

    Returns
    -------
    Sheet
        What was written (see `drawing`).

    Raises
    ------
    ModelError
        Another suffix, ezdxf missing for a DXF, or a path of an unknown name.
    MotionError
        A position the model cannot reach.

    Examples
    --------
    >>> import os, tempfile, numpy as np, mbplanar
    >>> from mbplanar.formats import export_drawing
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> path = os.path.join(tempfile.mkdtemp(), "fourbar.svg")
    >>> _ = export_drawing(engine, np.radians([30.0]), path, paths=["M"])
    >>> "<svg" in open(path, encoding="utf-8").read()
    True
    """
    suffix = str(path).lower().rsplit(".", 1)[-1]
    if suffix not in ("dxf", "svg"):
        raise ModelError(f"the drawing is written as .dxf or .svg, not '{path}'")
    if suffix == "dxf":
        require_ezdxf()                             # (before the work)
    sheet = drawing(engine, phi, paths, steps)
    (write_dxf if suffix == "dxf" else write_svg)(sheet, path)
    return sheet
