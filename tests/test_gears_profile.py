"""The generated tooth profile: its self-check (generated involute = analytic involute, pitch thickness =
formula, to 1e-9 of the module), geometric laws an involute and a generated gear obey whatever the
numbers, the meshing placement (touching, no overlap), and the DXF, SVG and CSV written from it."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mbplanar.gears import Rack, gear_pair, gear_profile
from mbplanar.gears import export
from mbplanar.gears.export import mesh_placement, placed


def _pair(m, z1, z2, x1, x2=0.0, alpha_deg=20.0, **kw):
    return gear_pair(m, (z1, z2), (x1, x2), rack=Rack(math.radians(alpha_deg)), **kw)


@settings(max_examples=60, deadline=None)
@given(st.integers(4, 90), st.floats(-0.6, 1.0), st.sampled_from([14.5, 20.0, 25.0]), st.floats(0.3, 25.0))
def test_self_check_passes_and_undercut_is_x_below_x_min(z, x, alpha_deg, m_mm):
    """For any tooth number, shift, pressure angle and module: the generated involute lies on the
    analytic one and the thickness read off the outline is the formula's, to 1e-9 m·(m/m); the profile is
    undercut exactly when x < x_min."""
    m = m_mm * 1e-3
    rack = Rack(math.radians(alpha_deg))
    x_min = rack.flank_end - z * math.sin(rack.pressure_angle) ** 2 / 2
    if abs(x - x_min) < 1e-9:
        return
    try:
        prof = gear_profile(_pair(m, z, 60, x, 0.0, alpha_deg), 1)
    except Exception as exc:                                  # no involute at all: a pointed stub
        assert "no involute" in str(exc)
        return
    assert prof.check.success, prof.check
    assert prof.check.involute_error <= 1e-9 * m and prof.check.thickness_error <= 1e-9 * m
    assert prof.undercut == (x < x_min)


def test_normals_of_the_generated_involute_touch_the_base_circle():
    """The involute's defining property, checked on the generated samples only: the normal at each point
    (from the samples' central differences) passes at r_b from the centre, and the arc length between two
    points equals the difference of their roll lengths (ρ²/2r_b), to the differences' accuracy."""
    p = _pair(10e-3, 23, 40, 0.2)
    prof = gear_profile(p, 1, samples=4000)
    inv_pts = prof.flank[1]
    rb = p.gears[0].base_diameter / 2
    t = (inv_pts[2:] - inv_pts[:-2])
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    mid = inv_pts[1:-1]
    distance = np.abs(mid[:, 0] * t[:, 0] + mid[:, 1] * t[:, 1])   # |p·t|: the normal's distance from O
    assert np.max(np.abs(distance - rb)) < 1e-7 * p.module
    rho = np.sqrt(np.sum(inv_pts ** 2, axis=1) - rb ** 2)
    arc = np.sum(np.linalg.norm(np.diff(inv_pts, axis=0), axis=1))
    assert abs(arc - (rho[-1] ** 2 - rho[0] ** 2) / (2 * rb)) < 1e-6 * p.module


def test_fillet_reaches_the_root_circle_and_joins_the_involute_smoothly():
    p = _pair(5e-3, 30, 40, 0.1)
    prof = gear_profile(p, 1, samples=400)
    fillet, involute = prof.flank
    r = np.hypot(prof.outline[:, 0], prof.outline[:, 1])
    assert abs(r.min() - p.gears[0].root_diameter / 2) < 1e-12
    assert abs(r.max() - p.gears[0].tip_diameter / 2) < 1e-12
    assert np.allclose(fillet[-1], involute[0], atol=1e-15)   # no undercut: they meet where the flank ends
    t1 = fillet[-1] - fillet[-2]
    t2 = involute[1] - involute[0]
    cos = t1 @ t2 / np.linalg.norm(t1) / np.linalg.norm(t2)
    assert cos > 1 - 1e-4                                      # tangent (to the samples' resolution)
    assert not prof.undercut and abs(prof.form_radius - p.gears[0].form_radius) < 1e-12


def test_undercut_profile_turns_a_corner_where_fillet_and_involute_cross():
    p = _pair(10e-3, 9, 40, 0.0)
    prof = gear_profile(p, 1, samples=400)
    fillet, involute = prof.flank
    assert prof.undercut and np.allclose(fillet[-1], involute[0], atol=1e-13)
    assert prof.form_radius > p.gears[0].base_diameter / 2          # the involute starts above the base circle
    t1, t2 = fillet[-1] - fillet[-2], involute[1] - involute[0]
    assert t1 @ t2 / np.linalg.norm(t1) / np.linalg.norm(t2) < 0.999   # a corner: the undercut


def test_whole_gear_outline_is_closed_counter_clockwise_and_z_fold_symmetric():
    p = _pair(4e-3, 17, 40, 0.3)
    prof = gear_profile(p, 1)
    out = prof.outline
    area = 0.5 * np.sum(out[:, 0] * np.roll(out[:, 1], -1) - np.roll(out[:, 0], -1) * out[:, 1])
    g = p.gears[0]
    assert area > 0 and math.pi * (g.root_diameter / 2) ** 2 < area < math.pi * (g.tip_diameter / 2) ** 2
    turned = placed(out, (0.0, 0.0), 2 * math.pi / 17)
    from scipy.spatial import cKDTree
    d, _ = cKDTree(out).query(turned)
    assert d.max() < 1e-12
    # no two edges cross (the outline is a simple polygon)
    a, b = out, np.roll(out, -1, axis=0)
    for k in range(0, len(a), 400):
        pa, pb = a[k:k + 400, None], b[k:k + 400, None]
        def cross(u, v):
            return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]
        d1 = cross(pb - pa, a[None] - pa)
        d2 = cross(pb - pa, b[None] - pa)
        d3 = cross(b[None] - a[None], pa - a[None])
        d4 = cross(b[None] - a[None], pb - a[None])
        crossing = (d1 * d2 < -1e-30) & (d3 * d4 < -1e-30)
        assert not crossing.any()


