"""The higher pairs' compiled building blocks (`backends._numba_higher`) against numpy's laws
(`engine._higher`) and curves (`model._curves`): the curves' points and derivatives, each pair's closure
residuals, the rates that make a Jacobian column, the velocity's and the acceleration's right-hand side,
on random states of every kind of pair (gear, internal gear, rack, knife, roller, circular face, flat
face, pin in a slot), to 1e-12."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import mbplanar
from conftest import MODELS

pytest.importorskip("numba")

from mbplanar.backends._numba_higher import _curve_into, _higher_closure, _higher_rates  # noqa: E402
from mbplanar.engine._constraints import Pose, Rates  # noqa: E402
from mbplanar.engine._higher_tables import (CURVE_WORK, H_EQUATIONS, H_ROW, H_VAR, HIGHER_CACHE,  # noqa: E402
                                            curve_tables, higher_tables)
from mbplanar.model._curves import Circle, Offset, Spline  # noqa: E402

TOL = 1e-12


def _close(got, want, scale):
    """|got − want| <= 1e-12 of the larger of |want| and `scale` (componentwise)."""
    got, want = np.asarray(got, float), np.asarray(want, float)
    assert np.all(np.abs(got - want) <= TOL * np.maximum(np.abs(want), scale)), (got, want)


# -- curves ---------------------------------------------------------------------------------------------
@st.composite
def shapes(draw):
    """A circle, an arc, or a spline (closed or open, degree 3 or 5, by chord length or a given
    parameter) through random points around a circle; offset by a random distance or not."""
    kind = draw(st.sampled_from(["circle", "arc", "closed", "open"]))
    centre = (draw(st.floats(-0.1, 0.1)), draw(st.floats(-0.1, 0.1)))
    radius = draw(st.floats(0.02, 0.2))
    if kind == "circle":
        base = Circle(centre, radius)
    elif kind == "arc":
        lo = draw(st.floats(-math.pi, math.pi))
        base = Circle(centre, radius, (lo, lo + draw(st.floats(0.2, 2 * math.pi))))
    else:
        count = draw(st.integers(8, 40))
        wobble = draw(st.lists(st.floats(-0.15, 0.15), min_size=count, max_size=count))
        span = 2 * math.pi if kind == "closed" else draw(st.floats(0.5, 4.0))
        t = np.linspace(0.0, span, count + 1 if kind == "closed" else count)[:count]
        rad = radius * (1.0 + np.array(wobble) * 0.3)
        pts = np.stack([centre[0] + rad * np.cos(t), centre[1] + rad * np.sin(t)], axis=1)
        parameter = None
        if draw(st.booleans()):     # a parameter of its own (a cam angle), strictly increasing
            steps = np.array(draw(st.lists(st.floats(0.5, 2.0), min_size=count, max_size=count)))
            parameter = np.concatenate([[0.0], np.cumsum(steps)])[:count + 1 if kind == "closed" else count]
        base = Spline(pts, parameter, kind == "closed", draw(st.sampled_from([3, 5])))
    if draw(st.booleans()):
        return Offset(base, draw(st.floats(-0.3, 0.3)) * radius)
    return base


@given(shapes(), st.lists(st.floats(-1.5, 1.5), min_size=1, max_size=12))
@settings(max_examples=120, deadline=None)
def test_the_curves_and_their_derivatives_equal_numpys(shape, where):
    """c(u), c'(u), c''(u) (and c''' of a curve without offset) at random parameter values across its
    range and beyond it (a closed curve's repeats, an open one's extrapolated ends), to 1e-12 of each
    derivative's size along the curve."""
    cv = curve_tables([shape])
    wk, hc, unturned = np.zeros(CURVE_WORK), np.zeros((1, HIGHER_CACHE)), np.array([[0.0], [1.0], [0.0]])
    u = shape.lo + (np.array(where) + 0.5) * shape.period * (3.0 if shape.closed else 1.2)
    count = 3 if isinstance(shape, Offset) else 4
    got = np.empty((len(u), 2 * count))
    for k, x in enumerate(u):   # (on a link at rest: R = 1)
        _curve_into(cv, 0, float(x), count, 0, unturned, wk, hc, 0)
        got[k] = hc[0, :2 * count]
    for n in range(count):
        want = shape.point(u, n)
        scale = np.max(np.hypot(*shape.point(np.linspace(shape.lo, shape.hi, 64), n)))
        _close(got[:, 2 * n:2 * n + 2].T, want, scale)


