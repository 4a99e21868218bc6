"""A mechanism drawn far from the world's origin gives the answers of the same mechanism drawn at the
origin: the engine solves in the mechanism's own frame (`model._scale.frame_origin`), so that closure
residuals, Newton steps, pivots, determinants and limits are judged on vectors within the mechanism.

What remains is the rounding of the drawing's own coordinates, ~1e-16 of their size: ~1e-16 × ratio of
the mechanism's size, ratio = (the farthest joint's distance from the origin) / (the mechanism's size).
Within `FAR_GUARANTEED` (1e8) the answers agree with the origin's to a tolerance that grows with the
ratio; beyond it a `PrecisionWarning` says by how much they may differ, and beyond `FAR_REFUSED` (1e11)
the model is refused. Before the fix a crank-rocker 1000 m from the origin reported false dead points."""

import dataclasses
import json
import math
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import mbplanar
from mbplanar.cli import main
from mbplanar.errors import ModelError, PrecisionWarning
from mbplanar.model._assembly import reference_points
from mbplanar.model._model import Gravity
from mbplanar.model._scale import FAR_GUARANTEED, FAR_REFUSED, frame_origin

from conftest import MODELS, linkage_models

BACKENDS = ["numpy", "numba"]
# six_bar_press's rocker is a straight triangle whose middle pin the sketch fixes only to ~1e-8 of the
# size (tests/test_scale.py): turned, its sketch assembles ~1e-8 away
BASE = {"six_bar_press.toml": 1e-6}


def tolerance(name: str, ratio: float, gain: float = 1.0) -> float:
    """Relative agreement expected with the origin's answers: the base of a turned drawing, and the
    rounding of coordinates `ratio` sizes from the origin (measured: ≤ 1e-15 × ratio; ×10 margin),
    times the `gain` of the quantity's computation."""
    return BASE.get(name, 1e-9) + 1e-14 * gain * ratio


# the forces are solved from the link frames in world coordinates, whose rounding the force system's
# condition then amplifies (measured up to 1.5e-14 × ratio, class4_group's)
FORCES = 100.0


# -- the mechanism of the report ------------------------------------------------------------------------
def crank_rocker(off: float) -> mbplanar.Mechanism:
    """Crank 0.1, coupler 0.3, rocker 0.25, frame 0.3 m, crank at 1 rad, drawn with O at (off, off)."""
    m = mbplanar.Mechanism("far")
    for n in "123":
        m.add_link(n)
    o, a, c = (off, off), (off + 0.1 * math.cos(1.0), off + 0.1 * math.sin(1.0)), (off + 0.3, off)
    d = math.dist(a, c)
    along = (0.3 ** 2 - 0.25 ** 2 + d * d) / (2 * d)
    h = math.sqrt(0.3 ** 2 - along * along)
    b = (a[0] + along * (c[0] - a[0]) / d - h * (c[1] - a[1]) / d,
         a[1] + along * (c[1] - a[1]) / d + h * (c[0] - a[0]) / d)
    m.add_joint("O", "R", "0", "1", at=o)
    m.add_joint("A", "R", "1", "2", at=a)
    m.add_joint("B", "R", "2", "3", at=b)
    m.add_joint("C", "R", "3", "0", at=c)
    m.add_input("O")
    return m


# the offset at which the report's four-bar reaches the guaranteed ratio (its size: |AC| in the drawn pose)
LIMIT_OFFSET = FAR_GUARANTEED * mbplanar.Engine(crank_rocker(0.0)).size / math.sqrt(2.0) * 0.999


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("off", [1e2, 1e3, 1e4, 1e5, 1e6, 1e7, LIMIT_OFFSET])
def test_crank_rocker_far_from_the_origin_turns_fully(backend, off):
    """The report's crank-rocker (Grashof: 0.1 + 0.3 < 0.25 + 0.3, the crank the shortest link) turns
    fully wherever it is drawn: no dead point, a full turn analysed, the origin's answers."""
    near, far = (mbplanar.Engine(crank_rocker(x), backend=backend) for x in (0.0, off))
    assert far.centre.tolist() != [0.0, 0.0] and near.centre.tolist() == [0.0, 0.0]
    report = mbplanar.check(far)
    assert report.full_turn and report.limits == [] and report.grashof.kind == "crank-rocker"
    phi = np.linspace(0.0, 2 * np.pi, 73)
    m0, m1 = mbplanar.analyse(near, phi, omega=10.0), mbplanar.analyse(far, phi, omega=10.0)
    assert m1.success and len(m1.phi) == 73
    tol = tolerance("", off * math.sqrt(2.0) / near.size)
    size = near.size
    assert np.abs(m1.angle - m0.angle).max() <= tol
    assert np.abs(m1.xy - off - m0.xy).max() <= tol * size
    assert np.abs(m1.v - m0.v).max() <= tol * size * 10.0 * np.abs(m0.w).max()
    assert np.abs(m1.a - m0.a).max() <= tol * size * 100.0 * max(np.abs(m0.w).max() ** 2, 1.0)
    assert np.abs(m1.value - m0.value).max() <= tol
    t0, t1 = mbplanar.check(near).transmission[0], report.transmission[0]
    assert abs(t1.minimum - t0.minimum) <= tol and abs(t1.maximum - t0.maximum) <= tol


