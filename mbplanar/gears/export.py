"""Writing a pair's tooth profiles: CSV (each gear in its own frame), DXF and SVG (both gears placed in
mesh), through mbplanar's one CAD writer (`mbplanar.io._cad`: a `Sheet` of layers, `write_dxf`,
`write_svg`).

Placement (`mesh_placement`): gear 1's centre at the origin with a tooth pointing up at the pitch point
P = (0, r_w1); gear 2's centre at (0, a_w) above it (an internal gear 2: at (0, −a_w), below), turned so
that a tooth space of gear 2 faces P. At the working pitch circles the tooth of one fills the space of
the other exactly (s_w1 + s_w2 = p_w), so the two outlines touch without overlap.
"""

from __future__ import annotations

import math

import numpy as np

from ..io import Layer, Sheet
from ..io import write_dxf as cad_dxf
from ..io import write_svg as cad_svg

__all__ = ["mesh_placement", "placed", "write_csv", "write_dxf", "write_svg"]

_LAYERS = (Layer("GEAR1", 7, "#1a1a1a", "#dde6ee", width=0.5), Layer("GEAR2", 7, "#1a1a1a", "#f0e2cf", width=0.5),
           Layer("PITCH", 5, "#2a6fb0", width=0.3, dash=(4, 2)), Layer("CENTRES", 1, "#b03a2e"))


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


def _sheet(pair, profiles, title, exact: bool) -> Sheet:
    """Both gears in mesh, in mm: with `exact`, each flank a fit-point spline and each root or tip arc a
    polyline segment with its bulge (tan of a quarter of its sweep); else each outline a closed polygon
    (for a filled SVG). The working pitch circles and the centres on their layers."""
    sheet = Sheet("mm", title)
    for layer in _LAYERS:
        sheet.layer(layer)
    if pair.internal:                                         # a ring's outline bounds its hollow: not filled
        sheet.layer(Layer("GEAR2", 7, "#1a1a1a", "none", width=0.5))
    for k, ((centre, turn), prof) in enumerate(zip(mesh_placement(pair), profiles), 1):
        layer = f"GEAR{k}"
        if not exact:
            sheet.polyline(layer, placed(prof.outline, centre, turn) * 1e3, closed=True)
        for piece in prof.pieces if exact else ():
            if piece.kind == "arc":
                c = placed(np.array([piece.centre]), centre, turn)[0]
                ends = c + piece.radius * np.array([[math.cos(piece.start + turn), math.sin(piece.start + turn)],
                                                    [math.cos(piece.end + turn), math.sin(piece.end + turn)]])
                sheet.polyline(layer, ends * 1e3, bulges=[math.tan((piece.end - piece.start) / 4), 0.0])
            else:
                sheet.spline(layer, placed(piece.points, centre, turn) * 1e3)
        sheet.circle("PITCH", np.asarray(centre) * 1e3, pair.gears[k - 1].working_diameter / 2 * 1e3)
        sheet.point("CENTRES", np.asarray(centre) * 1e3)
    return sheet


def write_dxf(pair, profiles, path) -> None:
    """Both gears in mesh (mm): on layers GEAR1 and GEAR2 each flank (fillet, involute) a fit-point spline
    through its generated points and each root or tip arc a polyline with a bulge; the working pitch
    circles (PITCH) and the centres (CENTRES)."""
    cad_dxf(_sheet(pair, profiles, "", exact=True), path)


def write_svg(pair, profiles, path, title: str = "gear pair") -> None:
    """Both gears in mesh (mm, y up): filled outlines, the working pitch circles dashed, the centres."""
    cad_svg(_sheet(pair, profiles, title, exact=False), path)
