"""Writing the profile: CSV (pitch and working profile in mm, the seed's x.txt and y.txt), DXF (closed
splines through the points, ezdxf; optional extra `cad`) and SVG (hand-written text).

`write_dxf_entities` and `svg_text` are the writers themselves (layers of fit-point splines, arcs,
circles and points; filled or dashed paths and dots); the cam's files and the gears' (`mbplanar.gears`)
are made with them."""

from __future__ import annotations

import math

import numpy as np

from ..errors import MbplanarError
from .geometry import CamGeometry

__all__ = ["write_csv", "write_dxf", "read_dxf_points", "write_svg", "dxf_deviation", "dxf_chordal_error",
           "write_dxf_entities", "svg_text", "require_ezdxf"]


def write_csv(geometry: CamGeometry, path) -> None:
    """One row per cam angle: angle (deg), lift (mm), pitch x, y and profile x, y (mm, cam frame)."""
    g = geometry
    pitch = g.pitch if g.pitch is not None else np.full_like(g.profile, np.nan)
    cols = np.column_stack([np.degrees(g.phi), g.s * 1e3, pitch * 1e3, g.profile * 1e3,
                            np.degrees(g.pressure), g.rho_profile * 1e3])
    header = "angle[deg],s[mm],pitch_x[mm],pitch_y[mm],profile_x[mm],profile_y[mm],pressure[deg],rho[mm]"
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(header + "\n")
        for row in cols:
            fh.write(",".join("" if not math.isfinite(x) else f"{x:.9g}" for x in row) + "\n")


def require_ezdxf():
    """The ezdxf module, or an `MbplanarError` saying how to install it."""
    try:
        import ezdxf
    except ImportError:
        raise MbplanarError("DXF export needs ezdxf: pip install 'mbplanar[cad]'") from None
    return ezdxf


def write_dxf_entities(path, curves=(), arcs=(), circles=(), points=()) -> None:
    """A DXF file (R2010, millimetres) of entities given in metres, each on its layer.

    Parameters
    ----------
    path : str or Path
    curves : iterable of (layer, points (N, 2), closed)
        fit-point splines; a closed one repeats its first point at the end.
    arcs : iterable of (layer, centre (2,), radius, start_deg, end_deg)
        counter-clockwise from `start_deg` to `end_deg`.
    circles : iterable of (layer, centre (2,), radius)
    points : iterable of (layer, (x, y))
    """
    ezdxf = require_ezdxf()
    doc = ezdxf.new("R2010")
    doc.units = ezdxf.units.MM
    msp = doc.modelspace()

    def layer(name):
        if name not in doc.layers:
            doc.layers.add(name)
        return {"layer": name}

    for name, pts, closed in curves:
        pts = np.asarray(pts, float) * 1e3
        if closed:
            pts = np.vstack([pts, pts[:1]])               # the first point repeated closes the curve
        spline = msp.add_spline(fit_points=[(x, y, 0.0) for x, y in pts], dxfattribs=layer(name))
        if closed:
            spline.closed = True
    for name, centre, radius, start, end in arcs:
        msp.add_arc((centre[0] * 1e3, centre[1] * 1e3), radius * 1e3, start, end, dxfattribs=layer(name))
    for name, centre, radius in circles:
        msp.add_circle((centre[0] * 1e3, centre[1] * 1e3), radius * 1e3, dxfattribs=layer(name))
    for name, xy in points:
        msp.add_point((xy[0] * 1e3, xy[1] * 1e3), dxfattribs=layer(name))
    doc.saveas(path)


def write_dxf(geometry: CamGeometry, path) -> None:
    """Closed fit-point splines (mm) of the working profile (layer PROFILE) and the pitch curve (PITCH),
    and the cam's centre as a point (layer CENTRE)."""
    curves = [("PROFILE", geometry.profile, True)]
    if geometry.pitch is not None:
        curves.append(("PITCH", geometry.pitch, True))
    write_dxf_entities(path, curves=curves, points=[("CENTRE", (0.0, 0.0))])


def read_dxf_points(path, layer: str = "PROFILE") -> np.ndarray:
    """The fit points (m) of the spline on `layer` of a DXF written by `write_dxf`."""
    ezdxf = require_ezdxf()
    doc = ezdxf.readfile(path)
    for e in doc.modelspace().query("SPLINE"):
        if e.dxf.layer == layer:
            return np.array([(p[0], p[1]) for p in e.fit_points]) * 1e-3
    raise MbplanarError(f"{path}: no spline on layer {layer}")