# -- every bundled model, moved anywhere within the guarantee ----------------------------------------------
def moved(mech: mbplanar.Mechanism, angle: float, offset) -> mbplanar.Mechanism:
    """`mech` turned by `angle` (rad) about the origin, then moved by `offset` (2,): the joints, points,
    guides, higher pairs (their points, curves, racks' lines and flat faces), loads (points of
    application, forces, switch directions) and gravity turn with it, and
    an input measured from the ground's x axis gets its `zero` moved so that φ means the same."""
    c, s = math.cos(angle), math.sin(angle)

    def xy(p):
        return None if p is None else (c * p[0] - s * p[1] + offset[0], s * p[0] + c * p[1] + offset[1])

    def turned(f):
        return (c * f[0] - s * f[1], s * f[0] + c * f[1])

    joints = {n: dataclasses.replace(j, at=xy(j.at), guide_deg=None if j.guide_deg is None
                                     else j.guide_deg + math.degrees(angle)) for n, j in mech.joints.items()}
    points = {n: dataclasses.replace(p, at=xy(p.at)) for n, p in mech.points.items()}
    loads = tuple(dataclasses.replace(ld, at=xy(ld.at), other_at=xy(ld.other_at), force=turned(ld.force),
                                      switch_direction=ld.switch_direction + angle) for ld in mech.loads)
    gravity = mech.gravity
    if gravity is None and any(ld.kind == "weight" for ld in mech.loads):
        gravity = Gravity(g=0.0)  # (a weight acts along gravity's direction, which turns)
    if gravity is not None:
        gravity = dataclasses.replace(gravity, direction=gravity.direction + angle)
    inputs = []
    for inp in mech.inputs:
        a, b = mech.joints[inp.joint].links
        shift = (_turns(mech, b) - _turns(mech, a)) * angle if mech.joints[inp.joint].kind == "R" else 0.0
        inputs.append(dataclasses.replace(inp, zero=inp.zero + shift / inp.scale))
    higher = {n: dataclasses.replace(h, at=xy(h.at), curve=None if h.curve is None else h.curve.moved(xy),
                                     guide=None if h.guide is None else h.guide + angle,
                                     face=None if h.face is None else h.face + angle)
              for n, h in mech.higher.items()}
    return dataclasses.replace(mech, joints=joints, points=points, loads=loads, gravity=gravity, inputs=inputs,
                               higher=higher)


def _turns(mech, link) -> int:
    """1 when the link's reported angle turns with the drawing (it has a reference line or a guide)."""
    if link == mech.ground:
        return 0
    return int(reference_points(mech, link) is not None or any(j.kind == "P" for j in mech.joints_of(link)))


def _wrapped(x):
    return np.remainder(x + np.pi, 2 * np.pi) - np.pi


def _rotate(v, angle):
    c, s = math.cos(angle), math.sin(angle)
    out = np.empty_like(v)
    out[..., 0] = c * v[..., 0] - s * v[..., 1]
    out[..., 1] = s * v[..., 0] + c * v[..., 1]
    return out


_REFERENCE = {}


