"""The accuracy of mechanisms (mbplanar.accuracy): sensitivities against closed forms differentiated by hand
and against central differences of made designs on every bundled model, the meaning of a dimension against
the table's own (an edited, re-assembled table), the Monte Carlo against the RSS of the exact
sensitivities, the clearance model against a hand calculation, and the errors of [tolerances]."""

import copy
import json
import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import mbplanar
from mbplanar.accuracy import (Clearance, DesignSpace, Tolerance, ToleranceSpec, accuracy, catalogue, monte_carlo,
                               resolve_outputs, sensitivities, stack)
from mbplanar.accuracy.made import made_geometry
from mbplanar.accuracy.report import format_text
from mbplanar.accuracy.run import cycle, load
from mbplanar.accuracy.sensitivity import nominal_values
from mbplanar.cli import main
from mbplanar.engine import solve_positions
from mbplanar.errors import ModelError
from mbplanar.study.batch import DesignBatch

from conftest import MODELS, linkage_models


def _has_higher_pairs(path) -> bool:
    import tomllib
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    return any(j.get("type", "R") not in ("R", "P") for j in data.get("joints", []))


LOWER = [p for p in linkage_models() if not _has_higher_pairs(p)]
HIGHER = [p for p in linkage_models() if _has_higher_pairs(p)]


def _space(model, names=None, backend="numpy"):
    template, raw, engine = load(model, backend)
    every = catalogue(engine, raw, template)
    return DesignSpace(engine, raw, template, list(every) if names is None else names), every


# -- closed forms, differentiated by hand ---------------------------------------------------------------
def test_fourbar_output_angle_against_freudenstein_differentiated_by_hand():
    """models/fourbar.toml: crank a = OA, coupler b = AB, rocker c = CB, ground d = OC along x, crank angle θ.
    The rocker's angle ψ (B = C + c·e(ψ)) solves F = (d + c cos ψ − a cos θ)² + (c sin ψ − a sin θ)² − b² = 0,
    so ∂ψ/∂p = −F_p / F_ψ with (by hand) F_ψ = 2X(−c sin ψ) + 2Y(c cos ψ), F_a = −2X cos θ − 2Y sin θ,
    F_b = −2b, F_c = 2X cos ψ + 2Y sin ψ, F_d = 2X, F_θ = 2X a sin θ − 2Y a cos θ (X, Y the two brackets).
    The rocker's reported angle is the direction B→C, ψ + π: the same derivatives."""
    space, _ = _space(MODELS / "fourbar.toml", ["links.1.length", "links.2.length", "links.3.length",
                                                "joints.C.x", "input.zero"])
    theta = np.radians(np.arange(0.0, 360.0, 7.5))
    sens = sensitivities(space, theta, resolve_outputs(space.engine.mech, ["3"]))
    a, b, c, d = 0.1, 0.3, 0.25, 0.3
    psi = sens.value[:, 0] - np.pi
    X = d + c * np.cos(psi) - a * np.cos(theta)
    Y = c * np.sin(psi) - a * np.sin(theta)
    f_psi = 2 * X * (-c * np.sin(psi)) + 2 * Y * (c * np.cos(psi))
    hand = {"links.1.length": -2 * X * np.cos(theta) - 2 * Y * np.sin(theta),
            "links.2.length": np.full_like(theta, -2 * b),
            "links.3.length": 2 * X * np.cos(psi) + 2 * Y * np.sin(psi),
            "joints.C.x": 2 * X,
            "input.zero": 2 * X * a * np.sin(theta) - 2 * Y * a * np.cos(theta)}
    assert np.max(np.abs(np.hypot(X, Y) - b)) < 1e-13        # the solved pose closes the loop
    for k, name in enumerate(sens.dimensions):
        expected = -hand[name] / f_psi
        assert np.max(np.abs(sens.d[:, 0, k] - expected)) <= 1e-12 * np.max(np.abs(expected)), name


def _offset_slider_crank(r=0.1, l=0.3, e=0.02, at=40.0, loads=(), tolerances=None):
    th = math.radians(at)
    ax, ay = r * math.cos(th), r * math.sin(th)
    bx = ax + math.sqrt(l * l - (ay - e) ** 2)
    model = {"name": "offset_slider_crank",
             "links": [{"name": "1", "length": r}, {"name": "2", "length": l}, {"name": "3"}],
             "joints": [{"name": "O", "type": "R", "links": ["0", "1"], "at": [0.0, 0.0]},
                        {"name": "A", "type": "R", "links": ["1", "2"], "at": [ax, ay]},
                        {"name": "B", "type": "R", "links": ["2", "3"], "at": [bx, e]},
                        {"name": "Bp", "type": "P", "links": ["0", "3"], "at": [bx, e], "guide": 0.0}],
             "loads": list(loads), "input": {"joint": "O", "drawn_at": at}}
    if tolerances is not None:
        model["tolerances"] = tolerances
    return model


def test_offset_slider_crank_slider_position_against_the_closed_form_differentiated_by_hand():
    """x = r cos θ + s, s = √(l² − (r sin θ − e)²), by hand: ∂x/∂r = cos θ − (r sin θ − e) sin θ / s,
    ∂x/∂l = l / s, ∂x/∂e = (r sin θ − e) / s (e: the guide's offset, moved along its normal +y),
    ∂x/∂θ = −r sin θ − (r sin θ − e) r cos θ / s (the crank's zero)."""
    r, l, e = 0.1, 0.3, 0.02
    space, _ = _space(_offset_slider_crank(r, l, e), ["links.1.length", "links.2.length", "joints.Bp.offset",
                                                      "input.zero"])
    theta = np.radians(np.arange(0.0, 360.0, 10.0))
    sens = sensitivities(space, theta, resolve_outputs(space.engine.mech, ["Bp.x", "Bp.value"]))
    s = np.sqrt(l * l - (r * np.sin(theta) - e) ** 2)
    assert np.max(np.abs(sens.value[:, 0] - (r * np.cos(theta) + s))) < 1e-15
    hand = [np.cos(theta) - (r * np.sin(theta) - e) * np.sin(theta) / s, l / s, (r * np.sin(theta) - e) / s,
            -r * np.sin(theta) - (r * np.sin(theta) - e) * r * np.cos(theta) / s]
    for k, expected in enumerate(hand):         # (per SI unit: m/m, m/rad)
        assert np.max(np.abs(sens.d[:, 0, k] - expected)) <= 1e-12 * np.max(np.abs(expected)), sens.dimensions[k]
    # the slider's value is measured from the drawn pose (θ = 40°): its derivative is x's less x's there
    drawn = np.radians(40.0)
    s0 = math.sqrt(l * l - (r * math.sin(drawn) - e) ** 2)
    at_drawn = [math.cos(drawn) - (r * math.sin(drawn) - e) * math.sin(drawn) / s0, l / s0,
                (r * math.sin(drawn) - e) / s0]
    for k in range(3):
        assert np.max(np.abs(sens.d[:, 1, k] - (sens.d[:, 0, k] - at_drawn[k]))) < 1e-12


