"""Higher pairs in the engine (gear, rack, cam, slot), each checked against numbers written here: Willis'
formula for planetary and compound trains, the geared five-bar's and the slotted four-bar's closed forms,
the Scotch yoke's x = a·cos φ, the follower's lift, speed, pressure angle and contact force that
`mbplanar.cam` computes for the same cam, hand statics of a spur pair carrying a torque, virtual power;
property tests (closure after solve, rates equal to finite differences) on random gears, cam profiles and
slot arcs; the structure (W = 3n − 2p5 − p4, the equivalent mechanism's groups); bad pairs refused."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import mbplanar
from mbplanar.cli import main
from mbplanar.errors import ModelError
from mbplanar.forces import kinetostatics
from mbplanar.kinematics._contacts import contacts

MODELS = Path(__file__).resolve().parent.parent / "models"


def _engine(name: str, **kw):
    return mbplanar.Engine(mbplanar.read_model(MODELS / f"{name}.toml"), **kw)


def _turn_of(engine, phi):
    """φ (B,) a full turn of the input from the drawn pose."""
    return engine.phi_drawn[0] + np.linspace(0.0, 2 * math.pi, phi)


def _wq(motion, link):
    return motion.wq[:, motion.link(link)]


# -- gear trains: Willis ------------------------------------------------------------------------------
def test_planetary_2kh_by_willis():
    """Sun 20, planet 46, fixed ring 112 on the carrier H: (ω1 − ωH)/(ω3 − ωH) = −z3/z1 with ω3 = 0 gives
    ωH/ω1 = z1/(z1 + z3); the planet (ω2 − ωH)/(ω1 − ωH) = −z1/z2. To 1e-12 at every position."""
    engine = _engine("planetary")
    m = mbplanar.analyse(engine, _turn_of(engine, 73))
    z1, z2, z3 = 20, 46, 112
    w1, w2, wh = _wq(m, "1"), _wq(m, "2"), _wq(m, "H")
    np.testing.assert_allclose(w1, 1.0, rtol=0, atol=1e-15)
    np.testing.assert_allclose(wh, z1 / (z1 + z3), rtol=0, atol=1e-12)
    np.testing.assert_allclose((w2 - wh) / (w1 - wh), -z1 / z2, rtol=0, atol=1e-12)
    np.testing.assert_allclose(m.eq[:, 1:], 0.0, atol=1e-12)      # constant ratios: no angular acceleration
    assert engine.period() == pytest.approx(2 * math.pi * 6.6)      # when the carrier is back: 6.6 turns


# the train `mbplanar gear planetary` writes (docs/gears.md, "The model of a train"): scheme B, a two-row
# planet, sun 18 in, carrier out, then a shifted pair 12/30 on fixed axes, the rows in that helper's format
GEARS_TRAIN = """
name = "drive"
links = [ { name = "1" }, { name = "2" }, { name = "H" }, { name = "out" } ]
joints = [
  { name = "O1", type = "R", links = ["0", "1"], at = [0.0, 0.0] },
  { name = "OH", type = "R", links = ["0", "H"], at = [0.0, 0.0] },
  { name = "O2", type = "R", links = ["H", "2"], at = [0.051000000000000004, 0.0] },
  { name = "G12", type = "gear", links = ["1", "2"], teeth = [18, 33], module = 0.002, mesh = "external", carrier = "H", pressure_angle = 20.0, at = [0.018000000000000002, 0.0] },
  { name = "G34", type = "gear", links = ["2", "0"], teeth = [19, 70], module = 0.002, mesh = "internal", carrier = "H", pressure_angle = 20.0, at = [0.07, 0.0] },
  { name = "Oout", type = "R", links = ["0", "out"], at = [0.0, -0.21972229113017286] },
  { name = "G56", type = "gear", links = ["H", "out"], teeth = [12, 30], radii = [0.06277779746576367, 0.15694449366440916], mesh = "external", carrier = "0", pressure_angle = 21.5, at = [0.0, -0.06277779746576367] },
]
[input]
joint = "O1"
name = "phi"
"""


def test_a_written_train_reads_and_solves_by_willis():
    """Scheme B: u_1H = 1 + z2·z4/(z1·z3) = 1 + 33·70/(18·19), the planet (ω2 − ωH)/(ω1 − ωH) = −z1/z2,
    then the pair: ω_out/ωH = −r_H/r_out = −12/30. To 1e-12."""
    engine = mbplanar.Engine(mbplanar.parse_model(GEARS_TRAIN, "drive.toml"))
    m = mbplanar.analyse(engine, _turn_of(engine, 37))
    w1, w2, wh, wo = (_wq(m, n) for n in ("1", "2", "H", "out"))
    np.testing.assert_allclose(w1 / wh, 1 + 33 * 70 / (18 * 19), rtol=1e-12)
    np.testing.assert_allclose((w2 - wh) / (w1 - wh), -18 / 33, rtol=1e-12)
    np.testing.assert_allclose(wo / wh, -12 / 30, rtol=1e-12)
    assert engine.mech.higher["G34"].internal and engine.laws["G12"].carrier == "H"


@pytest.mark.parametrize("scheme, ratio", [("A", 7.0), ("B", 7.7392), ("C", 30.0), ("D", 19.348)])
def test_the_trains_mbplanar_gear_writes_solve_by_willis(scheme, ratio):
    """Every scheme of `mbplanar gear planetary`'s trains (two rows, internal meshes named either way round)
    and a train with its stage: the model it writes reads and solves, and the engine's ratio of the input
    to the output is the train's, u_1H = 1 − u^H_14 by Willis, to 1e-12."""
    from mbplanar.gears import gear_pair, planetary_trains
    from mbplanar.gears.planetary import SCHEMES
    from mbplanar.gears.trainmodel import Stage, train_model
    train = planetary_trains(ratio, scheme, planets=3, module=2e-3).trains[0]
    sch = SCHEMES[scheme]
    stage = Stage.from_pair(gear_pair(10e-3, (12, 30), (0.5923, 0.5278))) if scheme == "B" else None
    engine = mbplanar.Engine(mbplanar.parse_model(train_model(train, stage=stage), "train.toml"))
    m = mbplanar.analyse(engine, _turn_of(engine, 13))
    out = _wq(m, "out") if stage else _wq(m, "1" if sch.driven_by_carrier else "H")
    willis = (1 / (1 - train.willis)) if sch.driven_by_carrier else 1 - train.willis
    np.testing.assert_allclose(1 / out, willis * (-2.5 if stage else 1.0), rtol=1e-12)