# -- laws -----------------------------------------------------------------------------------------------
FLAT = """
name = "flat_face"
links = [ { name = "cam" }, { name = "f" } ]
joints = [
  { name = "O", type = "R", links = ["0", "cam"], at = [0.0, 0.0] },
  { name = "F", type = "P", links = ["0", "f"], at = [0.0, 0.06], guide = 90.0 },
  { name = "K", type = "cam", links = ["cam", "f"], follower = "flat", face = 0.0, at = [0.0, 0.06], profile = { centre = [0.02, 0.0], radius = 0.06 } },
]
[input]
joint = "O"
"""


def _on_eccentric(follower: str, gap: float) -> str:
    """FLAT with a follower of another kind whose point is `gap` from the eccentric (centre (0.02, 0),
    radius 0.06) on the guide x = 0."""
    y = repr(math.sqrt((0.06 + gap) ** 2 - 0.02 ** 2))
    pair = f'follower = "{follower}"' + (f", radius = {gap}" if gap else "")
    return (FLAT.replace('follower = "flat", face = 0.0, at = [0.0, 0.06]', f"{pair}, at = [0.0, {y}]")
            .replace("at = [0.0, 0.06], guide", f"at = [0.0, {y}], guide"))


CIRCLE, KNIFE = _on_eccentric("circle", 0.01), _on_eccentric("knife", 0.0)

MODELS_WITH_PAIRS = ["geared_five_bar", "planetary", "rack_pinion", "cam_eccentric", "cam_follower", "slot_arc",
                     "scotch_yoke", "shaper_geared", "flat", "circle", "knife"]


def _engine(name: str):
    if name in ("flat", "circle", "knife"):
        mech = mbplanar.parse_model({"flat": FLAT, "circle": CIRCLE, "knife": KNIFE}[name], f"{name}.toml")
    else:
        mech = mbplanar.read_model(MODELS / f"{name}.toml")
    return mbplanar.Engine(mech)


_ENGINES: dict = {}


def _cached(name: str):
    if name not in _ENGINES:
        engine = _ENGINES[name] = _engine(name)
        engine.prepared["test tables"] = higher_tables(engine)
    return _ENGINES[name]


def _pairs(engine):
    """(block, law, index in the tables) of every higher pair, in the tables' order."""
    out = []
    for bp in engine.blocks:
        out += [(bp, law) for law in bp.cuts if law.kind not in ("R", "P")]
    return [(bp, law, h) for h, (bp, law) in enumerate(out)]


def test_the_tables_hold_every_pair_of_the_models():
    """Every bundled model's higher pairs are in the tables, each with its rows and its parameter."""
    kinds = set()
    for name in MODELS_WITH_PAIRS:
        engine = _cached(name)
        hp, cv = engine.prepared["test tables"]
        pairs = _pairs(engine)
        assert len(hp.ints) == len(pairs) == len(engine.mech.higher) and hp.first[-1] == len(pairs)
        for bp, law, h in pairs:
            kinds.add(law.kind if law.kind != "point" else "slot" if law.pair.kind == "slot" else law.pair.follower)
            assert hp.ints[h, H_EQUATIONS] == law.equations and (hp.ints[h, H_VAR] >= 0) == bool(law.parameters)
    assert kinds == {"gear", "rack", "roller", "slot", "face", "circle", "knife"}


