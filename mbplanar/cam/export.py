"""Writing the profile: CSV (pitch and working profile in mm, the seed's x.txt and y.txt), DXF (closed
splines through the points, ezdxf; optional extra `cad`) and SVG, both through `mbplanar.io._cad`."""

from __future__ import annotations

import math

import numpy as np

from ..errors import MbplanarError
from ..io import Layer, Sheet, require_ezdxf
from ..io import write_dxf as cad_dxf
from ..io import write_svg as cad_svg
from .geometry import CamGeometry

__all__ = ["write_csv", "write_dxf", "read_dxf_points", "write_svg", "dxf_deviation", "dxf_chordal_error"]


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
            fh.write(",".join("" if not math.isfinite(x) else f"{x:.12g}" for x in row) + "\n")


def _sheet(geometry: CamGeometry, title: str = "") -> Sheet:
    """The profile (layer PROFILE), the pitch curve (PITCH) as closed fit-point splines in mm, the cam's
    centre as a point (CENTRE)."""
    sheet = Sheet("mm", title)
    sheet.layer(Layer("PROFILE", 7, "#1a1a1a", "#dde6ee")).layer(Layer("PITCH", 5, "#2a6fb0", width=0.5, dash=(4, 2)))
    sheet.layer(Layer("CENTRE", 1, "#b03a2e"))
    sheet.spline("PROFILE", geometry.profile * 1e3, closed=True)
    if geometry.pitch is not None:
        sheet.spline("PITCH", geometry.pitch * 1e3, closed=True)
    sheet.point("CENTRE", (0.0, 0.0))
    return sheet


def write_dxf(geometry: CamGeometry, path) -> None:
    """Closed fit-point splines (mm) of the working profile (layer PROFILE) and the pitch curve (PITCH),
    and the cam's centre as a point (layer CENTRE)."""
    cad_dxf(_sheet(geometry), path)


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


def write_svg(geometry: CamGeometry, path, title: str = "cam") -> None:
    """The working profile (solid), the pitch curve (dashed) and the centre, in mm, y up."""
    cad_svg(_sheet(geometry, title), path)