def test_compound_train_of_the_geared_shaper_by_willis():
    """Three pairs on fixed axes, 20/66, 18/72, 73/107: the motor turns (−1)³·(66/20)(72/18)(107/73) =
    −7062/365 times the crank (n_d/n1 = 23.54·60/73 exactly), each shaft by its own product. To 1e-12."""
    engine = _engine("shaper_geared")
    m = mbplanar.analyse(engine, _turn_of(engine, 25))
    w1 = _wq(m, "1")
    np.testing.assert_allclose(_wq(m, "i2") / w1, -107 / 73, rtol=1e-12)
    np.testing.assert_allclose(_wq(m, "i1") / w1, (107 / 73) * (72 / 18), rtol=1e-12)
    np.testing.assert_allclose(_wq(m, "m") / w1, -7062 / 365, rtol=1e-12)
    assert 7062 / 365 == pytest.approx(23.54 * 60 / 73, rel=1e-15)


# -- the geared five-bar: its closed form -------------------------------------------------------------
def _circles(a, b, ra, rb, left=True):
    """The intersection of the circles about a (radius ra) and b (radius rb) to the left of a→b (B, 2)."""
    d = b - a
    dist = np.hypot(d[:, 0], d[:, 1])
    along = (ra * ra - rb * rb + dist * dist) / (2 * dist)
    h = np.sqrt(ra * ra - along * along)
    u = d / dist[:, None]
    n = np.stack([-u[:, 1], u[:, 0]], axis=1)
    return a + along[:, None] * u + (1.0 if left else -1.0) * h[:, None] * n


def test_geared_five_bar_closed_form():
    """Cranks OA and EB (50 mm) coupled by gears of pitch radii 40 and 80 mm: θ4 − θ4₀ = −(40/80)(θ1 − θ1₀);
    P is where circles of 150 mm about A and B meet (the drawn branch: left of A→B). Over two turns of
    OA: P, the links' angles and the gears' law to 1e-10."""
    engine = _engine("geared_five_bar")
    phi = engine.phi_drawn[0] + np.linspace(0.0, 4 * math.pi, 241)
    m = mbplanar.analyse(engine, phi)
    assert m.success
    th1 = phi                                          # the crank's angle: the input, measured from +x
    th4 = math.pi / 2 - 0.5 * (th1 - math.pi / 2)      # EB drawn upright too, turning half as fast back
    a = 0.05 * np.stack([np.cos(th1), np.sin(th1)], axis=1)
    b = np.array([0.12, 0.0]) + 0.05 * np.stack([np.cos(th4), np.sin(th4)], axis=1)
    p = _circles(a, b, 0.15, 0.15, left=True)
    np.testing.assert_allclose(m.xy[:, m.point("A")], a, atol=1e-12)
    np.testing.assert_allclose(m.xy[:, m.point("B")], b, atol=1e-12)
    np.testing.assert_allclose(m.xy[:, m.point("P")], p, atol=1e-10)
    np.testing.assert_allclose(_wq(m, "4"), -0.5, atol=1e-12)
    assert engine.period() == pytest.approx(4 * math.pi)   # EB back upright after two turns of OA


# -- a cam built by mbplanar.cam ----------------------------------------------------------------------
def _designed_cam(follower: str, contact: str):
    """mbplanar.cam's design of a smooth cam (a simple-harmonic rise and return of 180° each), its
    geometry at 1440 angles."""
    from mbplanar.cam import design
    from mbplanar.cam.spec import parse_cam
    cam = {"follower": follower, "contact": contact, "rotation": "ccw",
           "phases": [{"kind": "rise", "angle": 180.0, "law": "simple_harmonic", "stroke": 0.02},
                      {"kind": "return", "angle": 180.0, "law": "simple_harmonic"}]}
    if follower == "translating":
        cam.update(base_radius=0.05, offset=0.01 if contact != "flat" else 0.0)
    else:
        cam.update(base_radius=0.05, centre_distance=0.12, arm=0.09, arm_angle=30.0)
    if contact == "roller":
        cam["roller"] = 0.012
    return design(parse_cam({"cam": cam}))


def _cam_linkage(d):
    """The cam of design `d` as a linkage: a `cam` pair whose profile is the design's profile points (its
    cam angles the spline's parameter), the follower on a guide or a pivot where the design puts it."""
    g, f = d.geometry, d.follower
    profile = {"points": g.profile.tolist(), "parameter": list(g.phi) + [2 * math.pi]}
    links = [{"name": "cam"}, {"name": "f", "mass": 0.5, "centre": "B"}]
    joints = [{"name": "O", "type": "R", "links": ["0", "cam"], "at": [0.0, 0.0]}]
    pair = {"name": "K", "type": "cam", "links": ["cam", "f"], "follower": f.contact if f.contact != "flat" else "flat",
            "at": "B", "profile": profile}
    if f.motion == "translating":
        b0 = [f.offset, math.sqrt(f.base_radius ** 2 - f.offset ** 2)] if f.contact != "flat" else [0.0, f.base_radius]
        joints.append({"name": "F", "type": "P", "links": ["0", "f"], "at": b0, "guide": 90.0})
    else:
        pivot = np.array([0.0, -f.centre_distance])
        b0 = (pivot + f.arm * np.array([math.cos(math.pi / 2 + f.arm_angle), math.sin(math.pi / 2 + f.arm_angle)])).tolist()
        joints.append({"name": "F", "type": "R", "links": ["0", "f"], "at": pivot.tolist()})
    if f.contact == "roller":
        pair["radius"] = f.roller
    if f.contact == "flat":
        pair["face"] = 0.0
    joints.append(pair)
    return mbplanar.parse_model({"name": "cam_linkage", "links": links, "joints": joints,
                                 "points": [{"name": "B", "link": "f", "at": b0}],
                                 "input": {"joint": "O", "unit": "rad", "omega": 60.0}}, "cam.toml")