# -- central differences of made designs on every bundled model -------------------------------------------
def _usable(engine, raw, template, every):
    """The dimensions that can be toleranced alone (a length its link's other lengths fix is refused)."""
    names = []
    for name in every:
        try:
            DesignSpace(engine, raw, template, [name])
            names.append(name)
        except ModelError:
            pass
    return names


def _positions(engine):
    if len(engine.inputs) > 1:
        return engine.phi_drawn[None, :] + np.array([[0.0, 0.0], [0.1, -0.05], [-0.1, 0.07]])
    lo, hi = engine.reach()
    if hi - lo < 4 * math.pi:
        return np.linspace(lo, hi, 10)[1:-1][:, None]
    return (engine.phi_drawn[0] + np.radians(np.arange(0.0, 360.0, 45.0)) + 0.1)[:, None]


STEPS = {"jansen": 2e-5}    # (a mechanism near a toggle: its fifth derivatives are large)


@pytest.mark.parametrize("path", LOWER + HIGHER, ids=lambda p: p.stem)
def test_sensitivities_match_central_differences_of_made_designs(path):
    """Every dimension of every bundled model (with gears, racks, cams and slots: their radii, lines,
    circles and points too), every joint, point and link: the exact sensitivities against the 5-point
    central difference of made designs (closed at the drawn input, solved by a design batch with their own
    higher pairs, or by their own engines with several inputs), to 1e-7 of the largest sensitivity of that
    output to that dimension over the positions (1e-3 of the dimension's largest, for the outputs it
    hardly moves; a dimension that moves nothing to first order, a rack's pitch point across its line, a
    scotch yoke's pin along its slot: differences below 1e-9 of the model's largest sensitivity)."""
    _check_against_differences(path, STEPS.get(path.stem, 1e-4))


CAMS = {
    "flat": '{ name = "K", type = "cam", links = ["cam", "f"], follower = "flat", face = 0.0, at = [0.0, 0.06], '
            'profile = { centre = [0.02, 0.0], radius = 0.06 } }',
    "knife": '{ name = "K", type = "cam", links = ["cam", "f"], follower = "knife", at = [0.01, 0.07533923280734944], '
             'profile = { centre = [0.02, 0.0], radius = 0.076 } }',
    "circle": '{ name = "K", type = "cam", links = ["cam", "f"], follower = "circle", radius = 0.015, at = "T", '
              'profile = { centre = [0.02, 0.0], radius = 0.06 } }',
}


@pytest.mark.parametrize("follower", list(CAMS))
def test_the_other_followers_against_central_differences(follower):
    """An eccentric disc (e = 20 mm, R = 60 mm) with a translating flat-faced follower (the face's
    direction and point toleranced), an offset knife (its tip drawn as [x, y]) and a circular face on a
    point of the follower: every dimension against the central differences of made designs, as above."""
    model = f"""
        name = "cam_{follower}"
        links = [ {{ name = "cam" }}, {{ name = "f" }} ]
        joints = [
          {{ name = "O", type = "R", links = ["0", "cam"], at = [0.0, 0.0] }},
          {{ name = "F", type = "P", links = ["0", "f"], at = [0.0, 0.06], guide = 80.0 }},
          {CAMS[follower]},
        ]
        points = [ {{ name = "T", link = "f", at = [0.002270069465426503, 0.07287420368854261] }} ]
        [input]
        joint = "O"
        """
    import tomllib
    _check_against_differences(tomllib.loads(model), 1e-3)


def _check_against_differences(path, h):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        template, raw, engine = load(path)
    every = catalogue(engine, raw, template)
    names = _usable(engine, raw, template, every)
    space = DesignSpace(engine, raw, template, names)
    phi = _positions(engine)
    outputs = resolve_outputs(engine.mech)
    sens = sensitivities(space, phi, outputs)
    assert sens.success
    K = len(names)
    steps = np.array([h * engine.size if d.unit in ("length", "m", "mm", "cm") else h for d in space.dimensions])
    delta = np.zeros((4 * K, K))
    for k in range(K):
        delta[4 * k:4 * k + 4, k] = np.array([2.0, 1.0, -1.0, -2.0]) * steps[k]
    geometry = made_geometry(engine, space.sided(delta))
    assert all(r is None for r in geometry.reasons)
    if len(engine.inputs) == 1:
        motion = DesignBatch(engine, geometry).solve(phi[:, 0], exact_limits=False, accelerations=False)
        assert motion.valid.all()
        values = np.empty((4 * K, len(phi), len(outputs)))
        for y, o in enumerate(outputs):
            values[:, :, y] = (motion.xy[:, :, motion.point(o.target), "xy".index(o.kind)] if o.kind in "xy"
                               else motion.angle[:, :, motion.link(o.target)])
    else:
        from dataclasses import replace

        from mbplanar.study.geometry import mechanism_of
        values = []
        for k in range(4 * K):
            mech = mechanism_of(engine.mech, geometry, k)
            mech = replace(mech, inputs=[replace(i, drawn_at=i.from_si(p)) for i, p in zip(mech.inputs, engine.phi_drawn)])
            design = engine.with_dimensions(mech)
            values.append(nominal_values(design, solve_positions(design, phi), outputs))
        values = np.array(values)
    largest = np.abs(sens.d).max()
    for k, dim in enumerate(space.dimensions):
        f = values[4 * k:4 * k + 4]
        fd = (-f[0] + 8 * f[1] - 8 * f[2] + f[3]) / (12 * steps[k])
        exact = sens.d[:, :, k]
        big = np.abs(exact).max(axis=0)
        if big.max() <= 1e-12 * largest:     # (it moves nothing to first order)
            assert np.abs(fd).max() <= 1e-9 * largest, dim.name
            continue
        scale = np.maximum(big, 1e-3 * max(big.max(), 1e-12))
        err = np.abs(fd - exact) / scale
        assert err.max() <= 1e-7, (dim.name, [o.name for o, e in zip(outputs, err.max(axis=0)) if e > 1e-7],
                                   err.max())