def _state(engine, rng):
    """A random pose, rates and velocities of every link (numpy's `Pose`, `Rates` and the kernel's ps, rt
    with the rates in slot 0 and the velocities in slot 1), a random contact parameter per pair that has
    one (within its curve's range) with a random rate and velocity."""
    n_l = len(engine.links)
    th, r = rng.uniform(-math.pi, math.pi, n_l), rng.uniform(-0.2, 0.2, (2, n_l))
    w, v = rng.uniform(-3, 3, (2, n_l)), rng.uniform(-1, 1, (2, 2, n_l))
    ps = np.stack([th, np.cos(th), np.sin(th), r[0], r[1]])
    rt = np.zeros((2, 3, n_l))
    rt[:, 0], rt[:, 1], rt[:, 2] = w, v[:, 0], v[:, 1]
    pose, rates, vel = Pose(1), Rates(1, 1), Rates(1, 1)
    for k, name in enumerate(engine.links):
        pose.place(name, th[k:k + 1], r[:, k:k + 1])
        rates.set(name, w[0, k].reshape(1, 1), v[0, :, k].reshape(2, 1, 1))
        vel.set(name, w[1, k].reshape(1, 1), v[1, :, k].reshape(2, 1, 1))
    hp, _ = engine.prepared["test tables"]
    q = np.zeros(max([1] + [int(v) + 1 for v in hp.ints[:, H_VAR]]))
    param = {}
    for _, law, h in _pairs(engine):
        if law.parameters:
            lo, hi = law.param_range if not law.path.closed else (law.path.lo - 1.0, law.path.hi + 1.0)
            pose.u[law.name] = rng.uniform(lo, hi, 1)
            q[hp.ints[h, H_VAR]] = pose.u[law.name][0]
            param[law.name] = rng.uniform(-2, 2, 2)
            rates.set_param(law.name, param[law.name][:1].reshape(1, 1))
            vel.set_param(law.name, param[law.name][1:].reshape(1, 1))
    return ps, rt, q, pose, rates, vel, param


@pytest.mark.parametrize("name", MODELS_WITH_PAIRS)
@given(st.integers(0, 2 ** 32 - 1))
@settings(max_examples=25, deadline=None)
def test_the_laws_and_their_rates_equal_numpys(name, seed):
    """Per pair on a random state: the closure rows, their rates (a Jacobian column: the links' rates and
    the parameter's), and with the velocities the acceleration's terms, to 1e-12 of the size of the
    terms (the mechanism's size times the rates)."""
    engine = _cached(name)
    hp, cv = engine.prepared["test tables"]
    ps, rt, q, pose, rates, vel, param = _state(engine, np.random.default_rng(seed))
    hc, wk, res = np.zeros((len(hp.ints), HIGHER_CACHE)), np.zeros(CURVE_WORK), np.zeros(8)
    size = engine.size
    for bp, law, h in _pairs(engine):
        want, cache = law.closure(pose)
        row = int(hp.ints[h, H_ROW])
        _higher_closure(h, hp, cv, ps, q, hc, wk, res)
        _close(res[row:row + law.equations], want[:, 0], size)
        pu, big_u = param.get(law.name, (0.0, 0.0))
        first = law.closure_rates(cache, rates)[:, 0, 0]
        got = _higher_rates(h, hp, hc, rt, 0, float(pu), -1, 0.0)[:law.equations]
        _close(got, first, 10 * size)
        second = law.closure_rates(cache, rates, vel)[:, 0, 0]
        got = _higher_rates(h, hp, hc, rt, 0, float(pu), 1, float(big_u))[:law.equations]
        _close(got, second, 100 * size)


# -- the compiled kernels on every bundled higher-pair model --------------------------------------------
BUNDLED = ["geared_five_bar", "planetary", "rack_pinion", "cam_eccentric", "cam_follower", "slot_arc",
           "scotch_yoke", "shaper_geared"]


def _loaded(name: str):
    """The bundled model with a mass, a moment of inertia and a centre on every moving link, a force on
    its last link and gravity, its own loads left out where numpy evaluates them (springs, torques): a
    kinetostatics that the compiled program takes, with every pair carrying a force."""
    import dataclasses
    from mbplanar.forces._loads import needs_numpy
    mech = mbplanar.read_model(MODELS / f"{name}.toml")
    if needs_numpy(mech):
        mech.loads = ()
    moving = [n for n in mech.links if n != mech.ground]
    for k, n in enumerate(moving):
        mech.links[n] = dataclasses.replace(mech.links[n], mass=1.0 + k, inertia=0.01 * (k + 1),
                                            centre=mech.joints_of(n)[0].name)
    mech.add_load("force", link=moving[-1], at=mech.joints_of(moving[-1])[-1].name, force=[30.0, -50.0])
    mech.set_gravity()
    return mech


def _largest(*arrays) -> float:
    return max([1e-300] + [float(np.nanmax(np.abs(a))) for a in arrays if a is not None and np.size(a)])