def _at_origin(path, backend):
    """The model's engine as written (near the origin), input values relative to its drawn pose, and
    its motion, forces and check there (computed once per model and backend)."""
    key = (path.name, backend)
    if key not in _REFERENCE:
        mech = mbplanar.read_model(path)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            engine = mbplanar.Engine(mech, backend=backend)
            if len(mech.inputs) > 1:
                rel = np.linspace(0.0, 0.3, 5)[:, None] * np.ones(len(mech.inputs))
            elif engine.period() is not None:
                rel = np.linspace(-3.0, 3.0, 25)
            else:
                lo, hi = engine.reach()
                # (away from the limits, where the rates grow without bound and amplify any change of shape)
                d0, margin = float(engine.phi_drawn[0]), 0.05 * (hi - lo)
                rel = np.linspace(lo + margin - d0, hi - margin - d0, 25)
            motion = mbplanar.analyse(engine, engine.phi_drawn + (rel if rel.ndim == 2 else rel[:, None]))
            forces = mbplanar.kinetostatics(engine, motion) if _loaded(mech) else None
            report = mbplanar.check(engine) if len(mech.inputs) == 1 else None
        _REFERENCE[key] = (mech, engine, rel, motion, forces, report)
    return _REFERENCE[key]


def _loaded(mech) -> bool:
    return bool(mech.loads or any(lk.mass or lk.inertia for lk in mech.links.values()))


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("path", linkage_models(), ids=lambda p: p.name)
@settings(max_examples=2, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(angle=st.floats(-math.pi, math.pi), exponent=st.floats(0.0, math.log10(FAR_GUARANTEED)),
       direction=st.floats(-math.pi, math.pi))
@example(angle=2.0, exponent=math.log10(FAR_GUARANTEED), direction=-2.3)  # at the guarantee's edge
def test_a_model_moved_and_turned_gives_the_origins_answers(path, backend, angle, exponent, direction):
    """Every bundled model, turned by any angle and moved up to the guaranteed ratio from the origin:
    the same check verdicts and limits, link angles (turned), joint values, points (turned and moved),
    velocities, accelerations, reactions (turned) and balancing loads, to a tolerance that grows with
    the distance."""
    mech, e0, rel, m0, k0, c0 = _at_origin(path, backend)
    size = e0.size
    # a spline's points, moved far out, carry the rounding of their coordinates, and the spline through
    # them differentiates it (its slope, curvature and their rates enter the rates): measured 2e-11 × the
    # ratio on the acceleration of cam_follower's profile (points 1 mm apart); docs/units.md says so
    splined = any(h.curve is not None and h.curve.kind == "spline" for h in mech.higher.values())
    ratio = 10.0 ** (min(exponent, 6.0) if splined else exponent)
    distance = 0.99 * max(ratio - 1.0, 0.0) * size  # (the drawn joints lie within a size of the model's origin)
    offset = (distance * math.cos(direction), distance * math.sin(direction))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mbplanar.errors.ModelWarning)
        warnings.simplefilter("error", PrecisionWarning)  # within the guarantee: no warning
        e1 = mbplanar.Engine(moved(mech, angle, offset), backend=backend)
        m1 = mbplanar.analyse(e1, e1.phi_drawn + (rel if rel.ndim == 2 else rel[:, None]))
    tol = tolerance(path.name, ratio + 1.0, 1e4 if splined else 1.0)
    assert len(m1.phi) == len(m0.phi), m1.message
    turn = np.array([e1.reference_angle[n] - e0.reference_angle[n] for n in e0.links])
    assert np.abs(_wrapped(m1.angle - m0.angle - turn)).max() <= tol
    revolute = np.array([j.kind == "R" for j in mech.joints.values()])
    shift = np.array([e1.joint_value_drawn[n] - e0.joint_value_drawn[n] for n in mech.joints])
    values = m1.value - m0.value - np.where(revolute, shift, 0.0)
    assert np.abs(np.where(revolute, _wrapped(values), values / size)).max() <= tol
    assert np.abs(m1.xy - _rotate(m0.xy, angle) - np.array(offset)).max() <= tol * size
    w_max, e_max = 1.0 + np.abs(m0.w).max(), np.abs(m0.e).max()
    assert np.abs(m1.w - m0.w).max() <= tol * w_max and np.abs(m1.e - m0.e).max() <= tol * (w_max ** 2 + e_max)
    assert np.abs(m1.v - _rotate(m0.v, angle)).max() <= tol * size * w_max
    assert np.abs(m1.a - _rotate(m0.a, angle)).max() <= tol * size * (w_max ** 2 + e_max)
    if k0 is not None:
        k1 = mbplanar.kinetostatics(e1, m1)
        force = max(np.abs(np.hypot(r.fx, r.fy)).max() for r in k0.reactions.values())
        scale = force + max(np.abs(b).max() for b in k0.balancing.values()) / size + 1e-300
        tol_f = tolerance(path.name, ratio + 1.0, FORCES * (100.0 if splined else 1.0))
        for name, r0 in k0.reactions.items():
            r1 = k1.reactions[name]
            turned = _rotate(np.stack([r0.fx, r0.fy], axis=-1), angle)
            assert np.abs(np.stack([r1.fx, r1.fy], axis=-1) - turned).max() <= tol_f * scale, name
            assert np.abs(r1.moment - r0.moment).max() <= tol_f * scale * size, name
        for name, b0 in k0.balancing.items():
            assert np.abs(k1.balancing[name] - b0).max() <= tol_f * scale * size, name
    if c0 is not None:
        c1 = mbplanar.check(e1)
        inp = e0.inputs[0]
        d0, d1 = inp.from_si(float(e0.phi_drawn[0])), inp.from_si(float(e1.phi_drawn[0]))
        per_unit = inp.to_si(1.0) / (1.0 if mech.joints[inp.joint].kind == "R" else size)
        assert c1.full_turn == c0.full_turn
        assert [(lim.direction, lim.links, lim.kind) for lim in c1.limits] == \
            [(lim.direction, lim.links, lim.kind) for lim in c0.limits]
        for l1, l0 in zip(c1.limits, c0.limits):
            assert abs((l1.phi - d1) - (l0.phi - d0)) * per_unit <= 10 * tol
        assert len(c1.change_points) == len(c0.change_points)
        if not c0.full_turn:
            assert np.abs(np.subtract(c1.range, d1) - np.subtract(c0.range, d0)).max() * per_unit <= 10 * tol
        for t1, t0 in zip(c1.transmission, c0.transmission):
            assert abs(t1.minimum - t0.minimum) <= 10 * tol and abs(t1.maximum - t0.maximum) <= 10 * tol