def test_planetary_train_against_its_gear_laws_solved_and_differentiated_by_hand():
    """models/planetary.toml (sun r1 on the input, planet on the carrier H, fixed ring r3): the laws
    r1(θ1 − θH) + r2'(θ2 − θH) = 0 and r2(θ2 − θH) + r3·θH = 0 (r2' and r2 the planet's radius in each mesh)
    give θH = r1·r2·θ1 / D, D = r1·r2 + r3·r2', and θ2 = θH(1 − r3/r2); their partial derivatives by hand
    against the sensitivities of H's and the planet's angles to the four radii, to 1e-12."""
    template, raw, engine = load(MODELS / "planetary.toml")
    names = ["joints.G12.radius_a", "joints.G12.radius_b", "joints.G23.radius_a", "joints.G23.radius_b"]
    space = DesignSpace(engine, raw, template, names)
    phi = engine.phi_drawn[0] + np.radians([-200.0, -35.0, 10.0, 95.0, 400.0])
    sens = sensitivities(space, phi, resolve_outputs(engine.mech, ["H", "2"]))
    r1, r2p, r2, r3 = 0.02, 0.046, 0.046, 0.112
    t1 = phi - engine.phi_drawn[0]
    d = r1 * r2 + r3 * r2p
    th = r1 * r2 * t1 / d
    dth = {"r1": r2 * r3 * r2p * t1 / d ** 2, "r2p": -r1 * r2 * r3 * t1 / d ** 2, "r2": r1 * r3 * r2p * t1 / d ** 2,
           "r3": -r1 * r2 * r2p * t1 / d ** 2}
    f = 1 - r3 / r2
    dplanet = {"r1": dth["r1"] * f, "r2p": dth["r2p"] * f, "r2": dth["r2"] * f + th * r3 / r2 ** 2,
               "r3": dth["r3"] * f - th / r2}
    for k, key in enumerate(["r1", "r2p", "r2", "r3"]):
        for y, hand in enumerate((dth[key], dplanet[key])):
            assert np.max(np.abs(sens.d[:, y, k] - hand)) <= 1e-12 * np.max(np.abs(hand)), (key, y)


def test_rack_and_pinion_against_the_rolled_length():
    """models/rack_pinion.toml: the pinion turns by θ4 = ∓s/r for the rack's travel s (checked), so
    ∂θ4/∂r = −θ4/r, and its sensitivity to the crank's length is ∓(∂x_B/∂l₁)/r, x_B the rack's point; to
    1e-12."""
    template, raw, engine = load(MODELS / "rack_pinion.toml")
    space = DesignSpace(engine, raw, template, ["joints.K.radius", "links.1.length"])
    phi = np.radians([20.0, 75.0, 130.0, 250.0, 320.0])
    sens = sensitivities(space, np.concatenate([phi, engine.phi_drawn]),
                         resolve_outputs(engine.mech, ["4.angle", "B.x"]))
    turn = sens.value[:-1, 0] - sens.value[-1, 0]
    travel = sens.value[:-1, 1] - sens.value[-1, 1]
    r = 0.025
    side = -np.sign(turn[0] * travel[0])           # the pinion's side of the rack: θ4 = −side·s/r
    assert np.allclose(turn, -side * travel / r, rtol=1e-12, atol=0)
    assert np.max(np.abs(sens.d[:-1, 0, 0] + turn / r)) <= 1e-12 * np.max(np.abs(turn / r))
    assert np.max(np.abs(sens.d[:-1, 0, 1] + side * sens.d[:-1, 1, 1] / r)) <= 1e-12 * np.max(np.abs(sens.d[:, 0, 1]))


# -- the meaning of a dimension is the table's --------------------------------------------------------
def _edited(data, dim, h):
    data = copy.deepcopy(data)
    kind, target = dim.kind, dim.target
    if kind == "length":
        row = next(r for r in data["links"] if str(r["name"]) == target[0])
        if "length" in row:
            row["length"] += h
        else:
            row["lengths"][target[1]][2] += h
    elif kind == "coordinate":
        row = next(r for r in data["joints"] if r["name"] == target[0])
        row["at"][target[1]] += h
    elif kind == "zero":
        data["input"]["zero"] = data["input"].get("zero", 0.0) + h
    elif kind == "point":
        row = next(r for r in data["points"] if r["name"] == target[0])
        row[target[1]] = row.get(target[1], 0.0) + h
    return data


@pytest.mark.parametrize("model", ["fourbar", "slider_crank"])
def test_a_dimension_means_what_editing_the_table_means(model):
    """The sensitivities equal the central differences of the model with that number edited in its table
    and assembled again from the sketch (the table's own meaning), to the assembly's precision."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        template, raw, engine = load(MODELS / f"{model}.toml")
        every = catalogue(engine, raw, template)
        names = [n for n, d in every.items() if d.kind in ("length", "coordinate", "zero", "point")]
        space = DesignSpace(engine, raw, template, names)
        phi = np.radians(np.arange(0.0, 360.0, 30.0)) + 0.1
        sens = sensitivities(space, phi)
        for k, dim in enumerate(space.dimensions):
            h = 1e-6 * engine.size / dim.scale
            values = []
            for sign in (1, -1):
                design = engine.with_dimensions(mbplanar.parse_model(_edited(template.data, dim, sign * h)))
                values.append(nominal_values(design, solve_positions(design, phi[:, None]), sens.outputs))
            fd = (values[0] - values[1]) / (2 * h * dim.scale)
            big = np.abs(sens.d[:, :, k]).max()
            assert np.max(np.abs(fd - sens.d[:, :, k])) <= 1e-6 * big, dim.name


# -- the Monte Carlo --------------------------------------------------------------------------------------
def test_the_monte_carlo_spread_matches_the_rss_of_the_exact_sensitivities():
    """models/fourbar.toml's tolerances, 10⁵ samples: at every one of 24 positions the Monte Carlo's
    standard deviation of M and of the rocker's angle is within 5 % of the RSS σ (its sampling error at
    10⁵ is ~0.3 %), and its mean within 0.05 σ of the nominal value plus the bands' mean shift."""
    result = accuracy(MODELS / "fourbar.toml", samples=100_000, positions=24, seed=7)
    mc, st = result.monte_carlo, result.stack
    assert mc.success and mc.count == 100_000
    assert np.all(np.abs(mc.std / st.sigma - 1) < 0.05)
    assert np.all(np.abs(mc.mean - result.sensitivities.value - st.shift) < 0.05 * st.sigma)
    assert np.all(mc.high - mc.low <= 2 * st.worst + 1e-12)     # no sample beyond the worst case