def _segment_distance(points, a, b):
    """(P,) distance of each point to the nearest of the segments a→b (the segments at the 8 nearest
    segment starts and ends: the nearest segment is among them for a sampled smooth curve)."""
    from scipy.spatial import cKDTree
    tree = cKDTree(np.vstack([a, b]))
    _, idx = tree.query(points, k=8)
    idx = idx % len(a)                                        # a segment by its start or its end
    pa, pb = a[idx], b[idx]
    ab = pb - pa
    q = points[:, None, :]
    t = np.clip(np.sum((q - pa) * ab, -1) / np.sum(ab * ab, -1), 0, 1)
    return np.min(np.linalg.norm(q - pa - t[..., None] * ab, axis=-1), axis=1)


def _inside_depth(points, polygon, near, outside=False):
    """How far each of `points` lies inside `polygon` (with `outside`: outside it), 0 for the others: the
    distance to the polygon's edges that start within the mask `near`."""
    from matplotlib.path import Path
    flagged = Path(polygon).contains_points(points)
    flagged = ~flagged if outside else flagged
    depth = np.zeros(len(points))
    if flagged.any():
        a, b = polygon[near], np.roll(polygon, -1, axis=0)[near]
        depth[flagged] = _segment_distance(points[flagged], a, b)
    return depth


@pytest.mark.parametrize("teeth, shifts, internal", [((12, 30), (0.5923, 0.5278), False),
                                                     ((17, 24), (0.0, 0.3), False),
                                                     ((20, 62), (0.0, 0.2), True)])
def test_gears_placed_in_mesh_touch_without_overlap(teeth, shifts, internal):
    """At the working pitch circles the tooth of one fills the space of the other (s_w1 + s_w2 = p_w): the
    outlines placed by `mesh_placement` touch (gap below 1e-4 of the module) and neither enters the other
    by more than 1e-5 of the module (the polygons' chords cut a concave flank by their sagitta, ~3e-6 m·m
    at 300 samples; a placement off by a tooth's turn would overlap by a good part of the module)."""
    m = 10e-3
    p = gear_pair(m, teeth, shifts, internal=internal, ring_tip="cut" if internal else "standard")
    profs = [gear_profile(p, 1, samples=300), gear_profile(p, 2, samples=300)]
    (c1, t1), (c2, t2) = mesh_placement(p)
    o1, o2 = placed(profs[0].outline, c1, t1), placed(profs[1].outline, c2, t2)
    pitch_point = np.array([0.0, p.gears[0].working_diameter / 2])
    mask1 = np.linalg.norm(o1 - pitch_point, axis=1) < 3 * m
    mask2 = np.linalg.norm(o2 - pitch_point, axis=1) < 3 * m
    near1, near2 = o1[mask1], o2[mask2]
    wide1, wide2 = (np.linalg.norm(o - pitch_point, axis=1) < 5 * m for o in (o1, o2))
    gap = _segment_distance(near2, o1[wide1], np.roll(o1, -1, axis=0)[wide1]).min()
    assert gap < 1e-4 * m
    if internal:        # the ring's material lies outside its toothed outline: the pinion must stay inside it
        assert _inside_depth(near1, o2, wide2, outside=True).max() < 1e-5 * m
        assert _inside_depth(near2, o1, wide1).max() < 1e-5 * m
    else:
        assert _inside_depth(near2, o1, wide1).max() < 1e-5 * m
        assert _inside_depth(near1, o2, wide2).max() < 1e-5 * m