@pytest.mark.parametrize("follower, contact", [("translating", "roller"), ("oscillating", "roller"),
                                               ("translating", "knife"), ("translating", "flat")])
def test_cam_follower_equals_mbplanar_cam(follower, contact):
    """The linkage's follower runs as the cam module's law says: lift s(φ), ds/dφ and d²s/dφ² (translating:
    the guide's displacement; oscillating: the arm's arc l·Δθ) and the pressure angle, at its 1440 angles,
    to 1e-9 (of the stroke, m/rad and rad)."""
    d = _designed_cam(follower, contact)
    g = d.geometry
    engine = mbplanar.Engine(_cam_linkage(d))
    m = mbplanar.analyse(engine, g.phi)
    assert m.success
    k = m.joint("F")
    scale = d.follower.arm if follower == "oscillating" else 1.0
    np.testing.assert_allclose(m.value[:, k] * scale - (m.value[0, k] * scale - g.s[0]), g.s, rtol=0, atol=1e-9 * 0.02)
    np.testing.assert_allclose(m.rate_q[:, k] * scale, g.v, rtol=0, atol=1e-9)
    np.testing.assert_allclose(m.accel_q[:, k] * scale, g.a, rtol=0, atol=1e-8)
    angle = contacts(engine, m)["K"].pressure_angle
    np.testing.assert_allclose(angle, g.pressure, rtol=0, atol=1e-9)


def test_cam_contact_force_equals_mbplanar_cam_and_says_where_it_pulls():
    """A follower of 0.5 kg on a spring (2000 N/m, 60 N at zero lift) at ω = 60 and 160 rad/s: the normal
    contact force N = Q/(n·∂X/∂s) of `mbplanar.cam.cam_forces` to 1e-9 of its largest, and it pulls (the
    follower leaves the cam) at exactly the positions the cam module says; the virtual power balances."""
    from mbplanar.cam.dynamics import cam_forces
    from mbplanar.cam.spec import DynamicsSpec
    d = _designed_cam("translating", "roller")
    g = d.geometry
    mech = _cam_linkage(d)
    mech.add_point("T", "f", at=(0.01, 0.15))
    mech.add_load("spring", links=["0", "f"], at=[[0.01, 0.25], "T"], stiffness=2000.0, free_length=0.13)
    engine = mbplanar.Engine(mech)
    for omega in (60.0, 160.0):
        m = mbplanar.analyse(engine, g.phi, omega=omega)
        ks = kinetostatics(engine, m)
        cam = cam_forces(g, DynamicsSpec(omega, 0.5, 2000.0, 60.0))
        normal = ks.contact_forces["K"]
        np.testing.assert_allclose(normal, cam.contact, rtol=0, atol=1e-9 * np.abs(cam.contact).max())
        np.testing.assert_array_equal(ks.pulling["K"], cam.contact < 0)
        assert ks.success == (not cam.lift_off.any())
        assert ks.virtual_power_residual.max() < 1e-9
    assert not ks.success and "would pull" in ks.message          # at 160 rad/s it leaves the cam


# -- slots: a pin in a circular slot, a Scotch yoke ---------------------------------------------------
def test_pin_in_a_circular_slot_is_a_four_bar():
    """The crank's pin A (60 mm) in an arc of the rocker about its point D: A stays on the circle of radius
    |A₀D₀| about D, so D is where that circle about A meets the circle of radius |CD₀| about C (the
    four-bar O–A–D–C, its closed form). D and the rocker's angle to 1e-10 over a turn."""
    engine = _engine("slot_arc")
    phi = _turn_of(engine, 145)
    m = mbplanar.analyse(engine, phi)
    assert m.success
    a0, d0, c = np.array([0.0, 0.06]), np.array([0.25, 0.31]), np.array([0.3, 0.0])
    a = 0.06 * np.stack([np.cos(phi), np.sin(phi)], axis=1)
    cc = np.broadcast_to(c, a.shape)
    d = _circles(a, cc, np.linalg.norm(a0 - d0), np.linalg.norm(c - d0), left=True)
    np.testing.assert_allclose(m.xy[:, m.point("D")], d, atol=1e-10)
    rocker = np.unwrap(np.arctan2(d[:, 1] - c[1], d[:, 0] - c[0]) - math.atan2(d0[1] - c[1], d0[0] - c[0]))
    np.testing.assert_allclose(m.frames.th[:, engine.link_index["2"]], rocker, atol=1e-10)
    assert [g.kind for g in engine.topology.structure.groups] == ["RRR"]   # the equivalent four-bar's dyad


def test_scotch_yoke_written_with_a_slot():
    """The yoke's displacement is a·cos φ − a (a = 50 mm), its velocity and acceleration analogues −a·sin φ
    and −a·cos φ, to 1e-10; the pin's place along the straight slot is a·sin φ (the spline's chord
    parameter from its first point). The slot is straight: its equivalent pair on the yoke is prismatic."""
    engine = _engine("scotch_yoke")
    phi = _turn_of(engine, 73)
    m = mbplanar.analyse(engine, phi)
    k, a = m.joint("Y"), 0.05
    np.testing.assert_allclose(m.value[:, k], a * np.cos(phi) - a, atol=1e-10)
    np.testing.assert_allclose(m.rate_q[:, k], -a * np.sin(phi), atol=1e-10)
    np.testing.assert_allclose(m.accel_q[:, k], -a * np.cos(phi), atol=1e-10)
    np.testing.assert_allclose(m.frames.contact[:, 0] - 0.08, a * np.sin(phi), atol=1e-10)
    assert engine.topology.structure.groups[0].kind == "RPP"


# -- forces: hand statics of a spur pair, virtual power -----------------------------------------------
@pytest.mark.parametrize("internal", [False, True])
@given(st.floats(0.02, 0.1), st.floats(1.5, 4.0), st.floats(-math.pi, math.pi), st.floats(10.0, 30.0),
       st.floats(-200.0, 200.0), st.floats(-math.pi, math.pi))