# -- the frame's origin ----------------------------------------------------------------------------------
@settings(max_examples=50, deadline=None)
@given(x=st.floats(-1e9, 1e9), y=st.floats(-1e9, 1e9), size=st.floats(1e-6, 1e3))
def test_points_move_into_the_frame_exactly_and_stay_near_its_origin(x, y, size):
    """The frame's origin is 0 near the world's origin; a drawn point moved into the frame (p − origin)
    and back is exact, and lies within a few sizes of the frame's origin."""
    pts = np.array([[x, y], [x + size, y], [x, y + 0.5 * size]])
    origin = frame_origin(pts, size)
    local = pts - origin
    assert np.array_equal(local + origin, pts)
    assert np.abs(local).max() <= 64 * size + 1e-16 * np.abs(pts).max()
    if np.abs(pts).max() <= 7 * size:
        assert origin.tolist() == [0.0, 0.0]


# -- beyond the guarantee --------------------------------------------------------------------------------
def test_beyond_the_guarantee_a_precision_warning_gives_the_numbers():
    ratio = 1e9
    off = ratio * 0.393601 / math.sqrt(2.0)
    with pytest.warns(PrecisionWarning, match=r"1e\+09 times the mechanism's size .*shape only to ~1e-07 of its size"):
        engine = mbplanar.Engine(crank_rocker(off))
    assert mbplanar.check(engine).full_turn  # (still the right verdict here, ~1e-7 off)


def test_beyond_the_refusal_limit_the_model_is_refused():
    off = 2 * FAR_REFUSED * 0.393601
    with pytest.raises(ModelError, match=r"drawn up to .* from the origin, .* fewer than 5 digits.* nearer the origin"):
        mbplanar.Engine(crank_rocker(off))


def _far_toml(tmp_path, offset: float, unit: str = "m") -> str:
    """models/fourbar.toml (a sketch with lengths, drawn at 60°) moved by (offset, offset)."""
    import tomllib
    data = tomllib.loads((MODELS / "fourbar.toml").read_text(encoding="utf-8"))
    k = 1000.0 if unit == "mm" else 1.0
    lines = [f'length_unit = "{unit}"', 'name = "far"', 'links = [']
    lines += [f'  {{ name = "{lk["name"]}", length = {lk["length"] * k!r} }},' for lk in data["links"]]
    lines += ["]", "joints = ["]
    for j in data["joints"]:
        x, y = (j["at"][0] + offset) * k, (j["at"][1] + offset) * k
        lines.append(f'  {{ name = "{j["name"]}", type = "R", links = {json.dumps(j["links"])}, at = [{x!r}, {y!r}] }},')
    lines += ["]", "[input]", 'joint = "O"', f'drawn_at = {data["input"]["drawn_at"]!r}']
    path = tmp_path / f"far_{unit}.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return str(path)