def test_dxf_holds_the_outline_exactly(tmp_path):
    ezdxf = pytest.importorskip("ezdxf")
    p = _pair(10e-3, 12, 30, 0.5923, 0.5278)
    profs = [gear_profile(p, 1), gear_profile(p, 2)]
    path = tmp_path / "pair.dxf"
    export.write_dxf(p, profs, path)
    doc = ezdxf.readfile(path)
    msp = doc.modelspace()
    layers = {e.dxf.layer for e in msp}
    assert {"GEAR1", "GEAR2", "PITCH", "CENTRES"} <= layers
    for k, (prof, (centre, turn)) in enumerate(zip(profs, mesh_placement(p)), 1):
        splines = [e for e in msp.query("SPLINE") if e.dxf.layer == f"GEAR{k}"]
        arcs = [e for e in msp.query("LWPOLYLINE") if e.dxf.layer == f"GEAR{k}"]
        z = prof.teeth
        assert len(splines) == 4 * z and len(arcs) == 3 * z
        curves = [pc for pc in prof.pieces if pc.kind == "curve"]
        for spline, piece in zip(splines, curves):
            fit = np.array([pt[:2] for pt in spline.fit_points]) * 1e-3
            assert np.max(np.abs(fit - placed(piece.points, centre, turn))) < 1e-12
        radii = set()
        for arc in arcs:                                      # a segment with a bulge: r = c(1 + b²)/(4|b|)
            (x0, y0, _, _, b), (x1, y1, *_) = arc.get_points("xyseb")
            c = math.hypot(x1 - x0, y1 - y0)
            radii.add(round(c * (1 + b * b) / (4 * abs(b)), 9))
            mid = np.array([(x0 + x1) / 2, (y0 + y1) / 2]) * 1e-3 - np.asarray(centre)
            assert np.hypot(*mid) < (max(radii) + 1e-9) * 1e-3   # the arc's chord lies inside its circle
        g = p.gears[k - 1]
        assert np.allclose(sorted(radii), sorted([g.root_diameter / 2 * 1e3, prof.tip_radius * 1e3]), atol=1e-9)
    # the curve a CAD program draws through the fit points stays on the exact involute
    spline = next(e for e in msp.query("SPLINE") if e.dxf.layer == "GEAR1")
    drawn = np.array(list(spline.construction_tool().approximate(2000)))[:, :2] * 1e-3
    involute = [pc for pc in profs[0].pieces if pc.part == "involute"][0].points
    from scipy.spatial import cKDTree
    dense_ok = drawn[np.hypot(drawn[:, 0], drawn[:, 1]) > np.hypot(*involute[0]) + 1e-9]
    if dense_ok.size:
        d, _ = cKDTree(placed(gear_profile(p, 1, samples=4000).flank[1], (0, 0), 0)).query(dense_ok)
        assert d.max() < 1e-6 * p.module


def test_svg_and_csv(tmp_path):
    p = _pair(10e-3, 12, 30, 0.5923, 0.5278)
    profs = [gear_profile(p, 1), gear_profile(p, 2)]
    export.write_svg(p, profs, tmp_path / "pair.svg", "pair & <test>")
    root = ET.parse(tmp_path / "pair.svg").getroot()
    svg = "{http://www.w3.org/2000/svg}"
    layers = {g.get("id"): g for g in root.iter(svg + "g")}
    assert set(layers) == {"GEAR1", "GEAR2", "PITCH", "CENTRES"}
    assert len(list(layers["GEAR1"].iter(svg + "path"))) == 1 and len(list(layers["PITCH"].iter(svg + "circle"))) == 2
    assert root.find(svg + "title").text == "pair & <test>"
    export.write_csv(profs, tmp_path / "pair.csv")
    rows = (tmp_path / "pair.csv").read_text().splitlines()
    assert rows[0] == "gear,piece,part,x[mm],y[mm]"
    assert len(rows) - 1 == sum(len(pc.points) for prof in profs for pc in prof.pieces)
    parts = {r.split(",")[2] for r in rows[1:]}
    assert parts == {"root", "fillet", "involute", "tip"}