@pytest.mark.parametrize("name", BUNDLED)
def test_every_higher_pair_model_on_numba_equals_numpy(name, caplog):
    """A turn of the input (what the motion reaches of it) on the numba engine, through its compiled
    kernels (the seam's log says so), equals numpy's: positions to 1e-12 of the size, the contact
    parameters to 1e-12 of their curve's range, the reactions, the contact forces and the balancing
    loads to 1e-12 of the largest force; the velocities, accelerations and joint rates to 1e-12 of
    their largest where numpy solves that position alone (its batch corrector moves a position by a
    few 1e-14 with the other positions of its batch, which the geared five-bar's accelerations carry to
    ~1e-12: against the whole batch, 1e-11); one position (`mbplanar.position`) likewise."""
    import logging
    mech = _loaded(name)
    ref, fast = mbplanar.Engine(mech), mbplanar.Engine(mech, backend="numba")
    phi = ref.phi_drawn[0] + np.linspace(-math.pi, math.pi, 181)
    caplog.set_level(logging.DEBUG, logger="mbplanar.backends")
    m_ref, m_fast = mbplanar.analyse(ref, phi, 2.5, -0.7), mbplanar.analyse(fast, phi, 2.5, -0.7)
    k_ref, k_fast = mbplanar.kinetostatics(ref, m_ref), mbplanar.kinetostatics(fast, m_fast)
    n = len(m_ref.phi)
    assert n >= 30 and f"kinematics of 181: numba\n" in caplog.text and f"kinetostatics of {n}: numba\n" in caplog.text
    np.testing.assert_array_equal(m_fast.phi, m_ref.phi)
    np.testing.assert_allclose(m_fast.xy, m_ref.xy, rtol=0, atol=1e-12 * ref.size)
    np.testing.assert_allclose(m_fast.angle, m_ref.angle, rtol=0, atol=1e-12)
    span = max([1.0] + [law.path.period for law in ref.laws.values() if getattr(law, "parameters", 0)])
    np.testing.assert_allclose(m_fast.frames.contact, m_ref.frames.contact, rtol=0, atol=1e-12 * span)
    fields = ("w", "e", "v", "a", "rate", "accel")
    for field in fields:
        got, want = getattr(m_fast, field), getattr(m_ref, field)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-11 * _largest(want), err_msg=field)
    for k in np.argsort(np.abs(m_fast.a - m_ref.a).max(axis=(1, 2)))[-3:]:   # numpy solving them alone
        alone = mbplanar.analyse(ref, np.repeat(m_ref.phi[k, 0], 2), 2.5, -0.7)   # (twice: numpy's batch)
        for field in fields:
            np.testing.assert_allclose(getattr(m_fast, field)[k], getattr(alone, field)[0], rtol=0,
                                       atol=1e-12 * _largest(getattr(m_ref, field)), err_msg=field)
    forces = [getattr(r, part) for r in k_ref.reactions.values() for part in ("fx", "fy", "moment")]
    scale = _largest(*forces, *k_ref.balancing.values())
    assert scale > 1.0                                             # (every model carries loads here)
    for j, r in k_ref.reactions.items():
        for part in ("fx", "fy", "moment"):
            np.testing.assert_allclose(getattr(k_fast.reactions[j], part), getattr(r, part), rtol=0, atol=1e-12 * scale,
                                       err_msg=f"{j}.{part}")
    for j, q in k_ref.balancing.items():
        np.testing.assert_allclose(k_fast.balancing[j], q, rtol=0, atol=1e-12 * scale)
    for j, f in k_ref.contact_forces.items():
        np.testing.assert_allclose(k_fast.contact_forces[j], f, rtol=0, atol=1e-12 * scale)
    assert np.nanmax(k_fast.virtual_power_residual) < 1e-12
    at = float(m_ref.phi[n // 3, 0])
    one_ref, one_fast = mbplanar.position(ref, at, 2.5, -0.7), mbplanar.position(fast, at, 2.5, -0.7)
    np.testing.assert_allclose(one_fast.xy, one_ref.xy, rtol=0, atol=1e-12 * ref.size)
    np.testing.assert_allclose(one_fast.a, one_ref.a, rtol=0, atol=1e-12 * _largest(one_ref.a))