def test_an_asymmetric_band_moves_the_mean_and_a_normal_row_has_its_sigma():
    spec = ToleranceSpec((Tolerance("links.2.length", 0.0, 0.0004), Tolerance("joints.C.x", sigma=0.0001)),
                         outputs=("3",), positions=12)
    result = accuracy(MODELS / "fourbar.toml", spec=spec, samples=20_000, seed=3)
    sens, st, mc = result.sensitivities, result.stack, result.monte_carlo
    assert np.allclose(st.shift[:, 0], sens.d[:, 0, 0] * 0.0002, rtol=1e-12, atol=0)
    sigma = np.hypot(sens.d[:, 0, 0] * 0.0004 / math.sqrt(12), sens.d[:, 0, 1] * 0.0001)
    assert np.allclose(st.sigma[:, 0], sigma, rtol=1e-12)
    assert np.allclose(st.worst[:, 0], np.abs(sens.d[:, 0, 0]) * 0.0002 + np.abs(sens.d[:, 0, 1]) * 0.0003)
    assert np.all(np.abs(mc.mean - sens.value - st.shift) < 0.05 * st.sigma)


def test_samples_that_lock_or_do_not_assemble_are_counted_with_their_cause():
    """A crank ±0.2 m on a four-bar whose Grashof margin is 0.15 m: the longer cranks cannot turn (the
    crank and the coupler stretch out, a motion limit) or cannot reach the drawn pose at all; the crank's
    length is the cause, the failures at its long end."""
    spec = ToleranceSpec((Tolerance("links.1.length", -0.02, 0.2), Tolerance("joints.C.y", -1e-4, 1e-4)),
                         outputs=("M",), positions=36)
    result = accuracy(MODELS / "fourbar.toml", spec=spec, samples=2000, seed=1)
    mc = result.monte_carlo
    assert 0 < mc.locking + mc.not_assembled < 1 and mc.count == 2000 * (1 - mc.locking - mc.not_assembled)
    causes = mc.causes["locking"] or mc.causes["not_assembled"]
    assert causes[0].dimension == "links.1.length" and causes[0].correlation > 0.3
    assert "links.1.length" in format_text(result)


def test_the_monte_carlo_is_the_same_on_both_backends_and_in_any_chunks():
    space, _ = _space(MODELS / "fourbar.toml", ["links.1.length", "links.2.length", "points.M.offset"])
    fast, _ = _space(MODELS / "fourbar.toml", ["links.1.length", "links.2.length", "points.M.offset"],
                     backend="numba")
    tols = [Tolerance("links.1.length", -1e-3, 1e-3), Tolerance("links.2.length", sigma=5e-4),
            Tolerance("points.M.offset", -1e-3, 1e-3)]
    phi = np.radians(np.arange(0.0, 360.0, 15.0))
    outputs = resolve_outputs(space.engine.mech, ["M", "3"])
    a = monte_carlo(space, tols, phi, outputs, samples=300, seed=5)
    b = monte_carlo(fast, tols, phi, outputs, samples=300, seed=5, chunk=70)
    c = monte_carlo(space, tols, phi, outputs, samples=300, seed=5, chunk=70)
    for x in (b, c):
        for name in ("mean", "std", "low", "high"):
            assert np.allclose(getattr(x, name), getattr(a, name), rtol=0, atol=1e-12), name


@pytest.mark.parametrize("model", ["six_bar_press", "shaper"])
def test_the_sensitivities_are_the_same_on_both_backends(model):
    """Every output of the model's [tolerances] to its every dimension, the engine built for numba against
    numpy's."""
    pytest.importorskip("numba")
    a, b = (accuracy(MODELS / f"{model}.toml", positions=36, backend=backend, monte_carlo_run=False).sensitivities
            for backend in ("numpy", "numba"))
    assert a.success and b.success and a.d.shape == b.d.shape
    assert np.abs(b.d - a.d).max() <= 1e-12 * np.abs(a.d).max()
    assert np.abs(b.value - a.value).max() <= 1e-12


def test_the_monte_carlo_on_dask_workers_equals_the_serial_run():
    from mbplanar.study.cluster import close, local_client
    space, _ = _space(MODELS / "fourbar.toml", ["links.1.length", "links.2.length"])
    tols = [Tolerance("links.1.length", -1e-3, 1e-3), Tolerance("links.2.length", sigma=5e-4)]
    phi = np.radians(np.arange(0.0, 360.0, 30.0))
    outputs = resolve_outputs(space.engine.mech, ["M"])
    serial = monte_carlo(space, tols, phi, outputs, samples=400, seed=2, chunk=100)
    client = local_client(2)
    try:
        remote = monte_carlo(space, tols, phi, outputs, samples=400, seed=2, chunk=100, client=client)
    finally:
        close(client)
    for name in ("mean", "std", "low", "high"):
        assert np.array_equal(getattr(remote, name), getattr(serial, name)), name


# -- stacks: laws that always hold ---------------------------------------------------------------------
@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(-10, 10), st.floats(0, 1), st.floats(0, 1)), min_size=1, max_size=8))
def test_the_worst_case_bounds_the_statistical_spread(rows):
    """For uniform bands the worst case is at least √3 σ (Σ|S|h ≥ √3·√(Σ(S h/√3)²)), and equal to it for one
    dimension; the shares sum to 1."""
    from mbplanar.accuracy.geometry import Dimension
    from mbplanar.accuracy.sensitivity import Sensitivities
    d = np.array([[[s for s, _, _ in rows]]])
    tols = [Tolerance(f"p{k}", -a, b) for k, (_, a, b) in enumerate(rows)]
    dims = [Dimension(f"p{k}", "length", (), "length", 1.0, 0.0) for k in range(len(rows))]
    sens = Sensitivities(np.zeros((1, 1)), np.ones(1, bool), (None,), tuple(t.name for t in tols), np.zeros((1, 1)), d)
    result = stack(sens, tols, dims)
    half = np.array([(a + b) / 2 for _, a, b in rows])
    assert result.worst[0, 0] >= math.sqrt(3) * result.sigma[0, 0] * (1 - 1e-12) - 1e-300
    assert abs(result.worst[0, 0] - np.abs(d[0, 0]) @ half) <= 1e-12 * (1 + result.worst[0, 0])
    if result.sigma[0, 0] > 0:
        assert abs(result.share[0].sum() - 1) < 1e-12