@settings(max_examples=12, deadline=None)
def test_spur_pair_carrying_a_torque(internal, r1, ratio, direction, alpha, moment, at):
    """Gear 1 (input) drives gear 2 loaded by a moment M, centres on the frame: the tangential force on 2 is
    F_t = M/r2 at the pitch point, the radial tan α·|F_t| pushes the teeth apart, each bearing takes the
    opposite of its gear's contact force, and the drive M·r1/r2. To 1e-10 relative (hand statics)."""
    assume(abs(moment) > 1.0)
    r2 = ratio * r1
    m_dir = np.array([math.cos(direction), math.sin(direction)])
    o2 = (r2 - r1 if internal else r1 + r2) * m_dir
    mech = mbplanar.Mechanism("spur")
    mech.add_link("1")
    mech.add_link("2")
    mech.add_joint("O1", "R", "0", "1", at=(0.0, 0.0))
    mech.add_joint("O2", "R", "0", "2", at=tuple(o2))
    mech.add_higher("G", "gear", "1", "2", radii=(r1, r2), internal=internal, pressure_angle=math.radians(alpha))
    mech.add_input("O1", unit="rad")
    mech.add_load("moment", link="2", moment=moment)
    engine = mbplanar.Engine(mech)
    m = mbplanar.analyse(engine, engine.phi_drawn[0] + np.array([0.0, at]))
    ks = kinetostatics(engine, m)
    # by hand: the pitch point P, the line of centres out of gear 1 through P, the tangent
    p = -r1 * m_dir if internal else r1 * m_dir
    out = p / np.linalg.norm(p)
    t = np.array([-out[1], out[0]])
    lever = p - o2
    f_t = -moment / (lever[0] * t[1] - lever[1] * t[0])          # the moment about O2 balances M
    force = f_t * t + math.tan(math.radians(alpha)) * abs(f_t) * out
    size = abs(f_t) / math.cos(math.radians(alpha))
    for row in range(2):
        got = np.array([ks.reactions["G"].fx[row], ks.reactions["G"].fy[row]])
        np.testing.assert_allclose(got, force, rtol=0, atol=1e-10 * size)
        for joint, sign in (("O2", -1.0), ("O1", 1.0)):          # on gear 2 from the frame; on gear 1 from it
            r = ks.reactions[joint]
            np.testing.assert_allclose([r.fx[row], r.fy[row]], sign * force, rtol=0, atol=1e-10 * size)
        drive = -(p[0] * -force[1] - p[1] * -force[0])          # what balances −F at P on gear 1
        assert ks.balancing["O1"][row] == pytest.approx(drive, rel=1e-10)
        assert abs(drive) == pytest.approx(abs(moment) * r1 / r2, rel=1e-10)
    np.testing.assert_allclose(ks.contact_forces["G"], f_t, rtol=1e-10)
    assert ks.virtual_power_residual.max() < 1e-12


@pytest.mark.parametrize("name", ["shaper_geared", "geared_five_bar", "planetary", "rack_pinion", "cam_eccentric",
                                  "cam_follower", "slot_arc", "scotch_yoke"])
def test_virtual_power_residual_everywhere(name):
    """Every model with higher pairs, with its loads (or a force and a moment on every moving link where it has
    none) and masses, at a speed and acceleration: the virtual power of the loads and the drive vanishes at
    each of 360 positions to 1e-9 (the contact forces do no work: the pitch circles roll; a cam's and a
    slot's force is normal to the relative motion)."""
    mech = mbplanar.read_model(MODELS / f"{name}.toml")
    if not mech.loads:
        for k, link in enumerate(mech.moving_links):
            mech.add_load("force", link=link, at=list(mech.joints_of(link)[0].at), force=[10.0 + k, -20.0])
            mech.add_load("moment", link=link, moment=1.5 - k)
    engine = mbplanar.Engine(mech)
    m = mbplanar.analyse(engine, _turn_of(engine, 360), omega=3.0, epsilon=-2.0)
    ks = kinetostatics(engine, m, input_inertia=0.2)
    assert np.nanmax(ks.virtual_power_residual) <= 1e-9


def test_friction_in_a_cam_contact():
    """μ·|N| against the sliding at a flat-faced follower's contact with an eccentric (a spring presses
    it on): the virtual power still balances (the friction is a load), the friction's power is a loss,
    and the drive does work over the cycle, none without it. A roller rolls: no friction there."""
    from mbplanar.forces import FrictionSpec, friction_kinetostatics, read_friction
    from mbplanar.forces._friction import PairFriction
    mech = mbplanar.parse_model("""
        name = "flat_face"
        links = [ { name = "cam" }, { name = "f", mass = 0.3, centre = "F" } ]
        joints = [
          { name = "O", type = "R", links = ["0", "cam"], at = [0.0, 0.0] },
          { name = "F", type = "P", links = ["0", "f"], at = [0.0, 0.06], guide = 90.0 },
          { name = "K", type = "cam", links = ["cam", "f"], follower = "flat", face = 0.0, at = [0.0, 0.06], profile = { centre = [0.02, 0.0], radius = 0.06 } },
        ]
        loads = [ { type = "force", link = "f", at = "F", force = [0.0, -40.0] } ]
        [input]
        joint = "O"
        """, "flat.toml")
    engine = mbplanar.Engine(mech)
    m = mbplanar.analyse(engine, _turn_of(engine, 73), omega=8.0)
    fr = friction_kinetostatics(engine, m, FrictionSpec((PairFriction("K", 0.15),)))
    assert fr.converged and fr.iterations > 1
    assert fr.kinetostatics.virtual_power_residual.max() < 1e-9
    assert np.all(fr.losses <= 1e-12) and fr.losses.min() < 0
    q, phi = fr.kinetostatics.balancing["O"], m.phi[:, 0]
    work, ideal = (float(np.sum((y[1:] + y[:-1]) * np.diff(phi)) / 2) for y in (q, fr.ideal.balancing["O"]))
    assert work > 0 and abs(ideal) < 1e-12 * work         # a conservative load: only the friction takes work
    rolling = mbplanar.read_model(MODELS / "cam_eccentric.toml")
    rolling.extras["friction"] = {"mu": 0.1, "pin_radius": 0.005}
    assert [p.joint for p in read_friction(rolling).pairs] == ["O", "C"]     # the roller's cam pair: none


