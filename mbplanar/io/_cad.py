"""CAD drawings: geometry on named layers, written as DXF (ezdxf, the optional extra `cad`) or plain SVG.

A `Sheet` collects entities (polylines with arc segments, fit-point splines, circles, points, lines,
texts) on named `Layer`s in one length unit; `write_dxf` and `write_svg` write it. The cam's profile
(`mbplanar.cam.export`) and the linkage's drawing (`mbplanar.formats.drawing`, in `mbplanar/formats/sheet.py`) are both written through
these two functions: there is one DXF writer and one SVG writer.

SVG has y down: the writer turns y over, and keeps texts upright. Each layer is a group `<g id=NAME>`
that Inkscape shows as a layer.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError

__all__ = ["Layer", "Sheet", "write_dxf", "write_svg", "require_ezdxf", "DXF_UNITS"]

DXF_UNITS = {"m": 6, "cm": 5, "mm": 4}   # the $INSUNITS codes (ezdxf.units.M, CM, MM)


@dataclass(frozen=True)
class Layer:
    """A layer of a `Sheet`: its name, its DXF colour and how SVG draws it.

    Attributes
    ----------
    name : str
        The layer's name (the DXF layer, the SVG group's id).
    colour : int
        The DXF colour (AutoCAD colour index: 1 red, 5 blue, 7 black/white).
    stroke, fill : str
        SVG's stroke and fill colours.
    width : float
        SVG's line width relative to the sheet's line width.
    dash : tuple of float
        SVG's dash pattern in line widths (empty: solid).

    Examples
    --------
    >>> from mbplanar.io import Layer, Sheet
    >>> sheet = Sheet(unit="mm").layer(Layer("centre lines", colour=1, stroke="#c00", dash=(6, 2)))
    >>> sheet.layers["centre lines"].dash
    (6, 2)
    """

    name: str
    colour: int = 7
    stroke: str = "#1a1a1a"
    fill: str = "none"
    width: float = 1.0
    dash: tuple = ()


@dataclass
class Sheet:
    """Entities on layers, in `unit` ("m", "cm", "mm"). Coordinates are (x, y) with y up.

    Entities are tuples (kind, layer, data): "polyline" (points (n, 2), closed, bulges (n,) or None: a
    bulge b on a vertex makes the segment to the next vertex an arc of 4·atan(b), counter-clockwise for
    b > 0), "spline" (fit points (n, 2), closed), "circle" (centre, radius), "point" (xy), "line" (a, b),
    "text" (xy, text, height; centred on xy). The methods of those names add them; a layer named there
    and not declared with `layer` is made with `Layer`'s defaults.

    Attributes
    ----------
    unit : str
        The drawing's length unit, "m", "cm" or "mm" (DXF's $INSUNITS, SVG's width and height).
    title : str
        SVG's title.
    layers : dict of str to Layer
        The layers, in the order they were declared.
    entities : list of tuple
        (kind, layer, data) in the order they were added.

    Examples
    --------
    A 40 mm disc with a slot whose ends are half circles (bulge 1: a 180° arc):

    >>> from mbplanar.io import Layer, Sheet
    >>> sheet = Sheet(unit="mm", title="plate").layer(Layer("outline", colour=7))
    >>> sheet.circle("outline", (0, 0), 20)
    >>> sheet.polyline("outline", [(-5, -2), (5, -2), (5, 2), (-5, 2)], closed=True, bulges=[0, 1, 0, 1])
    >>> sheet.text("labels", (0, -25), "plate", 3)
    >>> [kind for kind, _, _ in sheet.entities], list(sheet.layers), sheet.extent()
    (['circle', 'polyline', 'text'], ['outline', 'labels'], (array([-20., -25.]), array([20., 20.])))
    """

    unit: str = "mm"
    title: str = ""
    layers: dict = field(default_factory=dict)
    entities: list = field(default_factory=list)

    def layer(self, layer: Layer) -> "Sheet":
        self.layers[layer.name] = layer
        return self

    def _add(self, kind, layer, *data):
        if layer not in self.layers:
            self.layers[layer] = Layer(layer)
        self.entities.append((kind, layer, data))

    def polyline(self, layer, points, closed=False, bulges=None):
        self._add("polyline", layer, np.asarray(points, float).reshape(-1, 2), bool(closed),
                  None if bulges is None else np.asarray(bulges, float))

    def spline(self, layer, points, closed=False):
        self._add("spline", layer, np.asarray(points, float).reshape(-1, 2), bool(closed))

    def circle(self, layer, centre, radius):
        self._add("circle", layer, np.asarray(centre, float), float(radius))

    def point(self, layer, xy):
        self._add("point", layer, np.asarray(xy, float))

    def line(self, layer, a, b):
        self._add("line", layer, np.asarray(a, float), np.asarray(b, float))

    def text(self, layer, xy, text, height):
        self._add("text", layer, np.asarray(xy, float), str(text), float(height))

    def extent(self) -> tuple[np.ndarray, np.ndarray]:
        """(lower-left, upper-right) corners of every entity."""
        pts = []
        for kind, _, data in self.entities:
            if kind in ("polyline", "spline"):
                pts.append(data[0])
            elif kind == "circle":
                pts.append(data[0] + np.array([[-data[1], -data[1]], [data[1], data[1]]]))
            elif kind in ("point", "text"):
                pts.append(data[0][None])
            else:
                pts.append(np.stack(data))
        xy = np.concatenate(pts) if pts else np.zeros((1, 2))
        xy = xy[np.all(np.isfinite(xy), axis=1)]
        return xy.min(axis=0), xy.max(axis=0)


def require_ezdxf():
    """The ezdxf module (the optional extra ``cad``), imported on first use.

    Returns
    -------
    module
        ezdxf.

    Raises
    ------
    ModelError
        ezdxf is not installed: the message says ``pip install 'mbplanar[cad]'``.

    Examples
    --------
    >>> from mbplanar.io import require_ezdxf
    >>> require_ezdxf().__name__
    'ezdxf'
    """
    try:
        import ezdxf
    except ImportError:
        raise ModelError("DXF export needs ezdxf: pip install 'mbplanar[cad]'") from None
    return ezdxf


def write_dxf(sheet: Sheet, path) -> None:
    """The sheet as a DXF (R2010) drawing in its unit, one DXF layer per layer: polylines as LWPOLYLINE
    with their bulges, splines through their fit points, circles, points, lines and centred texts.

    Parameters
    ----------
    sheet : Sheet
        The drawing.
    path : str or path-like
        The file to write.

    Returns
    -------
    None

    Raises
    ------
    ModelError
        ezdxf is not installed (`require_ezdxf`).
    OSError
        The file cannot be written.

    Examples
    --------
    >>> import pathlib, tempfile, ezdxf
    >>> from mbplanar.io import Sheet, write_dxf
    >>> sheet = Sheet(unit="mm")
    >>> sheet.circle("outline", (0, 0), 20)
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "plate.dxf"
    >>> write_dxf(sheet, path)
    >>> [(e.dxftype(), e.dxf.layer, e.dxf.radius) for e in ezdxf.readfile(path).modelspace()]
    [('CIRCLE', 'outline', 20.0)]
    """
    ezdxf = require_ezdxf()
    from ezdxf.enums import TextEntityAlignment
    doc = ezdxf.new("R2010")
    doc.units = DXF_UNITS[sheet.unit]
    msp = doc.modelspace()
    for layer in sheet.layers.values():
        doc.layers.add(layer.name, color=layer.colour)
    for kind, layer, data in sheet.entities:
        attribs = {"layer": layer}
        if kind == "polyline":
            points, closed, bulges = data
            b = np.zeros(len(points)) if bulges is None else bulges
            msp.add_lwpolyline([(x, y, bb) for (x, y), bb in zip(points, b)], format="xyb", close=closed,
                               dxfattribs=attribs)
        elif kind == "spline":
            points, closed = data
            loop = np.vstack([points, points[:1]]) if closed else points   # the first point again closes it
            spline = msp.add_spline(fit_points=[(x, y, 0.0) for x, y in loop], dxfattribs=attribs)
            spline.closed = closed
        elif kind == "circle":
            msp.add_circle(tuple(data[0]), data[1], dxfattribs=attribs)
        elif kind == "point":
            msp.add_point(tuple(data[0]), dxfattribs=attribs)
        elif kind == "line":
            msp.add_line(tuple(data[0]), tuple(data[1]), dxfattribs=attribs)
        else:
            xy, text, height = data
            msp.add_text(text, height=height, dxfattribs=attribs).set_placement(
                tuple(xy), align=TextEntityAlignment.MIDDLE_CENTER)
    doc.saveas(path)


def _escape(text) -> str:
    return str(text).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;")


def _svg_path(points, closed, bulges) -> str:
    """An SVG path (y turned over) through `points`, arcs where a bulge is given."""
    p = points * np.array([1.0, -1.0])
    out = [f"M {p[0, 0]:.9g},{p[0, 1]:.9g}"]
    n = len(p)
    for k in range(n if closed else n - 1):
        a, b = p[k], p[(k + 1) % n]
        bulge = 0.0 if bulges is None else float(bulges[k])
        if bulge == 0.0:
            out.append(f"L {b[0]:.9g},{b[1]:.9g}")
            continue
        chord = float(np.hypot(*(b - a)))
        radius = chord * (1 + bulge * bulge) / (4 * abs(bulge))
        large = 1 if abs(bulge) > 1 else 0
        sweep = 0 if bulge > 0 else 1        # counter-clockwise in y up is clockwise on the turned page
        out.append(f"A {radius:.9g},{radius:.9g} 0 {large} {sweep} {b[0]:.9g},{b[1]:.9g}")
    if closed:
        out.append("Z")
    return " ".join(out)


def write_svg(sheet: Sheet, path) -> None:
    """The sheet as a plain SVG document in its unit (width and height in it), y up, one group per layer
    (an Inkscape layer), 5 % of the drawing's size as a margin.

    Parameters
    ----------
    sheet : Sheet
        The drawing.
    path : str or path-like
        The file to write (UTF-8).

    Returns
    -------
    None

    Raises
    ------
    OSError
        The file cannot be written.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from mbplanar.io import Sheet, write_svg
    >>> sheet = Sheet(unit="mm")
    >>> sheet.line("outline", (0, 0), (100, 0))
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "line.svg"
    >>> write_svg(sheet, path)
    >>> text = path.read_text()
    >>> 'width="110mm"' in text, '<line x1="0" y1="-0" x2="100" y2="-0"/>' in text
    (True, True)
    """
    lo, hi = sheet.extent()
    span = float(np.max(hi - lo)) or 1.0
    pad = 0.05 * span
    x0, y0 = lo[0] - pad, -(hi[1] + pad)
    w, h = hi[0] - lo[0] + 2 * pad, hi[1] - lo[1] + 2 * pad
    stroke = 0.003 * max(w, h)
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" '
             f'xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" '
             f'viewBox="{x0:.9g} {y0:.9g} {w:.9g} {h:.9g}" width="{w:.6g}{sheet.unit}" height="{h:.6g}{sheet.unit}">']
    if sheet.title:
        parts.append(f"<title>{_escape(sheet.title)}</title>")
    for layer in sheet.layers.values():
        style = (f'fill="{layer.fill}" stroke="{layer.stroke}" stroke-width="{layer.width * stroke:.6g}"'
                 + (f' stroke-dasharray="{" ".join(f"{d * stroke:.6g}" for d in layer.dash)}"' if layer.dash else ""))
        body = []
        for kind, name, data in sheet.entities:
            if name != layer.name:
                continue
            if kind == "polyline":
                body.append(f'<path d="{_svg_path(*data)}"/>')
            elif kind == "spline":
                body.append(f'<path d="{_svg_path(data[0], data[1], None)}"/>')
            elif kind == "circle":
                body.append(f'<circle cx="{data[0][0]:.9g}" cy="{-data[0][1]:.9g}" r="{data[1]:.9g}"/>')
            elif kind == "point":
                body.append(f'<circle cx="{data[0][0]:.9g}" cy="{-data[0][1]:.9g}" r="{2 * stroke:.6g}" '
                            f'fill="{layer.stroke}" stroke="none"/>')
            elif kind == "line":
                a, b = data
                body.append(f'<line x1="{a[0]:.9g}" y1="{-a[1]:.9g}" x2="{b[0]:.9g}" y2="{-b[1]:.9g}"/>')
            else:
                xy, text, height = data
                body.append(f'<text x="{xy[0]:.9g}" y="{-xy[1]:.9g}" font-size="{height:.6g}" '
                            f'text-anchor="middle" dominant-baseline="central" fill="{layer.stroke}" '
                            f'stroke="none" font-family="sans-serif">{_escape(text)}</text>')
        if body:
            parts.append(f'<g id="{_escape(layer.name)}" inkscape:groupmode="layer" '
                         f'inkscape:label="{_escape(layer.name)}" {style}>')
            parts += body
            parts.append("</g>")
    parts.append("</svg>")
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("\n".join(parts) + "\n")