# -- clearances under load ----------------------------------------------------------------------------
def test_clearances_under_load_against_a_hand_calculation():
    """An offset slider-crank (r = 0.1, l = 0.3, e = 0.02 m) without masses, a force of 500 N pushing the
    slider towards the crank: the rod is a two-force member in compression, so the gaps at A and B close
    along it and the rod acts c_A + c_B shorter (Δx = −(c_A + c_B)·l/s); the crank's pivot O sits c_O
    further from B along the rod (Δx = δ_x − (r sin θ − e)·δ_y/s, δ = −c_O·u_AB); the block sits c_P below
    the guide's line where the guide pushes it up (N_y = −(P/u_x)·u_y > 0) and above it where it pulls
    down (Δx = −(r sin θ − e)/s·c_P·sign N_y). The guide's force turns through zero where sin θ = e/r:
    the block knocks there."""
    r, l, e, P = 0.1, 0.3, 0.02, 500.0
    c = {"O": 1e-5, "A": 2e-5, "B": 3e-5, "Bp": 4e-5}
    model = _offset_slider_crank(r, l, e, loads=[{"type": "force", "link": "3", "at": "B", "force": [-P, 0.0]}],
                                 tolerances={"outputs": ["Bp.x"], "clearances": [
                                     {"joint": j, "clearance": v} for j, v in c.items()]})
    result = accuracy(model, positions=72)
    cl = result.clearances
    assert cl.loaded and result.monte_carlo is None
    th = result.phi
    s = np.sqrt(l * l - (r * np.sin(th) - e) ** 2)
    u = np.stack([s, e - r * np.sin(th)]) / l
    normal = -P / u[0] * u[1]
    dO = -c["O"] * u
    hand = {"O": dO[0] - (r * np.sin(th) - e) * dO[1] / s, "A": -c["A"] * l / s, "B": -c["B"] * l / s,
            "Bp": -(r * np.sin(th) - e) / s * c["Bp"] * np.sign(normal)}
    for k, joint in enumerate(cl.joints):
        assert np.max(np.abs(cl.part[:, 0, k] - hand[joint])) <= 1e-12 * np.max(np.abs(hand[joint])), joint
    assert np.max(np.abs(cl.error[:, 0] - sum(hand.values()))) < 1e-15
    knocks = np.array(cl.knocks["Bp"])
    exact = np.array([math.asin(e / r), math.pi - math.asin(e / r)])
    assert len(knocks) == 2 and np.max(np.abs(knocks - exact)) < 1e-3      # (linear between 5° apart)
    assert cl.knocks["A"] == cl.knocks["B"] == cl.knocks["O"] == ()


def test_an_unloaded_model_counts_each_clearance_in_its_worst_direction():
    result = accuracy(MODELS / "fourbar.toml", positions=36, monte_carlo_run=False)
    cl = result.clearances
    assert not cl.loaded and np.all(cl.error == 0)
    assert np.all(cl.worst > 0)
    assert "worst direction" in format_text(result)