# -- the geared shaper's dynamics ---------------------------------------------------------------------
def test_geared_shaper_flywheel_on_the_motor_shaft():
    """The shaper with its gear train: the same J_I as models/shaper.toml, the first group holding the
    crank's gear (0.1625 kg·m²) and the motor's rotor (0.0875 kg·m²) reduced to the crank by u² with the
    gears' u = 7062/365, and the flywheel on the motor shaft J_m = (J_I − 0.1625 − 0.0875·u²)/u², the
    seed's 0.305132 kg·m², equal to the other model's (its motor_rpm formula) to 1e-12."""
    from mbplanar.forces import machine_dynamics
    geared = machine_dynamics(_engine("shaper_geared"), simulate_motion=False)
    plain = machine_dynamics(_engine("shaper"), simulate_motion=False)
    u = 7062 / 365
    assert geared.flywheel.speed_ratio == pytest.approx(u, rel=1e-12)
    assert geared.flywheel.shaft == "m"
    assert geared.inertia_first_group == pytest.approx(plain.inertia_first_group, rel=1e-12)
    np.testing.assert_allclose(geared.J_II, plain.J_II, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(geared.reduced.J_input, 0.1625 + 0.0875 * u * u, rtol=1e-12)
    assert geared.flywheel.inertia == pytest.approx(plain.flywheel.inertia, rel=1e-10)
    assert geared.flywheel.inertia == pytest.approx(0.305132, abs=5e-7)


# -- property tests: closure and rates on random pairs ------------------------------------------------
def _closure_and_rates(engine, phi, check):
    """Newton's closure (`check(motion)` small) and the analogues against central differences of the
    positions."""
    m = mbplanar.analyse(engine, phi)
    assume(m.success)
    check(m)
    h = 1e-6
    up, down = mbplanar.analyse(engine, phi + h), mbplanar.analyse(engine, phi - h)
    assume(up.success and down.success)
    scale = 1.0 + np.abs(m.wq).max()
    np.testing.assert_allclose(m.wq, np.unwrap(up.angle - down.angle, axis=0) / (2 * h), atol=1e-6 * scale)
    np.testing.assert_allclose(m.vq, (up.xy - down.xy) / (2 * h), atol=1e-6 * engine.size * scale)
    np.testing.assert_allclose(m.eq, (up.wq - down.wq) / (2 * h), atol=1e-5 * scale * scale)


@given(st.floats(0.02, 0.2), st.floats(0.02, 0.2), st.booleans(), st.floats(0.1, 1.4))
@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
def test_random_geared_five_bars(r1, r2, internal, lean):
    """A geared five-bar of random gear radii (external or internal): the gears' law r1·Δθ1 = ∓r2·Δθ4 holds
    to 1e-12 after solve, and the rates are the positions' derivatives."""
    assume(not internal or abs(r1 - r2) > 0.02)
    d = abs(r1 - r2) if internal else r1 + r2
    c = 0.06
    mech = mbplanar.Mechanism("g5")
    for name in ("1", "2", "3", "4"):
        mech.add_link(name)
    e = np.array([d, 0.0])
    a, b = c * np.array([math.cos(lean), math.sin(lean)]), e + c * np.array([0.0, 1.0])
    p = _circles(a[None], b[None], 0.25, 0.25, left=False)[0]
    mech.add_joint("O", "R", "0", "1", at=(0.0, 0.0))
    mech.add_joint("E", "R", "0", "4", at=tuple(e))
    mech.add_joint("A", "R", "1", "2", at=tuple(a))
    mech.add_joint("B", "R", "4", "3", at=tuple(b))
    mech.add_joint("P", "R", "2", "3", at=tuple(p))
    small, big = sorted((r1, r2))
    radii = (small, big) if internal else (r1, r2)
    mech.add_higher("G", "gear", "1", "4", radii=radii, internal=internal)
    mech.add_input("O", unit="rad")
    engine = mbplanar.Engine(mech)
    phi = engine.phi_drawn[0] + np.linspace(-0.4, 0.4, 9)

    def law(m):
        th1 = m.frames.th[:, engine.link_index["1"]]
        th4 = m.frames.th[:, engine.link_index["4"]]
        sign = -1.0 if internal else 1.0
        np.testing.assert_allclose(radii[0] * th1 + sign * radii[1] * th4, 0.0, atol=1e-12 * engine.size)
    _closure_and_rates(engine, phi, law)


@st.composite
def cam_profiles(draw):
    """A random smooth closed cam profile: a circle of radius 0.05 about the shaft's neighbourhood with
    two random harmonics of its radius, 180 points through it (a convex shape: small harmonics)."""
    c = (draw(st.floats(-0.01, 0.01)), draw(st.floats(-0.01, 0.01)))
    h2, h3 = draw(st.floats(-0.003, 0.003)), draw(st.floats(-0.002, 0.002))
    t = np.linspace(0.0, 2 * math.pi, 181)[:-1]
    rad = 0.05 + h2 * np.cos(2 * t + 0.3) + h3 * np.sin(3 * t)
    return np.stack([c[0] + rad * np.cos(t), c[1] + rad * np.sin(t)], axis=1)


@given(cam_profiles(), st.sampled_from(["knife", "roller"]), st.floats(-0.01, 0.01))
@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
def test_random_cam_profiles(points, follower, offset):
    """A translating follower on a random spline profile: after solve the follower's point is on the profile
    (a knife) or a roller's radius from it, to 1e-12 of the size; the rates are the positions'
    derivatives."""
    from mbplanar.model._curves import Spline
    spline = Spline(points, closed=True)
    u = np.linspace(spline.lo, spline.hi, 20001)
    xy = spline.point(u).T
    near = np.abs(xy[:, 0] - offset) < 2e-4
    top = u[near][np.argmax(xy[near, 1])]
    from scipy.optimize import brentq
    top = brentq(lambda s: spline.point(np.array([s]))[0, 0] - offset, top - 1e-3, top + 1e-3)
    contact = spline.point(np.array([top]))[:, 0]
    radius = 0.01 if follower == "roller" else 0.0
    d1 = spline.point(np.array([top]), 1)[:, 0]
    normal = np.array([d1[1], -d1[0]]) / np.hypot(*d1)         # outwards: the points run counter-clockwise
    at = contact + radius * normal
    assume(abs(normal[0]) < 0.5)                                 # the follower not too far off the normal
    mech = mbplanar.Mechanism("cam")
    mech.add_link("cam")
    mech.add_link("f")
    mech.add_joint("O", "R", "0", "cam", at=(0.0, 0.0))
    mech.add_joint("F", "P", "0", "f", at=tuple(at), guide=90.0)
    from mbplanar.model._model import Curve
    mech.add_higher("K", "cam", "cam", "f", at=tuple(at), follower=follower, radius=radius,
                    curve=Curve("spline", points=tuple(map(tuple, points)), closed=True))
    mech.add_input("O", unit="rad")
    engine = mbplanar.Engine(mech)

    def touches(m):
        f_xy = m.xy[:, m.point("F")]
        th = m.frames.th[:, engine.link_index["cam"]]
        local = np.stack([np.cos(th) * f_xy[:, 0] + np.sin(th) * f_xy[:, 1],
                          -np.sin(th) * f_xy[:, 0] + np.cos(th) * f_xy[:, 1]], axis=1)
        for p in local:
            assert abs(spline.closest(p)[1] - radius) < 1e-12 * engine.size
    _closure_and_rates(engine, engine.phi_drawn[0] + np.linspace(0.0, 0.6, 7), touches)


@given(st.floats(0.2, 0.5), st.floats(-1.0, 1.0), st.floats(0.03, 0.08), st.floats(0.5, 2.5))
@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
def test_random_slot_arcs(radius, bend, crank, reach):
    """A crank's pin in a random arc of a rocker: after solve the pin is on the arc (its distance from the
    arc's centre, a point of the rocker, is the radius) to 1e-12; the rates are the positions'
    derivatives."""
    a0 = np.array([0.0, crank])
    c = np.array([reach * radius, 0.0])
    centre = a0 + radius * np.array([math.cos(bend), math.sin(bend)])
    assume(np.linalg.norm(centre - c) > 0.05 and np.linalg.norm(c) > 0.1)
    mech = mbplanar.Mechanism("slot")
    mech.add_link("1")
    mech.add_link("2")
    mech.add_joint("O", "R", "0", "1", at=(0.0, 0.0))
    mech.add_joint("C", "R", "0", "2", at=tuple(c))
    mech.add_point("A", "1", at=tuple(a0))
    mech.add_point("D", "2", at=tuple(centre))
    from mbplanar.model._model import Curve
    mech.add_higher("S", "slot", "2", "1", at=tuple(a0), point="A", curve=Curve("circle", centre=tuple(centre),
                                                                                    radius=radius))
    mech.add_input("O", unit="rad")
    try:
        engine = mbplanar.Engine(mech)
    except mbplanar.MotionError:
        assume(False)

    def on_arc(m):
        gap = np.linalg.norm(m.xy[:, m.point("A")] - m.xy[:, m.point("D")], axis=1)
        np.testing.assert_allclose(gap, radius, atol=1e-12 * engine.size)
    _closure_and_rates(engine, engine.phi_drawn[0] + np.linspace(-0.1, 0.1, 5), on_arc)


# -- structure: Chebyshev with p4, the equivalent mechanism ------------------------------------------
def test_info_counts_higher_pairs_and_decomposes_the_equivalent(capsys):
    """W = 3n − 2p5 − p4 and the engine's count; the higher pairs with their replacing links; the groups of
    the equivalent lower-pair mechanism with their classes."""
    assert main(["info", str(MODELS / "geared_five_bar.toml")]) == 0
    out = capsys.readouterr().out
    assert "W = 3·n − 2·p5 − p4 = 3·4 − 2·5 − 1 = 1 (Chebyshev)" in out
    assert "4 joint variables + 0 contact parameter(s) − 3 closure equations = 1" in out
    assert "higher pair G      gear  1–4" in out and "replaced by a link with R on 1" in out
    assert "group class 2 order 2 RRR: links 4, G'" in out and "I(0,1) → II(4,G') → II(2,3)" in out
    assert main(["info", str(MODELS / "cam_follower.toml"), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["count"] == {"n": 2, "p5": 2, "p4": 1, "chebyshev": 1, "joint_variables": 2, "contact_parameters": 1,
                            "closure_equations": 2, "engine": 1}
    assert doc["replaced"] == {"K'": "K"} and doc["higher_pairs"]["K"]["follower"] == "roller"
    assert [e["type"] for e in doc["higher_pairs"]["K"]["equivalent"]] == ["R", "R"]
    assert doc["groups"][0]["kind"] == "RRP"


@pytest.mark.parametrize("name, kinds", [("rack_pinion", ["RRP", "RRP"]), ("scotch_yoke", ["RPP"]),
                                         ("cam_eccentric", ["RRR"]), ("shaper_geared", ["RPR", "RRR", "RPP", "RRR", "RRR"])])
def test_equivalent_pairs_follow_the_curvature(name, kinds):
    """The replacing link's pairs: revolute at a centre of curvature, prismatic where a profile is straight (a
    rack, a flat face, a straight slot): the dyads' kinds."""
    assert [g.kind for g in _engine(name).topology.structure.groups] == kinds


def test_the_engine_solves_the_higher_pairs_grouped_or_not():
    """The Assur groups of the equivalent mechanism as solving blocks, or one global block: the same."""
    for name in ("shaper_geared", "cam_eccentric", "slot_arc"):
        mech = mbplanar.read_model(MODELS / f"{name}.toml")
        grouped, single = mbplanar.Engine(mech), mbplanar.Engine(mech, grouped=False)
        phi = _turn_of(grouped, 25)
        a, b = mbplanar.analyse(grouped, phi), mbplanar.analyse(single, phi)
        np.testing.assert_allclose(a.xy, b.xy, atol=1e-12 * grouped.size)
        np.testing.assert_allclose(a.wq, b.wq, atol=1e-10)


# -- bad pairs ----------------------------------------------------------------------------------------
BAD = [
    ("geared_five_bar", ('teeth = [16, 32], module = 0.005', 'radii = [0.04, 0.07]'),
     "joint 'G' (gear): the gears' centres are 0.12 m apart, but their pitch radii 0.04 m and 0.07 m need 0.11 m"),
    ("geared_five_bar", ('teeth = [16, 32]', 'teeth = [0, 32]'), "a tooth number must be a whole number >= 1, got 0"),
    ("cam_eccentric", ('radius = 12.0', 'radius = 30.0'), "joint 'K' (cam): the roller's centre is 12 mm from the cam's "
                                                          "profile, not its radius 30 mm: the follower does not touch"),
    ("slot_arc", ('arc = [190.0, 260.0]', 'radius = 0.2, arc = [190.0, 260.0]'), "joint 'S' (slot): the pin is "),
    ("planetary", ('carrier = "H", at = [0.02, 0.0]', 'carrier = "H", at = [0.03, 0.0]'), "joint 'G12' (gear): the "
                                                                                        "pitch point 'at'"),
    ("planetary", ('mesh = "internal"', 'mesh = "external"'), "joint 'G23' (gear): the gears' centres are"),
    ("rack_pinion", ('teeth = 25', 'teeth = 25, guide = 10.0'), "must be square to the line from the pinion's centre"),
    ("cam_follower", ('follower = "roller", radius = 10.0', 'follower = "knife", radius = 10.0'),
     "a knife follower takes no 'radius'"),
    ("geared_five_bar", ('joint = "O"', 'joint = "G"'), "'G' is a higher pair (gear): an input drives a revolute"),
]


@pytest.mark.parametrize("name, edit, says", BAD, ids=[f"{b[0]}-{k}" for k, b in enumerate(BAD)])
def test_bad_higher_pairs_are_refused_naming_the_joint(name, edit, says, tmp_path, capsys):
    text = (MODELS / f"{name}.toml").read_text(encoding="utf-8")
    assert edit[0] in text
    path = tmp_path / f"{name}.toml"
    path.write_text(text.replace(edit[0], edit[1]), encoding="utf-8")
    for csv in MODELS.glob("*.csv"):
        (tmp_path / csv.name).write_text(csv.read_text(encoding="utf-8"), encoding="utf-8")
    assert main(["info", str(path)]) == 2
    err = capsys.readouterr().err
    assert says in err and "Traceback" not in err, err


# -- the backends -------------------------------------------------------------------------------------
def test_the_compiled_backend_takes_higher_pairs(capsys, caplog):
    """The numba backend's kinematics, kinetostatics and design kernels hold the higher pairs' laws: a cam
    model's sweep and forces are the compiled kernels' (the seam's log says so, the Motion holds the
    kernel's records with the contact parameters) and equal numpy's (tests/test_numba_higher.py: every
    bundled model, to 1e-12; tests/test_numba_design_higher.py: their design batches); no job is
    declined and the command line notes nothing."""
    pytest.importorskip("numba")
    import logging
    fast, ref = _engine("cam_eccentric", backend="numba"), _engine("cam_eccentric")
    phi = _turn_of(ref, 50)
    caplog.set_level(logging.DEBUG, logger="mbplanar.backends")
    a, b = mbplanar.analyse(fast, phi), mbplanar.analyse(ref, phi)
    assert "kinematics of 50: numba\n" in caplog.text + "\n"
    assert a.records is not None and "contact" in a.records.dtype.names
    np.testing.assert_allclose(a.xy, b.xy, rtol=0, atol=1e-12 * ref.size)
    np.testing.assert_allclose(a.frames.contact, b.frames.contact, rtol=0, atol=1e-12)
    assert main(["--backend", "numba", "solve", str(MODELS / "cam_eccentric.toml"), "--at", "30"]) == 0
    assert "note: backend numba" not in capsys.readouterr().err


# -- every command ------------------------------------------------------------------------------------
# (info, solve, forces, sweep, check and dynamics run on every bundled model in tests/test_units.py)
@pytest.mark.parametrize("command", [["report", "-o", "{tmp}/r.html"], ["plot", "diagram", "-o", "{tmp}/d.png"],
                                     ["plot", "diagram", "--show", "reactions", "-o", "{tmp}/f.png"],
                                     ["animate", "-o", "{tmp}/a.html"]])
@pytest.mark.parametrize("name", ["cam_follower", "planetary"])
def test_the_pictures_of_the_higher_pair_models(command, name, tmp_path, capsys):
    pytest.importorskip("matplotlib")
    argv = [c.replace("{tmp}", str(tmp_path)) for c in command]
    code = main([argv[0], str(MODELS / f"{name}.toml")] + argv[1:])
    err = capsys.readouterr().err
    assert code == 0 and "Traceback" not in err, err


def test_the_diagram_draws_the_pairs():
    """Gears as pitch circles with a mark per tooth and their mesh point, a cam's profile and its roller, a
    slot's walls: in the scene, placed by their links at every position."""
    from mbplanar.viz._scene import build_scene
    engine = _engine("geared_five_bar")
    m = mbplanar.analyse(engine, _turn_of(engine, 5))
    (pair,) = build_scene(engine, m).pairs
    assert [kind for kind, *_ in pair.lines] == ["pitch", "pitch"] and pair.marks.shape[1] == 16 + 32
    pitch = m.xy[:, m.point("G")]
    np.testing.assert_allclose(pair.contact, pitch, atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(pair.lines[0][2] - m.xy[:, m.point("O"), None], axis=-1), 0.04,
                               atol=1e-15)
    engine = _engine("cam_follower")
    kinds = [kind for kind, *_ in build_scene(engine, mbplanar.analyse(engine, [0.3])).pairs[0].lines]
    assert kinds == ["profile", "roller"]
    engine = _engine("slot_arc")
    kinds = [kind for kind, *_ in build_scene(engine, mbplanar.analyse(engine, [0.3])).pairs[0].lines]
    assert kinds == ["slot", "slot", "slot-centre"]


def test_a_design_batch_solves_each_design_of_a_higher_pair_model():
    """[parameters] in a higher pair's numbers (the slot's centre, with the rocker's point there): each
    design solved by its own engine, as the model itself is."""
    import tomllib
    from mbplanar.study import design_batch
    text = (MODELS / "slot_arc.toml").read_text(encoding="utf-8").replace("[0.25, 0.31]", '["cx", 0.31]')
    data = dict(tomllib.loads(text), parameters={"cx": 0.25})
    batch = design_batch(data, {"cx": np.array([0.24, 0.25, 0.26])})
    phi = np.radians(np.arange(0.0, 360.0, 30.0))
    got = batch.solve(phi)
    assert got.ok.all() and got.valid.all()
    for d, cx in enumerate((0.24, 0.25, 0.26)):
        ref = mbplanar.analyse(mbplanar.Engine(mbplanar.parse_model(dict(data, parameters={"cx": cx}))), phi)
        np.testing.assert_allclose(got.xy[d], ref.xy[:, [ref.point(p) for p in got.points]], atol=1e-12)


def test_path_synthesis_on_a_higher_pair_models_parameters():
    """`synth path --model` on [parameters] of a model with a slot: the slot's centre (and the rocker's
    point there) found again from the timed path of that point, to 1e-9 m."""
    import tomllib
    from mbplanar.synthesis.path_model import synthesise_model_path
    text = (MODELS / "slot_arc.toml").read_text(encoding="utf-8").replace("[0.25, 0.31]", '["cx", 0.31]')
    data = dict(tomllib.loads(text), parameters={"cx": 0.25})
    truth = mbplanar.Engine(mbplanar.parse_model(dict(data, parameters={"cx": 0.255})))
    phi = np.radians(np.arange(0.0, 360.0, 40.0))
    m = mbplanar.analyse(truth, phi)
    found = synthesise_model_path(data, "D", {"cx": (0.2, 0.3)}, m.xy[:, m.point("D")], timing=phi, starts=1,
                                  popsize=5, generations=3, samples=12)
    assert found.values["cx"] == pytest.approx(0.255, abs=1e-9) and found.errors.max() < 1e-9


def test_a_pin_stops_at_the_end_of_its_slot():
    """An arc of 20° (215° … 235° about D): the crank turns until the pin reaches an end, where the angle
    of D→A in the rocker's frame is 215° or 235° (the four-bar's closed form, solved by brentq here): the
    motion limits named for the slot, to 1e-9 rad."""
    from scipy.optimize import brentq
    text = (MODELS / "slot_arc.toml").read_text(encoding="utf-8").replace("arc = [190.0, 260.0]", "arc = [215.0, 235.0]")
    engine = mbplanar.Engine(mbplanar.parse_model(text, "slot_end.toml"))
    a0, d0, c = np.array([0.0, 0.06]), np.array([0.25, 0.31]), np.array([0.3, 0.0])
    radius, arm = np.linalg.norm(a0 - d0), np.linalg.norm(c - d0)
    drawn = math.atan2(d0[1] - c[1], d0[0] - c[0])

    def slot_angle(phi):
        a = 0.06 * np.array([[math.cos(phi), math.sin(phi)]])
        d = _circles(a, c[None], radius, arm, left=True)[0]
        turn = math.atan2(d[1] - c[1], d[0] - c[0]) - drawn
        return math.degrees(math.atan2(a[0, 1] - d[1], a[0, 0] - d[0]) - turn) % 360.0

    lo, hi = engine.reach()
    assert math.isclose(lo, brentq(lambda p: slot_angle(p) - 235.0, 0.3, 1.2), abs_tol=1e-9)
    assert math.isclose(hi, brentq(lambda p: slot_angle(p) - 215.0, 2.0, 3.0), abs_tol=1e-9)
    m = mbplanar.analyse(engine, np.linspace(lo - 0.1, hi + 0.1, 50))
    assert not m.success and all("the pin of 'S' at the end of its slot" in lim.kind for lim in m.limits)


def test_the_workbench_frames_carry_the_pairs():
    """The workbench's frames: each higher pair's lines, tooth marks and contact (the scene's), and a
    higher pair's reaction placed at its contact."""
    pytest.importorskip("tomlkit")
    from mbplanar.web._session import frames_of
    engine = _engine("rack_pinion")
    mech = engine.mech
    mech.add_load("moment", link="4", moment=2.0)
    engine = mbplanar.Engine(mech)
    m = mbplanar.analyse(engine, _turn_of(engine, 7))
    frames = frames_of(engine, m, m)
    (pair,) = frames["pairs"]
    assert [line["kind"] for line in pair["lines"]] == ["pitch", "rack"] and pair["marks"].shape[1] > 25
    np.testing.assert_allclose(frames["reactions"]["K"]["at"], pair["contact"])


def test_a_profile_file_is_read_beside_the_model_in_the_workbench_and_copied_with_it(tmp_path):
    """The workbench reads a gallery model's profile from the gallery and a served file's beside it (not
    from the working folder); `copy_examples` writes the profile with the model."""
    pytest.importorskip("tomlkit")
    from mbplanar.formats import copy_examples
    from mbplanar.web._session import Workbench
    written = copy_examples(["cam_follower"], tmp_path / "served" / "cams")
    assert sorted(p.name for p in written) == ["cam_follower.toml", "cam_roller_profile.csv"]
    text = written[0].read_text(encoding="utf-8")
    for name in ("gallery/cam_follower.toml", "cams/cam_follower.toml"):
        bench = Workbench(text, name, frames=12, folder=str(tmp_path / "served"))
        first = next(bench.refresh())
        assert not first["errors"] and "K" in bench.engine.mech.higher, name
    with pytest.raises(ModelError, match="cam_roller_profile.csv"):
        mbplanar.parse_model(text, source="cams/cam_follower.toml", folder=tmp_path)