def dxf_deviation(geometry: CamGeometry, path) -> float:
    """Largest distance (m) between the profile written to `path` and the computed one, point by point."""
    pts = read_dxf_points(path)
    if pts.shape[0] != geometry.profile.shape[0] + 1:
        return math.inf
    return float(np.max(np.linalg.norm(pts[:-1] - geometry.profile, axis=1)))


def dxf_chordal_error(path, points, layer: str = "PROFILE", per_span: int = 64) -> float:
    """Largest distance (m) from `points` (N, 2; e.g. the exact profile at the midpoints between the
    written samples) to the curve a CAD program draws from the spline in `path` (ezdxf's own
    interpolation of the fit points, flattened to `per_span` chords per span; distances to the chords)."""
    from scipy.spatial import cKDTree
    ezdxf = require_ezdxf()
    doc = ezdxf.readfile(path)
    spline = next(e for e in doc.modelspace().query("SPLINE") if e.dxf.layer == layer)
    count = len(spline.fit_points)
    curve = np.array(list(spline.construction_tool().approximate(per_span * count)))[:, :2] * 1e-3
    _, k = cKDTree(curve).query(points)
    best = np.full(len(points), np.inf)
    for lo in (k - 1, k):
        lo = np.clip(lo, 0, len(curve) - 2)
        a, b = curve[lo], curve[lo + 1]
        d = b - a
        t = np.clip(np.sum((points - a) * d, 1) / np.maximum(np.sum(d * d, 1), 1e-300), 0, 1)
        best = np.minimum(best, np.linalg.norm(points - a - t[:, None] * d, axis=1))
    return float(best.max())


def svg_text(title: str, paths, dots=(), extent=()) -> str:
    """An SVG picture (millimetres, y up) of paths and dots given in metres.

    Parameters
    ----------
    title : str
    paths : iterable of (points (N, 2), closed, fill, stroke, width, dash)
        `width` in units of the picture's line width (0.3 % of its size), `dash` a (on, off) pair in those
        units or None.
    dots : iterable of (centre (2,), radius, colour), radius in line widths
    extent : iterable of (x, y)
        more points the view must contain.
    """
    paths, dots = list(paths), list(dots)
    allp = np.vstack([np.asarray(p[0], float) for p in paths] + [np.asarray(d[0], float).reshape(1, 2) for d in dots]
                     + [np.asarray(list(extent), float).reshape(-1, 2)]) * 1e3
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    pad = 0.05 * float(np.max(hi - lo))
    x0, y0 = lo[0] - pad, -(hi[1] + pad)
    w, h = hi[0] - lo[0] + 2 * pad, hi[1] - lo[1] + 2 * pad
    stroke = 0.003 * max(w, h)

    def path_of(p, closed):
        p = np.asarray(p, float) * 1e3
        return "M " + " L ".join(f"{x:.6f},{-y:.6f}" for x, y in p) + (" Z" if closed else "")

    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="{x0:.4f} {y0:.4f} {w:.4f} {h:.4f}" '
             f'width="{w:.2f}mm" height="{h:.2f}mm">', f"<title>{_escape(title)}</title>"]
    for pts, closed, fill, colour, width, dash in paths:
        style = (f'fill="{fill}" stroke="{colour}" stroke-width="{width * stroke:.4f}"'
                 + (f' stroke-dasharray="{dash[0] * stroke:.4f} {dash[1] * stroke:.4f}"' if dash else ""))
        parts.append(f'<path d="{path_of(pts, closed)}" {style}/>')
    for centre, radius, colour in dots:
        parts.append(f'<circle cx="{_coord(centre[0])}" cy="{_coord(-centre[1])}" r="{radius * stroke:.4f}" '
                     f'fill="{colour}"/>')
    parts.append("</svg>")
    return "\n".join(parts) + "\n"


def _coord(v):
    """A coordinate in mm as the cam's centre was always written ("0" at the origin)."""
    return "0" if v == 0 else f"{v * 1e3:.4f}"


def write_svg(geometry: CamGeometry, path, title: str = "cam") -> None:
    """The working profile (solid), the pitch curve (dashed) and the centre, in mm, y up."""
    g = geometry
    paths = [(g.profile, True, "#dde6ee", "#1a1a1a", 1.0, None)]
    if g.pitch is not None:
        paths.append((g.pitch, True, "none", "#2a6fb0", 0.5, (4.0, 2.0)))
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(svg_text(title, paths, dots=[((0.0, 0.0), 2.0, "#b03a2e")]))


def _escape(text):
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