# -- the command, the document, the errors ----------------------------------------------------------------
def test_the_command_prints_a_summary_json_and_csv(tmp_path, capsys):
    assert main(["accuracy", str(MODELS / "fourbar.toml"), "--samples", "300", "--positions", "24"]) == 0
    text = capsys.readouterr().out
    assert text.splitlines()[0].startswith("fourbar: 7 toleranced dimension(s), 2 clearance(s); 24 positions")
    assert "M.x" in text and "σ (MC)" in text
    assert main(["accuracy", str(MODELS / "fourbar.toml"), "--samples", "300", "--positions", "24", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert [o["name"] for o in doc["outputs"]] == ["M.x", "M.y", "3.angle"]
    first = doc["outputs"][0]
    assert sum(c["share"] for c in first["contributions"]) == pytest.approx(1.0)
    assert first["contributions"][0]["share"] >= first["contributions"][-1]["share"]
    assert len(first["sensitivities"]["links.1.length"]) == 24 and doc["monte_carlo"]["samples"] == 300
    result = accuracy(MODELS / "fourbar.toml", samples=300, positions=24)
    assert mbplanar.io.document(result) == doc
    out = tmp_path / "acc.csv"
    assert main(["accuracy", str(MODELS / "fourbar.toml"), "--samples", "300", "--positions", "24", "-o",
                 str(out)]) == 0
    header = out.read_text().splitlines()[0].split(",")
    assert header[0] == "phi[deg]" and "M.x.sigma[m]" in header and "M.x.mc_sigma[m]" in header
    assert len(out.read_text().splitlines()) == 25
    header, cols = mbplanar.io.table(result, units="model")
    assert cols.shape == (24, len(header))


@pytest.mark.parametrize("section, words", [
    ({"dimensions": [{"name": "links.2.lenght", "band": 0.1}]},
     "dimensions[0] 'links.2.lenght': 'links.2.lenght' is not a dimension of the model (closest: links.2.length"),
    ({"dimensions": [{"name": "links.2.length", "band": -0.1}]},
     "dimensions[0] 'links.2.length': the band must not be negative, got -0.1"),
    ({"dimensions": [{"name": "links.2.length", "band": [0.1, -0.1]}]},
     "dimensions[0] 'links.2.length': the band's lower deviation 0.1 is above its upper one -0.1"),
    ({"dimensions": [{"name": "links.2.length", "sigma": -1}]},
     "dimensions[0] 'links.2.length': 'sigma' must not be negative, got -1"),
    ({"dimensions": [{"name": "links.2.length", "band": 0.1, "sigma": 0.1}]},
     "give a band (b or [lower, upper]) or a sigma, not both"),
    ({"clearances": [{"joint": "Q", "clearance": 0.01}]},
     "clearances[0] 'Q': 'Q' is not a joint of the model"),
    ({"clearances": [{"joint": "A", "clearance": -0.01}]},
     "clearances[0] 'A': 'clearance' must not be negative, got -0.01"),
    ({"samples": 0}, "'samples' must be a whole number >= 1, got 0"),
    ({"outputs": ["Z"]}, "outputs: 'Z' is not a joint, point or moving link of the model"),
])
def test_a_wrong_row_is_a_clear_error_naming_it_exit_2(tmp_path, capsys, section, words):
    import tomllib
    data = tomllib.loads((MODELS / "fourbar.toml").read_text())
    data["tolerances"] = section
    path = tmp_path / "bad.toml"
    path.write_text(_toml(data))
    with pytest.raises(ModelError, match=".*" + _escape(words)):
        accuracy(path, samples=10, positions=4)
    assert main(["accuracy", str(path), "--samples", "10"]) == 2
    err = capsys.readouterr().err
    assert words in err and err.count("\n") == 1 and "Traceback" not in err


def test_the_command_refuses_a_count_below_one_and_a_model_without_tolerances(capsys):
    assert main(["accuracy", str(MODELS / "fourbar.toml"), "--samples", "0"]) == 2
    assert "argument --samples: expected a whole number >= 1, got '0'" in capsys.readouterr().err
    assert main(["accuracy", str(MODELS / "fourbar.toml"), "--samples", "-5"]) == 2
    assert main(["accuracy", str(MODELS / "slider_crank.toml")]) == 2
    assert "has no [tolerances] section" in capsys.readouterr().err
    with pytest.raises(ModelError, match="samples must be a whole number >= 1, got 0"):
        accuracy(MODELS / "fourbar.toml", samples=0)


def test_a_length_its_link_cannot_change_alone_is_refused_with_the_reason():
    """The six-bar press's rocker holds C, B, D in line with all three distances: one cannot change alone."""
    with pytest.raises(ModelError, match="'links.3.C-D' changes the lengths of link '3'.*drawn in line"):
        _space(MODELS / "six_bar_press.toml", ["links.3.C-D"])


def _escape(text):
    import re
    return re.escape(text)


def _toml(data) -> str:
    """A small TOML writer for the test tables (numbers, strings, lists, inline tables, tables)."""
    def value(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, (int, float)):
            return repr(v)
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        return "{ " + ", ".join(f"{json.dumps(str(k))} = {value(x)}" for k, x in v.items()) + " }"
    top = [f"{json.dumps(k)} = {value(v)}" for k, v in data.items() if not isinstance(v, dict)]
    tables = [f"[{k}]\n" + "\n".join(f"{json.dumps(str(a))} = {value(b)}" for a, b in v.items())
              for k, v in data.items() if isinstance(v, dict)]
    return "\n".join(top + tables) + "\n"


def test_the_accuracy_picture_and_the_report_section(tmp_path):
    """`plot MODEL accuracy` draws the zone and the bands; the report's Accuracy section is there for a
    model with [tolerances] and left out for one without."""
    pytest.importorskip("matplotlib")
    out = tmp_path / "acc.png"
    assert main(["plot", str(MODELS / "fourbar.toml"), "accuracy", "-o", str(out)]) == 0
    assert out.stat().st_size > 10_000
    assert main(["plot", str(MODELS / "slider_crank.toml"), "accuracy", "-o", str(out)]) == 2
    from mbplanar.accuracy.plots import report_section
    from mbplanar.viz._report import ReportContext
    engine = mbplanar.Engine(mbplanar.read_model(MODELS / "fourbar.toml"))
    html = report_section(engine, ReportContext(engine, None, None))
    assert "<table>" in html and "points.M.offset" in html and "<img" in html
    plain = mbplanar.Engine(mbplanar.read_model(MODELS / "slider_crank.toml"))
    assert report_section(plain, ReportContext(plain, None, None)) is None


# -- higher pairs and far from the origin ---------------------------------------------------------------
def _with_section(tmp_path, name, section, change=None):
    """models/NAME.toml with a [tolerances] section (and `change` applied to its table), beside the cam
    profiles it may read."""
    import tomllib
    data = tomllib.loads((MODELS / f"{name}.toml").read_text(encoding="utf-8"))
    data["tolerances"] = section
    if change is not None:
        change(data)
    path = tmp_path / f"{name}.toml"
    path.write_text(_toml(data))
    for profile in MODELS.glob("*.csv"):
        (tmp_path / profile.name).write_bytes(profile.read_bytes())
    return path


def test_a_higher_pairs_dimension_means_what_its_table_gives():
    """The slot of models/slot_arc.toml with its circle's centre given by parameters: the sensitivities to
    them (the slot's radius following the pin, as the table takes it) against the central differences of
    the model built from its own table for each value (the higher pair's law made by the engine from the
    drawing), to 1e-7."""
    import tomllib
    from mbplanar.model._parameters import Template
    data = tomllib.loads((MODELS / "slot_arc.toml").read_text(encoding="utf-8"))
    data["parameters"] = {"cx": 0.25, "cy": 0.31}
    slot = next(j for j in data["joints"] if j["name"] == "S")
    slot["path"]["centre"] = ["cx", "cy"]
    template = Template(data, source="slot_arc (parameters)")
    _, raw, engine = load(template)
    space = DesignSpace(engine, raw, template, ["cx", "cy", "joints.S.path.x"])
    assert "joints.S.path.radius" not in catalogue(engine, raw, template)   # (the pin gives it)
    phi = np.radians(np.linspace(-20.0, 40.0, 7))
    sens = sensitivities(space, phi)
    assert np.array_equal(sens.d[:, :, 0], sens.d[:, :, 2])
    h = 1e-4
    for k, name in enumerate(["cx", "cy"]):
        values = []
        for step in (2, 1, -1, -2):
            design = engine.with_dimensions(mbplanar.parse_model(template.bind({name: 0.28 * (k == 0) + 0.31 * (k == 1)
                                                                                 - 0.03 * (k == 0) + step * h})))
            values.append(nominal_values(design, solve_positions(design, phi[:, None]), sens.outputs))
        fd = (-values[0] + 8 * values[1] - 8 * values[2] + values[3]) / (12 * h)
        exact = sens.d[:, :, k]
        assert np.abs(exact).max() > 0.1
        assert np.max(np.abs(fd - exact)) <= 1e-7 * np.abs(exact).max(), name


@pytest.mark.parametrize("model, bands, outputs", [
    ("geared_five_bar", {"links.1.length": 2e-5, "joints.E.x": 2e-5, "joints.G.radius_a": 1e-5,
                         "joints.G.radius_b": 1e-5, "input.zero": 0.01}, ["P"]),
    ("cam_eccentric", {"joints.K.radius": 0.02, "joints.K.profile.x": 0.02, "joints.K.profile.radius": 0.02,
                       "joints.C.y": 0.02, "input.zero": 0.05}, ["arm", "M"]),
])
def test_the_monte_carlo_of_a_higher_pair_model_matches_the_rss(model, bands, outputs):
    """A geared five-bar (gear radii) and an eccentric cam with its roller (the roller's radius, the
    eccentric's centre and radius): 10⁴ made designs through the design batch, each with its own pairs;
    at every one of 12 positions the Monte Carlo's σ is within 5 % of the RSS of the exact sensitivities
    (its sampling error at 10⁴ is ~0.7 %) and its mean within 0.05 σ of nominal + shift."""
    spec = ToleranceSpec(tuple(Tolerance(n, -b, b) for n, b in bands.items()), outputs=tuple(outputs),
                         samples=10_000, seed=4, positions=12)
    result = accuracy(MODELS / f"{model}.toml", spec=spec)
    mc, st = result.monte_carlo, result.stack
    assert mc.success and mc.count == 10_000
    assert np.all(np.abs(mc.std / st.sigma - 1) < 0.05), np.abs(mc.std / st.sigma - 1).max()
    assert np.all(np.abs(mc.mean - result.sensitivities.value - st.shift) < 0.05 * st.sigma)
    assert np.all(mc.high - mc.low <= 2 * st.worst * (1 + 1e-3))


@pytest.mark.parametrize("model, names", [
    ("rack_pinion", ["joints.K.radius", "joints.K.guide", "links.1.length"]),
    ("cam_follower", ["joints.K.radius", "joints.F.offset"]),
    ("slot_arc", ["joints.S.path.x", "points.A.y"]),
])
def test_a_made_designs_own_engine_moves_as_the_batch_says(model, names):
    """Made designs with higher pairs, each solved by the design batch and by its own engine (what the batch
    falls back to: the engine re-dimensioned with the design's own pairs, `DesignBatch.engine_of`): every
    joint and point at 12 positions agree to 1e-12 of the mechanism's size."""
    template, raw, engine = load(MODELS / f"{model}.toml")
    space = DesignSpace(engine, raw, template, names)
    scale = np.array([engine.size if d.unit in ("length", "mm", "m") else 1.0 for d in space.dimensions])
    geometry = made_geometry(engine, space.sided(np.random.default_rng(0).uniform(-1e-3, 1e-3, (3, len(names))) * scale))
    batch = DesignBatch(engine, geometry)
    phi = cycle(engine, 12)[0]
    motion = batch.solve(phi, exact_limits=False, accelerations=False)
    assert motion.ok.all() and motion.valid.all()
    for d in range(3):
        own = mbplanar.analyse(batch.engine_of(d), phi)
        for p in motion.points:
            assert np.abs(own.xy[:, own.point(p)] - motion.xy[d, :, motion.point(p)]).max() <= 1e-12 * engine.size


def _circles(c, r0, e, r1):
    """The points where circles about c (2,) of radius r0 and about e (2, N) of radius r1 meet, left of c→e."""
    d = e - c[:, None]
    dist = np.hypot(*d)
    a = (r0 * r0 - r1 * r1 + dist * dist) / (2 * dist)
    h = np.sqrt(r0 * r0 - a * a)
    u = d / dist
    return c[:, None] + a * u + h * np.stack([-u[1], u[0]])


def test_clearances_of_a_cam_mechanism_under_load_against_a_hand_calculation():
    """models/cam_eccentric.toml (an eccentric disc, e = 15 mm, R = 40 mm, turning at 120 rpm about O; a
    roller of 12 mm on an arm pivoted at C, 0.5 kg at the arm's middle M, a spring's −3 N·m on the arm,
    gravity). By hand: the roller's centre B on the circle of radius R + r about the eccentric's centre E;
    the contact force f·n (n = (B − E)/|B − E|) from the arm's moments about C (d'Alembert, a_M by
    differences of the closed-form position); the reactions on the arm R_C = −(f·n + m(g − a_M)) and on
    the cam R_O = f·n. The gaps close along them: the arm sits −c_C·R̂_C off its pivot, the cam −c_O·R̂_O
    off its shaft, and the arm turns by ∓(B − E)·δ / ((B − E)·perp(B − C)). The pairs' parts of the arm's
    angle error agree to 1e-6 (the differences' error)."""
    c = {"C": 2e-5, "O": 3e-5}
    spec = ToleranceSpec((), tuple(Clearance(j, v) for j, v in c.items()), ("arm",), positions=36)
    result = accuracy(MODELS / "cam_eccentric.toml", spec=spec)
    cl = result.clearances
    assert cl.loaded
    mm = 1e-3
    C, O = np.array([-100.0, 52.0]) * mm, np.zeros(2)
    B0, E0 = np.array([0.0, 49.78955713801841]) * mm, np.array([15.0, 0.0]) * mm
    length, rho = np.hypot(*(B0 - C)), 52.0 * mm

    def place(phi):
        e = np.stack([np.cos(phi) * E0[0] - np.sin(phi) * E0[1], np.sin(phi) * E0[0] + np.cos(phi) * E0[1]])
        b = _circles(C, length, e, rho)
        return b, e

    assert np.allclose(place(np.zeros(1))[0][:, 0], B0, atol=1e-12)
    phi = result.phi
    b, e = place(phi)
    m, g, omega, spring = 0.5, np.array([0.0, -9.81])[:, None], 120.0 * 2 * math.pi / 60, -3.0
    h = 1e-3
    mid = [(place(phi + k * h)[0] + C[:, None]) / 2 for k in (-2, -1, 0, 1, 2)]
    a_m = omega ** 2 * (-mid[0] + 16 * mid[1] - 30 * mid[2] + 16 * mid[3] - mid[4]) / (12 * h * h)
    cross = lambda p, q: p[0] * q[1] - p[1] * q[0]  # noqa: E731
    n = (b - e) / rho
    load = m * (g - a_m)
    f = -(spring + cross(mid[2] - C[:, None], load)) / cross(b - C[:, None], n)
    assert np.all(f > 0)                                        # (the spring keeps the roller on the cam)
    reactions = {"C": -(f * n + load), "O": f * n}
    turn = lambda delta: -np.sum((b - e) * delta, axis=0) / np.sum((b - e) * np.stack([-(b - C[:, None])[1], (b - C[:, None])[0]]), axis=0)  # noqa: E501,E731
    hand = {"C": turn(-c["C"] * reactions["C"] / np.hypot(*reactions["C"])),
            "O": -turn(-c["O"] * reactions["O"] / np.hypot(*reactions["O"]))}
    for k, joint in enumerate(cl.joints):
        assert np.max(np.abs(cl.part[:, 0, k] - hand[joint])) <= 1e-6 * np.max(np.abs(hand[joint])), joint
    assert cl.knocks == {"C": (), "O": ()}


def _same_numbers(got, want, rtol=1e-12):
    """The same document to rounding: the same keys, strings and counts, every list of numbers within
    `rtol` of its largest value (the compiled design kernel's answers are numpy's to rounding)."""
    if isinstance(want, dict):
        assert list(got) == list(want)
        for key in want:
            _same_numbers(got[key], want[key], rtol)
    elif isinstance(want, list) and want and all(isinstance(x, (int, float)) for x in want):
        a, b = np.asarray(got, float), np.asarray(want, float)
        assert a.shape == b.shape and np.allclose(a, b, rtol=0, atol=rtol * max(np.abs(b).max(), 1e-300)), (a, b)
    elif isinstance(want, list):
        assert len(got) == len(want)
        for x, y in zip(got, want):
            _same_numbers(x, y, rtol)
    elif isinstance(want, float):
        assert got == pytest.approx(want, rel=rtol, abs=1e-300)
    else:
        assert got == want


def test_a_higher_pair_model_through_the_command_and_the_report(tmp_path, capsys):
    """models/rack_pinion.toml with tolerances on the rack's radius and line and clearances: the command
    prints its table with the rack's dimensions ranked (exit 0), the same on the numba backend, and the
    report has its Accuracy section; a clearance on the rack itself, or a misspelt rack dimension, is an
    error naming the row (exit 2)."""
    section = {"outputs": ["4"], "dimensions": [{"name": "joints.K.radius", "band": 0.00002},
                                                 {"name": "joints.K.guide", "band": 0.02},
                                                 {"name": "links.1.length", "band": 0.00002}],
               "clearances": [{"joint": "Q", "clearance": 0.00002}]}
    path = _with_section(tmp_path, "rack_pinion", section)
    assert main(["accuracy", str(path), "--samples", "500", "--positions", "24"]) == 0
    text = capsys.readouterr().out
    assert text.startswith("rack_pinion: 3 toleranced dimension(s), 1 clearance(s); 24 positions")
    assert "joints.K.radius" in text and "500 assembled" in text
    assert main(["accuracy", str(path), "--samples", "500", "--positions", "24", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    if __import__("importlib").util.find_spec("numba"):
        assert main(["--backend", "numba", "accuracy", str(path), "--samples", "500", "--positions", "24",
                     "--json"]) == 0
        _same_numbers(json.loads(capsys.readouterr().out)["outputs"], doc["outputs"])  # (the design kernel's)
    report = tmp_path / "report.html"
    assert main(["report", str(path), "-o", str(report)]) == 0
    assert "Errors over the cycle" in report.read_text(encoding="utf-8")
    for bad, words in (({"clearances": [{"joint": "K", "clearance": 1e-5}]},
                        "clearances[0] 'K': 'K' is a rack pair: clearances are for revolute and prismatic pairs"),
                       ({"dimensions": [{"name": "joints.K.radios", "band": 1e-5}]},
                        "'joints.K.radios' is not a dimension of the model (closest: joints.K.radius")):
        capsys.readouterr()
        assert main(["accuracy", str(_with_section(tmp_path, "rack_pinion", bad)), "--samples", "10"]) == 2
        err = capsys.readouterr().err
        assert words in err and "Traceback" not in err, err


def _moved(tmp_path, name, offset):
    """models/NAME.toml with every drawn coordinate (joints, points, loads) moved by (offset, offset)."""
    import re
    text = (MODELS / f"{name}.toml").read_text(encoding="utf-8")
    number = r"(-?[0-9.]+(?:e-?[0-9]+)?)"
    text = re.sub(rf"at = \[{number}, {number}\]",
                  lambda m: f"at = [{float(m[1]) + offset!r}, {float(m[2]) + offset!r}]", text)
    path = tmp_path / f"{name}_{offset:g}.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_a_higher_pair_model_far_from_the_origin_gives_the_origins_answers(tmp_path):
    """models/rack_pinion.toml moved 10⁶ m: the rack's radius, line and pitch point and a rod's length give
    the sensitivities (1e-6 relative, measured 1e-9) and the Monte Carlo's σ (1e-5, measured 2e-7) found
    at the origin."""
    spec = ToleranceSpec(tuple(Tolerance(d, -1e-5, 1e-5) for d in ("joints.K.radius", "joints.K.guide",
                                                                    "joints.K.x", "links.2.length")),
                         outputs=("4", "B"), samples=300, positions=24)
    near, far = (accuracy(path, spec=spec) for path in (MODELS / "rack_pinion.toml", _moved(tmp_path, "rack_pinion", 1e6)))
    assert np.abs(far.sensitivities.d - near.sensitivities.d).max() <= 1e-6 * np.abs(near.sensitivities.d).max()
    assert np.abs(far.monte_carlo.std - near.monte_carlo.std).max() <= 1e-5 * np.abs(near.monte_carlo.std).max()


@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize("name", ["shaper", "six_bar_press"])
def test_far_from_the_origin_the_analysis_gives_the_origins_answers(tmp_path, name, backend):
    """The shaper (loaded: clearances under load, knocks) and the six-bar press (a slider's value) moved
    1e6 m from the origin (the engine's frame, `Engine.centre`): the same sensitivities, stacks, Monte
    Carlo (same seed) and clearances, the positions moved by the offset. The tolerances allow the
    rounding of the drawn coordinates there (1.2e-10 m, on links of 0.1-2 m: 1.4e-8 of the press's largest
    sensitivity measured)."""
    if backend == "numba":
        pytest.importorskip("numba")
    near = accuracy(MODELS / f"{name}.toml", samples=400, positions=24, backend=backend)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        far = accuracy(_moved(tmp_path, name, 1e6), samples=400, positions=24, backend=backend)
    assert far.success and near.success

    def close(a, b, rel):
        assert np.abs(a - b).max() <= rel * np.abs(b).max()

    close(far.sensitivities.d, near.sensitivities.d, 1e-6)
    close(far.stack.worst, near.stack.worst, 1e-6)
    close(far.stack.sigma, near.stack.sigma, 1e-6)
    shift = np.array([1e6 if o.kind in ("x", "y") else 0.0 for o in near.outputs])
    assert np.abs(far.sensitivities.value - shift - near.sensitivities.value).max() <= 1e-7
    assert far.monte_carlo.count == near.monte_carlo.count
    close(far.monte_carlo.std, near.monte_carlo.std, 1e-5)
    assert np.abs(far.monte_carlo.mean - shift - near.monte_carlo.mean).max() <= 1e-7
    if near.clearances is not None:
        close(far.clearances.worst, near.clearances.worst, 1e-6)
        # (the shaper's cutting resistance starts at φ = 0: its reactions jump there, and the rounding of
        # the position decides the side, so the errors under load are compared past that position)
        close(far.clearances.error[1:], near.clearances.error[1:], 1e-6)
        assert far.clearances.knocks.keys() == near.clearances.knocks.keys()
        for joint, at in near.clearances.knocks.items():
            assert np.allclose(far.clearances.knocks[joint], at, atol=1e-6), joint
