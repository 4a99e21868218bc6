"""Writing a pair's tooth profiles: CSV (each gear in its own frame), DXF and SVG (both gears placed in
mesh), with the cam's writers (`mbplanar.cam.export.write_dxf_entities`, `svg_text`).

Placement (`mesh_placement`): gear 1's centre at the origin with a tooth pointing up at the pitch point
P = (0, r_w1); gear 2's centre at (0, a_w) above it (an internal gear 2: at (0, −a_w), below), turned so
that a tooth space of gear 2 faces P. At the working pitch circles the tooth of one fills the space of
the other exactly (s_w1 + s_w2 = p_w), so the two outlines touch without overlap.
"""

from __future__ import annotations

import math

import numpy as np

from ..cam.export import svg_text, write_dxf_entities

__all__ = ["mesh_placement", "placed", "write_csv", "write_dxf", "write_svg"]


def mesh_placement(pair) -> tuple:
    """((centre₁, turn₁), (centre₂, turn₂)): each gear's centre (m) and its counter-clockwise turn (rad)
    from its own frame (tooth 0's axis along +y) to the mesh."""
    g2 = pair.gears[1]
    if pair.internal:
        return ((0.0, 0.0), 0.0), ((0.0, -pair.centre_distance), math.pi / g2.teeth)
    return ((0.0, 0.0), 0.0), ((0.0, pair.centre_distance), math.pi + math.pi / g2.teeth)


def placed(points, centre, turn):
    """Points of a gear's own frame turned by `turn` and moved to `centre`."""
    c, s = math.cos(turn), math.sin(turn)
    return np.asarray(points, float) @ np.array([[c, s], [-s, c]]) + np.asarray(centre, float)


def write_csv(profiles, path) -> None:
    """One row per outline point: gear (1, 2), piece number, part (root, fillet, involute, tip), x and y
    (mm) in the gear's own frame (centre at the origin, tooth 0's axis along +y)."""
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("gear,piece,part,x[mm],y[mm]\n")
        for k, prof in enumerate(profiles, 1):
            for n, piece in enumerate(prof.pieces):
                for x, y in piece.points * 1e3:
                    fh.write(f"{k},{n},{piece.part},{x:.9g},{y:.9g}\n")


def _entities(pair, profiles):
    curves, arcs, circles, points = [], [], [], []
    for k, ((centre, turn), prof) in enumerate(zip(mesh_placement(pair), profiles), 1):
        layer = f"GEAR{k}"
        for piece in prof.pieces:
            if piece.kind == "arc":
                c = placed(np.array([piece.centre]), centre, turn)[0]
                arcs.append((layer, c, piece.radius, math.degrees(piece.start + turn), math.degrees(piece.end + turn)))
            else:
                curves.append((layer, placed(piece.points, centre, turn), False))
        g = pair.gears[k - 1]
        circles.append(("PITCH", centre, g.working_diameter / 2))
        points.append(("CENTRES", centre))
    return curves, arcs, circles, points


def write_dxf(pair, profiles, path) -> None:
    """Both gears in mesh (mm): each on its layer (GEAR1, GEAR2) as fit-point splines (flanks: fillet and
    involute) and arcs (root and tip circles); the working pitch circles (PITCH) and the centres (CENTRES)."""
    curves, arcs, circles, points = _entities(pair, profiles)
    write_dxf_entities(path, curves=curves, arcs=arcs, circles=circles, points=points)


def write_svg(pair, profiles, path, title: str = "gear pair") -> None:
    """Both gears in mesh (mm, y up): filled outlines, the working pitch circles dashed, the centres."""
    paths, dots = [], []
    colours = ("#dde6ee", "#f0e2cf")
    for k, ((centre, turn), prof) in enumerate(zip(mesh_placement(pair), profiles)):
        paths.append((placed(prof.outline, centre, turn), True, "none" if prof.internal else colours[k],
                      "#1a1a1a", 0.5, None))
        t = np.linspace(0, 2 * math.pi, 721)
        r = pair.gears[k].working_diameter / 2
        paths.append((np.c_[centre[0] + r * np.cos(t), centre[1] + r * np.sin(t)], True, "none", "#2a6fb0", 0.3,
                      (4.0, 2.0)))
        dots.append((centre, 1.5, "#b03a2e"))
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(svg_text(title, paths, dots))