def test_the_command_line_checks_a_sketch_far_away_as_at_the_origin(tmp_path, capsys):
    """`check --json` of models/fourbar.toml's sketch (lengths, drawn_at) moved 1e6 m (in mm): the
    assembly closes it there, and it turns fully as the original does, with its transmission angles."""
    assert main(["check", str(MODELS / "fourbar.toml"), "--json"]) == 0
    near = json.loads(capsys.readouterr().out)
    assert main(["--no-cache", "check", _far_toml(tmp_path, 1e6, "mm"), "--json"]) == 0
    far = json.loads(capsys.readouterr().out)
    assert far["full_turn"] and near["full_turn"] and far["limits"] == near["limits"] == []
    for t1, t0 in zip(far["transmission"], near["transmission"]):
        assert abs(t1["minimum"] - t0["minimum"]) < 1e-6 and abs(t1["maximum"] - t0["maximum"]) < 1e-6


def test_the_command_line_notes_beyond_the_guarantee_and_refuses_beyond_the_limit(tmp_path, capsys):
    assert main(["--no-cache", "check", _far_toml(tmp_path, 1e9)]) == 0
    assert "mbplanar: note: " in capsys.readouterr().err
    assert main(["--no-cache", "check", _far_toml(tmp_path, 1e11)]) == 2
    err = capsys.readouterr().err
    assert "fewer than 5 digits" in err and "far_m.toml" in err


# -- design batches and synthesis far away ----------------------------------------------------------------
def _design_model(tmp_path, offset: float) -> str:
    """models/fourbar_design.toml with O at (offset, offset) and C at d from O along +x."""
    text = (MODELS / "fourbar_design.toml").read_text(encoding="utf-8")
    text = text.replace('at = [0.0, 0.0] }', f'at = [{offset!r}, {offset!r}] }}')
    text = text.replace('at = ["d", 0.0] }', 'at = { from = "O", length = "d", angle = 0.0 } }')
    path = tmp_path / f"design_{offset:g}.toml"
    path.write_text(text, encoding="utf-8")
    return str(path)


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_design_study_far_away_gives_the_origins_designs(tmp_path, capsys, backend):
    """Four variants of models/fourbar_design.toml studied 1e6 m from the origin (the design batch,
    numpy's or the compiled one): every one turns fully as at the origin (before: false dead points),
    with the same transmission angles and coupler curve (moved)."""
    variants = tmp_path / "variants.csv"
    variants.write_text("variant,a,b,d\n1,0.10,0.30,0.30\n2,0.08,0.32,0.30\n3,0.12,0.28,0.29\n4,0.1,0.35,0.33\n")
    docs = []
    for offset in (0.0, 1e6):
        assert main(["--backend", backend, "--no-cache", "study", _design_model(tmp_path, offset), "--variants",
                     str(variants), "--points", "M", "--json", "--no-progress"]) == 0
        docs.append(json.loads(capsys.readouterr().out))
    near, far = docs
    assert far["counts"] == near["counts"] == {"designs": 4, "assembled": 4, "full_turn": 4, "locking": 0}
    for d0, d1 in zip(near["designs"], far["designs"]):
        assert d1["limits"] == d0["limits"] == []
        assert abs(d1["transmission_min_deg"] - d0["transmission_min_deg"]) < 1e-6
        m0, m1 = (np.array(d["samples"]["M"], float) for d in (d0, d1))
        assert np.abs(m1 - 1e6 - m0).max() < 1e-7


def test_path_synthesis_on_targets_far_from_the_origin():
    """models/synthesis/path_twelve.csv's targets 1e4 spans from the origin: a design as good as at the
    origin (before: "no design found", every candidate with a false dead point)."""
    from mbplanar.synthesis import synthesise_path

    targets = np.loadtxt(MODELS / "synthesis" / "path_twelve.csv", delimiter=",", skiprows=2)
    span = np.ptp(targets, axis=0).max()
    near = synthesise_path(targets, seed=1, starts=1)
    far = synthesise_path(targets + 1e4 * span, seed=1, starts=1)
    assert far.success and near.success
    assert far.rms == pytest.approx(near.rms, rel=1e-6)
