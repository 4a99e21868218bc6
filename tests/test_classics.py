"""An audit of the engine on classic linkages it was not built around, against solutions written here
independently of mbplanar: closed forms derived in the docstrings, successive circle (and line)
intersections with their rates from the differentiated distance equations, the cosine rule for dead
points, statics by hand and virtual work, and printed textbook values.

Every mechanism is written as TOML text (the table an engineer writes), read with
`mbplanar.parse_model(tomllib.loads(text))` and, for the command line, saved to a file.

The reference solutions use the same few tools: `Kin` holds a point's position p, first analogue v = dp/dφ
and second analogue a = d²p/dφ² over a batch; `crank_point`, `dyad` (two circles), `on_line` (circle and
line), `rigid` (a point carried by a link) and `direction` (angle of a line and its rates) build them.
`dyad` and `on_line` differentiate the distance equations: for |X − P| = l, (X − P)·(X' − P') = 0 and
(X − P)·(X'' − P'') + |X' − P'|² = 0.
"""

from __future__ import annotations

import json
import math
import tomllib
from dataclasses import dataclass

import numpy as np
import pytest

import mbplanar
from mbplanar.cli import main

TAU = 2 * math.pi
WORST: dict[str, float] = {}   # tag → worst error met (printed at the end with `pytest -s`)


@pytest.fixture(scope="module", autouse=True)
def _summary():
    """Print the worst error met per quantity after the module's tests (visible with `pytest -s`)."""
    yield
    if WORST:
        print("\nworst errors against the independent solutions:")
        for tag, err in sorted(WORST.items()):
            print(f"  {tag:55s} {err:.2e}")


def close(tag, got, want, tol, scale=None):
    """Assert |got − want| ≤ tol (·max(1, |want|) when `scale` is "rel"), NaN-free; record the worst."""
    got, want = np.asarray(got, float), np.asarray(want, float)
    assert got.shape == want.shape, (tag, got.shape, want.shape)
    assert np.all(np.isfinite(got)), f"{tag}: non-finite values from the engine"
    err = np.abs(got - want)
    if scale == "rel":
        err = err / np.maximum(1.0, np.abs(want))
    worst = float(err.max()) if err.size else 0.0
    WORST[tag] = max(WORST.get(tag, 0.0), worst)
    assert worst <= tol, f"{tag}: worst error {worst:.3e} > {tol:.1e}"


def wrap(angle):
    """Angle difference folded into [−π, π)."""
    return np.remainder(np.asarray(angle) + math.pi, TAU) - math.pi


def close_angle(tag, got, want, tol):
    close(tag, wrap(np.asarray(got) - np.asarray(want)), np.zeros(np.shape(want)), tol)


# -- TOML text of a mechanism -------------------------------------------------------------------------
def _toml_value(v):
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return repr(float(v))


def _toml_row(row):
    return "{ " + ", ".join(f"{k} = {_toml_value(v)}" for k, v in row.items()) + " }"


def table(name, links, joints, inp, points=(), loads=()):
    """The TOML text of a model: rows are dicts (coordinates in metres, angles in degrees)."""
    lines = [f"name = {json.dumps(name)}", "links = ["]
    lines += [f"  {_toml_row(r)}," for r in links] + ["]", "joints = ["]
    lines += [f"  {_toml_row(r)}," for r in joints] + ["]"]
    if points:
        lines += ["points = ["] + [f"  {_toml_row(r)}," for r in points] + ["]"]
    if loads:
        lines += ["loads = ["] + [f"  {_toml_row(r)}," for r in loads] + ["]"]
    lines += ["[input]"] + [f"{k} = {_toml_value(v)}" for k, v in inp.items()]
    return "\n".join(lines) + "\n"


def engine_of(text):
    return mbplanar.Engine(mbplanar.parse_model(tomllib.loads(text), source="<classics>"))


def R(name, a, b, at):
    return {"name": name, "type": "R", "links": [a, b], "at": [float(at[0]), float(at[1])]}


def P(name, carrier, slider, at, guide):
    return {"name": name, "type": "P", "links": [carrier, slider], "at": [float(at[0]), float(at[1])],
            "guide": guide}


def links(*names, **angle):
    """Link rows; `angle={"3": ["C", "E"]}`-style keywords give a link's reference line."""
    return [{"name": n, **({"angle": angle[f"l{n}"]} if f"l{n}" in angle else {})} for n in names]


# -- the independent reference solutions --------------------------------------------------------------
def cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def dot(a, b):
    return np.einsum("...i,...i->...", a, b)


def perp(a):
    return np.stack([-a[..., 1], a[..., 0]], axis=-1)


@dataclass
class Kin:
    """Position p, analogues v = dp/dφ and a = d²p/dφ², each (B, 2)."""

    p: np.ndarray
    v: np.ndarray
    a: np.ndarray


def fixed(point, batch):
    p = np.broadcast_to(np.asarray(point, float), (batch, 2)).copy()
    return Kin(p, np.zeros_like(p), np.zeros_like(p))


def crank_point(centre, radius, angle, rate=1.0, accel=0.0):
    """A point at `radius` from a fixed `centre` along `angle` turning at rate θ', θ''."""
    e = np.stack([np.cos(angle), np.sin(angle)], axis=-1)
    rate, accel = np.asarray(rate, float)[..., None], np.asarray(accel, float)[..., None]
    return Kin(np.asarray(centre, float) + radius * e, radius * rate * perp(e),
               radius * (accel * perp(e) - rate ** 2 * e))


def _solve2(rows0, rows1, rhs0, rhs1):
    """Solve [rows0; rows1]·x = [rhs0; rhs1] per position (Cramer)."""
    det = cross(rows0, rows1)
    return np.stack([(rhs0 * rows1[..., 1] - rhs1 * rows0[..., 1]) / det,
                     (rows0[..., 0] * rhs1 - rows1[..., 0] * rhs0) / det], axis=-1)


def dyad(Pk: Kin, Qk: Kin, lp, lq, sign) -> Kin:
    """X at lp from P and lq from Q, to the left of P→Q for sign = +1 (the meet of two circles)."""
    d = Qk.p - Pk.p
    dist = np.linalg.norm(d, axis=-1)[..., None]
    u = d / dist
    x = (lp ** 2 - lq ** 2 + dist ** 2) / (2 * dist)
    X = Pk.p + x * u + sign * np.sqrt(lp ** 2 - x ** 2) * perp(u)
    dp, dq = X - Pk.p, X - Qk.p
    V = _solve2(dp, dq, dot(dp, Pk.v), dot(dq, Qk.v))
    A = _solve2(dp, dq, dot(dp, Pk.a) - dot(V - Pk.v, V - Pk.v), dot(dq, Qk.a) - dot(V - Qk.v, V - Qk.v))
    return Kin(X, V, A)


def on_line(Ck: Kin, length, origin, direction_deg, sign=1.0) -> Kin:
    """X = origin + t·u on a fixed line (u at `direction_deg`) at `length` from C; sign = +1 takes the
    larger t. t' = (X−C)·C'/((X−C)·u), t'' = ((X−C)·C'' − |t'u − C'|²)/((X−C)·u)."""
    u = np.array([math.cos(math.radians(direction_deg)), math.sin(math.radians(direction_deg))])
    w = np.asarray(origin, float) - Ck.p
    along = -dot(w, u)
    t = along + sign * np.sqrt(length ** 2 - cross(u, w) ** 2)
    X = np.asarray(origin, float) + t[..., None] * u
    d = X - Ck.p
    du = dot(d, u)
    t1 = dot(d, Ck.v) / du
    rel = t1[..., None] * u - Ck.v
    t2 = (dot(d, Ck.a) - dot(rel, rel)) / du
    return Kin(X, t1[..., None] * u, t2[..., None] * u)


def rigid(Pk: Kin, Qk: Kin, P0, Q0, X0) -> Kin:
    """The point of the link through P and Q drawn at X0 (P, Q drawn at P0, Q0): X = P + z·(Q − P) with
    the complex ratio z = (X0 − P0)/(Q0 − P0), a constant rotation and scaling."""
    z = complex(*np.subtract(X0, P0)) / complex(*np.subtract(Q0, P0))
    M = np.array([[z.real, -z.imag], [z.imag, z.real]])
    return Kin(*(p + (q - p) @ M.T for p, q in ((Pk.p, Qk.p), (Pk.v, Qk.v), (Pk.a, Qk.a))))


def direction(Pk: Kin, Qk: Kin):
    """Angle θ of P→Q with θ' = d×d'/|d|² and θ'' = (d×d'' − 2(d·d')θ')/|d|²."""
    d, dv, da = Qk.p - Pk.p, Qk.v - Pk.v, Qk.a - Pk.a
    n2 = dot(d, d)
    w = cross(d, dv) / n2
    return np.arctan2(d[..., 1], d[..., 0]), w, (cross(d, da) - 2 * dot(d, dv) * w) / n2


def compare_points(tag, motion, refs: dict, tol=1e-9):
    """Positions, velocity and acceleration analogues of named points against `Kin` references."""
    for name, ref in refs.items():
        k = motion.point(name)
        close(f"{tag}: {name} position", motion.xy[:, k], ref.p, tol)
        close(f"{tag}: {name} velocity analogue", motion.vq[:, k], ref.v, tol, "rel")
        close(f"{tag}: {name} acceleration analogue", motion.aq[:, k], ref.a, tol, "rel")


def compare_link(tag, motion, link, ref, tol=1e-9):
    """Angle, ω and ε analogues of a link against (θ, θ', θ'')."""
    k = motion.link(link)
    close_angle(f"{tag}: link {link} angle", motion.angle[:, k], ref[0], tol)
    close(f"{tag}: link {link} angular velocity analogue", motion.wq[:, k], ref[1], tol, "rel")
    close(f"{tag}: link {link} angular acceleration analogue", motion.eq[:, k], ref[2], tol, "rel")


def cli(args, capsys):
    """Run the command line; return (exit code, stdout, stderr)."""
    code = main([str(a) for a in args])
    out = capsys.readouterr()
    return code, out.out, out.err


def assert_clean_failure(code, err, expected_codes=(1,)):
    """A failed command: the expected exit status and one line on stderr, no traceback, no NaN."""
    assert code in expected_codes, err
    assert err.startswith("mbplanar: ") and err.count("\n") == 1, err
    assert "Traceback" not in err and "nan" not in err.lower().split(), err


def redriven(text, joint, unit):
    """The same table driven at another joint: φ is that joint's value, in `unit`."""
    return text.split("[input]")[0] + f'[input]\njoint = "{joint}"\nunit = "{unit}"\n'


def _reach_of(engine):
    """The input range reachable from the drawn pose (SI), from `check`."""
    report = mbplanar.check(engine)
    scale = engine.inputs[0].scale
    return (report.range[0] * scale, report.range[1] * scale), report.limits, report.full_turn


# == 1. Offset slider-crank ============================================================================
# Crank OA = r about O = (0, 0), rod AB = l, slider B on the line y = e (offset e ≠ 0), crank angle φ.
SC_R, SC_L, SC_E = 0.08, 0.30, 0.04
SC_PHI0 = math.radians(30.0)


def offset_slider_crank(loads=()):
    A = (SC_R * math.cos(SC_PHI0), SC_R * math.sin(SC_PHI0))
    B = (A[0] + math.sqrt(SC_L ** 2 - (A[1] - SC_E) ** 2), SC_E)
    joints = [R("O", "0", "1", (0, 0)), R("A", "1", "2", A), R("B", "2", "3", B), P("Bp", "0", "3", B, 0.0)]
    return table("offset_slider_crank", links("1", "2", "3"), joints, {"joint": "O", "unit": "rad"},
                 loads=loads), B


def slider_closed_form(phi, r=SC_R, l=SC_L, e=SC_E):
    """x_B = r cos φ + s, s = √(l² − w²), w = r sin φ − e; w' = r cos φ, w'' = −r sin φ;
    s' = −w w'/s, s'' = −(w'² + w w'')/s − w² w'²/s³; x' = −r sin φ + s', x'' = −r cos φ + s''."""
    w, w1, w2 = r * np.sin(phi) - e, r * np.cos(phi), -r * np.sin(phi)
    s = np.sqrt(l * l - w * w)
    s1 = -w * w1 / s
    s2 = -(w1 ** 2 + w * w2) / s - w * w * w1 ** 2 / s ** 3
    return r * np.cos(phi) + s, -r * np.sin(phi) + s1, -r * np.cos(phi) + s2


def test_offset_slider_crank_against_its_closed_form():
    text, B0 = offset_slider_crank()
    engine = engine_of(text)
    phi = np.linspace(0.0, TAU, 721)
    motion = mbplanar.analyse(engine, phi, omega=3.0, epsilon=-2.0)
    assert motion.success and not motion.limits
    x, x1, x2 = slider_closed_form(phi)
    k = motion.joint("Bp")
    tag = "1 offset slider-crank"
    close(f"{tag}: slider displacement", motion.value[:, k], x - B0[0], 1e-9)
    close(f"{tag}: slider velocity analogue", motion.rate_q[:, k], x1, 1e-9)
    close(f"{tag}: slider acceleration analogue", motion.accel_q[:, k], x2, 1e-9)
    # real values at ω = 3, ε = −2: v = x'ω, a = x''ω² + x'ε
    close(f"{tag}: slider real velocity", motion.rate[:, k], 3.0 * x1, 1e-9)
    close(f"{tag}: slider real acceleration", motion.accel[:, k], 9.0 * x2 - 2.0 * x1, 1e-9, "rel")
    A = crank_point((0, 0), SC_R, phi)
    Bk = Kin(np.stack([x, np.full_like(x, SC_E)], -1), np.stack([x1, 0 * x1], -1), np.stack([x2, 0 * x2], -1))
    compare_points(tag, motion, {"A": A, "B": Bk})
    compare_link(tag, motion, "2", direction(A, Bk))     # the rod, A→B


def test_offset_slider_crank_stroke_and_time_ratio():
    """Dead points: crank and rod in line. Outer: |OB| = l + r, φ_o = asin(e/(l + r)); inner:
    |OB| = l − r with the crank pointing away from B, φ_i = π + asin(e/(l − r)). Stroke
    H = √((l + r)² − e²) − √((l − r)² − e²); the two strokes take π ± α of crank turn with
    α = asin(e/(l − r)) − asin(e/(l + r)): time ratio K = (π + α)/(π − α)."""
    text, B0 = offset_slider_crank()
    report = mbplanar.check(engine_of(text))
    assert report.full_turn and not report.limits
    slider = next(e for e in report.extremes if e.name == "Bp")
    r, l, e = SC_R, SC_L, SC_E
    tag = "1 offset slider-crank (check)"
    close(f"{tag}: stroke", slider.maximum - slider.minimum,
          math.sqrt((l + r) ** 2 - e ** 2) - math.sqrt((l - r) ** 2 - e ** 2), 1e-9)
    close(f"{tag}: outer dead point x", slider.maximum + B0[0], math.sqrt((l + r) ** 2 - e ** 2), 1e-9)
    phi_o, phi_i = math.asin(e / (l + r)), math.pi + math.asin(e / (l - r))
    close_angle(f"{tag}: outer dead point crank angle", slider.at_max, phi_o, 1e-8)
    close_angle(f"{tag}: inner dead point crank angle", slider.at_min, phi_i, 1e-8)
    # pressure angle at the slider: the rod's angle to the guide, asin|r sin φ − e|/l, at most
    # asin((r + e)/l) (φ = 270°) and zero where r sin φ = e (sampled every 0.5° by `check`)
    (pressure,) = report.pressure
    close(f"{tag}: largest pressure angle (sampled)", pressure.maximum, math.asin((r + e) / l), 1e-4)
    close(f"{tag}: smallest pressure angle (sampled)", pressure.minimum, 0.0, 1e-4)
    alpha = math.asin(e / (l - r)) - math.asin(e / (l + r))
    turn = (slider.at_min - slider.at_max) % TAU          # outer → inner dead point, crank ccw
    ratio = max(turn, TAU - turn) / min(turn, TAU - turn)
    close(f"{tag}: time ratio", ratio, (math.pi + alpha) / (math.pi - alpha), 1e-8)


# == 2. Whitworth quick-return (crank-shaper with a rotating guide) ======================================
# Crank O2A = r about O2 = (0, 0); a block on the crank pin slides in the slotted lever 3 that turns about
# O4 = (0, −d), d < r, so the lever turns fully. The lever's other arm O4C = ρ (C opposite A) drives the
# ram D (on the line y = −d through O4) through the rod CD = L.
WH_R, WH_D, WH_RHO, WH_L = 0.10, 0.04, 0.12, 0.35
WH_PHI0 = math.radians(50.0)


def whitworth():
    O4 = (0.0, -WH_D)
    A = (WH_R * math.cos(WH_PHI0), WH_R * math.sin(WH_PHI0))
    th = math.atan2(A[1] - O4[1], A[0] - O4[0])
    C = (O4[0] - WH_RHO * math.cos(th), O4[1] - WH_RHO * math.sin(th))
    D = (C[0] + math.sqrt(WH_L ** 2 - (O4[1] - C[1]) ** 2), O4[1])
    joints = [R("O2", "0", "1", (0, 0)), R("A", "1", "2", A), P("Ap", "3", "2", A, math.degrees(th)),
              R("O4", "0", "3", O4), R("C", "3", "4", C), R("D", "4", "5", D), P("Dp", "0", "5", D, 0.0)]
    return table("whitworth", links("1", "2", "3", "4", "5", l3=["C", "O4"]), joints,
                 {"joint": "O2", "unit": "rad"}), D


def whitworth_lever(phi):
    """θ = atan2(r sin φ + d, r cos φ) (the direction O4→A = C→O4); with N = r² + r d sin φ and
    D = ρ_A² = r² + d² + 2 r d sin φ: θ' = N/D, θ'' = (N'D − N D')/D², N' = r d cos φ, D' = 2 r d cos φ."""
    r, d = WH_R, WH_D
    N, D = r * r + r * d * np.sin(phi), r * r + d * d + 2 * r * d * np.sin(phi)
    N1, D1 = r * d * np.cos(phi), 2 * r * d * np.cos(phi)
    return np.arctan2(r * np.sin(phi) + d, r * np.cos(phi)), N / D, (N1 * D - N * D1) / D ** 2


def test_whitworth_lever_and_ram_against_their_closed_forms():
    text, D0 = whitworth()
    engine = engine_of(text)
    assert engine.topology.structure.formula.count("II") == 2
    phi = np.linspace(0.0, TAU, 721)
    motion = mbplanar.analyse(engine, phi)
    assert motion.success
    tag = "2 Whitworth"
    lever = whitworth_lever(phi)
    compare_link(tag, motion, "3", lever)
    C = crank_point((0.0, -WH_D), WH_RHO, lever[0] + math.pi, lever[1], lever[2])
    D = on_line(C, WH_L, (0.0, -WH_D), 0.0)
    compare_points(tag, motion, {"A": crank_point((0, 0), WH_R, phi), "C": C, "D": D})
    k = motion.joint("Dp")
    close(f"{tag}: ram displacement", motion.value[:, k], D.p[:, 0] - D0[0], 1e-9)
    # the block's slide along the lever is |O4A| = ρ_A − ρ_A(φ0), ρ_A' = r d cos φ / ρ_A
    rho = np.sqrt(WH_R ** 2 + WH_D ** 2 + 2 * WH_R * WH_D * np.sin(phi))
    rho0 = math.sqrt(WH_R ** 2 + WH_D ** 2 + 2 * WH_R * WH_D * math.sin(WH_PHI0))
    k = motion.joint("Ap")
    close(f"{tag}: block slide along the lever", motion.value[:, k], rho - rho0, 1e-9)
    close(f"{tag}: block slide rate analogue", motion.rate_q[:, k], WH_R * WH_D * np.cos(phi) / rho, 1e-9)


def test_whitworth_stroke_and_time_ratio():
    """The ram is at its ends when the lever lies along the ram line (θ = 0 or π): r sin φ = −d, so the
    strokes take π ± 2β of crank turn, β = asin(d/r): K = (π + 2β)/(π − 2β); the stroke is 2ρ."""
    text, _ = whitworth()
    report = mbplanar.check(engine_of(text))
    assert report.full_turn
    lever = next(e for e in report.extremes if e.name == "3")
    assert lever.turns
    ram = next(e for e in report.extremes if e.name == "Dp")
    tag = "2 Whitworth (check)"
    close(f"{tag}: stroke", ram.maximum - ram.minimum, 2 * WH_RHO, 1e-9)
    beta = math.asin(WH_D / WH_R)
    close_angle(f"{tag}: crank angle at the far end", ram.at_max, math.pi + beta, 1e-8)
    close_angle(f"{tag}: crank angle at the near end", ram.at_min, -beta, 1e-8)
    turn = (ram.at_max - ram.at_min) % TAU
    close(f"{tag}: time ratio", turn / (TAU - turn), (math.pi + 2 * beta) / (math.pi - 2 * beta), 1e-8)


def test_whitworth_driven_by_its_ram_reports_the_dead_point_positions_exactly():
    """Driven by the ram, the Whitworth stops where O4, C and D line up on the ram line y = −d: the lever
    (reference C → O4) lies along it, at 0° and 180°, and the crank pin A, on the lever's line, is at
    height −d: crank angles −β and 180° + β, β = asin(d/r). The driven links move like the square root
    of the ram's distance from the limit, so these come from the configuration solved at the limits (a
    sample 1e-9 of the range inside had the lever at 0.005°)."""
    text, _ = whitworth()
    report = mbplanar.check(engine_of(redriven(text, "Dp", "m")))
    tag = "2 Whitworth driven by the ram (check)"
    lever = next(e for e in report.extremes if e.name == "3")
    close(f"{tag}: lever extremes at the dead points (deg)", np.degrees([lever.minimum, lever.maximum]),
          [0.0, 180.0], 1e-9)
    crank = next(e for e in report.extremes if e.name == "1")
    beta = math.degrees(math.asin(WH_D / WH_R))
    close(f"{tag}: crank extremes at the dead points (deg)", np.degrees([crank.minimum, crank.maximum]),
          [-beta, 180.0 + beta], 1e-9)
    assert sorted([lever.at_min, lever.at_max]) == list(report.range)


def test_whitworth_in_degrees_clockwise_from_a_zero():
    """The same Whitworth with the seed-style input: f in degrees, clockwise, zero = 90°: the crank angle
    is φ = 90° − f, so θ_f = −θ_φ and θ_ff = θ_φφ (per radian of f); real rates scale with ω, ε."""
    text, _ = whitworth()
    text = text.split("[input]")[0] + '[input]\njoint = "O2"\nunit = "deg"\nzero = 90.0\nsense = "cw"\n'
    engine = engine_of(text)
    f = np.linspace(-180.0, 180.0, 181)
    motion = mbplanar.analyse(engine, np.radians(f), omega=2.0, epsilon=0.5)
    assert motion.success
    th, w, e = whitworth_lever(np.radians(90.0 - f))
    tag = "2 Whitworth, f = 90° − φ (deg, cw)"
    compare_link(tag, motion, "3", (th, -w, e))
    k = motion.link("3")
    close(f"{tag}: lever real ω", motion.w[:, k], -2.0 * w, 1e-9, "rel")
    close(f"{tag}: lever real ε", motion.e[:, k], 4.0 * e - 0.5 * w, 1e-9, "rel")
    close(f"{tag}: drawn input", math.degrees(float(engine.phi_drawn[0])), 90.0 - math.degrees(WH_PHI0), 1e-9)


# == 3. Oscillating cylinder (inverted slider-crank, RPR) ================================================
# Crank OA = r about O = (0, 0); the piston rod 2 is pinned to the crank at A and slides in the cylinder 3,
# which swings about C = (d, 0); d > r. Its extension s = |CA| is the prismatic joint's value s − s0.
OC_R, OC_D = 0.05, 0.20
OC_PHI0 = math.radians(70.0)


def oscillating_cylinder(driver="O", unit="rad"):
    A = (OC_R * math.cos(OC_PHI0), OC_R * math.sin(OC_PHI0))
    C = (OC_D, 0.0)
    guide = math.degrees(math.atan2(A[1] - C[1], A[0] - C[0]))  # from C towards A: + is extension
    joints = [R("O", "0", "1", (0, 0)), R("A", "1", "2", A), P("Cp", "3", "2", A, guide), R("C", "0", "3", C)]
    points = [{"name": "E", "link": "3", "at": list(A)}]  # on the cylinder's axis: its angle C→E
    return table(f"oscillating_cylinder_{driver}", links("1", "2", "3", l3=["C", "E"]), joints,
                 {"joint": driver, "unit": unit}, points=points), math.dist(A, C)


def test_oscillating_cylinder_driven_by_the_crank():
    """θ_3 = direction C→A; s = |A − C|, s' = (A − C)·A'/s, s'' = (|A'|² + (A − C)·A'' − s'²)/s."""
    text, s0 = oscillating_cylinder()
    engine = engine_of(text)
    phi = np.linspace(0.0, TAU, 721)
    motion = mbplanar.analyse(engine, phi)
    assert motion.success
    tag = "3 oscillating cylinder, crank input"
    A, C = crank_point((0, 0), OC_R, phi), fixed((OC_D, 0.0), len(phi))
    compare_link(tag, motion, "3", direction(C, A))
    compare_link(tag, motion, "2", direction(C, A))   # the piston rod's line is the cylinder's
    d = A.p - C.p
    s = np.linalg.norm(d, axis=-1)
    s1 = dot(d, A.v) / s
    s2 = (dot(A.v, A.v) + dot(d, A.a) - s1 ** 2) / s
    k = motion.joint("Cp")
    close(f"{tag}: extension", motion.value[:, k], s - s0, 1e-9)
    close(f"{tag}: extension rate analogue", motion.rate_q[:, k], s1, 1e-9)
    close(f"{tag}: extension acceleration analogue", motion.accel_q[:, k], s2, 1e-9)


def crank_from_extension(s):
    """Cosine rule: s² = r² + d² − 2 r d cos φ, φ ∈ (0, π) on the drawn branch; differentiating
    r d sin φ·φ' = s twice: φ' = s/(r d sin φ), φ'' = (1 − r d cos φ·φ'²)/(r d sin φ)."""
    r, d = OC_R, OC_D
    phi = np.arccos((r * r + d * d - s * s) / (2 * r * d))
    w = s / (r * d * np.sin(phi))
    return phi, w, (1 - r * d * np.cos(phi) * w ** 2) / (r * d * np.sin(phi))


def test_oscillating_cylinder_driven_by_its_extension():
    """The cylinder as the actuator (a prismatic input between two moving links, unit m): the crank
    angle follows the cosine rule and the motion ends where crank and cylinder line up, s = d ∓ r."""
    text, s0 = oscillating_cylinder("Cp", "m")
    engine = engine_of(text)
    lo, hi = OC_D - OC_R - s0, OC_D + OC_R - s0            # the input's reachable range
    margin = 2e-3
    ext = np.linspace(lo + margin, hi - margin, 401)
    motion = mbplanar.analyse(engine, ext)
    assert motion.success
    tag = "3 oscillating cylinder, extension input"
    phi = crank_from_extension(s0 + ext)
    compare_link(tag, motion, "1", phi, tol=1e-9)
    A = crank_point((0, 0), OC_R, *phi)
    compare_points(tag, motion, {"A": A})
    compare_link(tag, motion, "3", direction(fixed((OC_D, 0.0), len(ext)), A))
    # real rates for a prismatic input: ṡ = 0.3 m/s, s̈ = 0.1 m/s²
    real = mbplanar.analyse(engine, ext, omega=0.3, epsilon=0.1)
    k = real.link("1")
    close(f"{tag}: crank real ω", real.w[:, k], 0.3 * phi[1], 1e-9, "rel")
    close(f"{tag}: crank real ε", real.e[:, k], 0.09 * phi[2] + 0.1 * phi[1], 1e-9, "rel")
    # the limits: reported where the cosine rule ends
    past = mbplanar.analyse(engine, np.linspace(lo - 0.01, hi + 0.01, 201))
    assert not past.success and len(past.limits) == 2
    assert np.all(np.isfinite(past.xy)) and np.all(np.isfinite(past.aq))
    got = sorted(float(lim.phi[0]) for lim in past.limits)
    close(f"{tag}: motion limits (m)", got, [lo, hi], 1e-13)
    assert past.phi[:, 0].min() >= lo - 1e-9 and past.phi[:, 0].max() <= hi + 1e-9
    report = mbplanar.check(engine)
    assert not report.full_turn
    close(f"{tag}: check range (m)", report.range, (lo, hi), 1e-13)
    close(f"{tag}: check limits (m)", sorted(lim.phi for lim in report.limits), [lo, hi], 1e-13)
    # the crank's extremes are where crank and cylinder line up (φ = 0, π): at the limits, where φ moves
    # like the square root of the input (a sample 1e-9 of the range inside would be off by ~7e-5 rad);
    # `check` takes them from the configuration solved at the limits
    crank = next(e for e in report.extremes if e.name == "1")
    close(f"{tag}: crank extremes (check, at the limits)", [crank.minimum, crank.maximum], [0.0, math.pi],
          1e-12)


# == 4. Six-bars: Watt II and Stephenson III ==============================================================
# Both start from the crank-rocker O2A = 0.1, AB = 0.35, O4B = 0.3, O2 = (0, 0), O4 = (0.3, 0).
FB_O4, FB_AB, FB_O4B, FB_R = (0.3, 0.0), 0.35, 0.30, 0.10
SIX_PHI0 = math.radians(40.0)


def _fourbar_points(phi):
    A = crank_point((0, 0), FB_R, phi)
    B = dyad(A, fixed(FB_O4, len(np.atleast_1d(phi))), FB_AB, FB_O4B, +1)   # B above the line A→O4
    return A, B


def _p0(kin):
    return tuple(float(c) for c in kin.p[0])


def fourbar_table(O4, a, b, c, phi0, sign=+1, masses=None):
    """Crank O2A = a about (0, 0), coupler AB = b, rocker O4B = c, drawn at crank angle phi0 (rad) with B
    on the side `sign` of A→O4; input O2 in degrees; `masses`: link rows' extra keys and points."""
    A = crank_point((0, 0), a, np.array([phi0]))
    A0, B0 = _p0(A), _p0(dyad(A, fixed(O4, 1), b, c, sign))
    rows = links("1", "2", "3", l3=["O4", "B"])
    points = []
    for row in rows:
        if masses and row["name"] in masses:
            extra, centre = masses[row["name"]]
            row.update(extra, centre=f"S{row['name']}")
            points.append({"name": f"S{row['name']}", "link": row["name"], "at": list(centre(A0, B0))})
    joints = [R("O2", "0", "1", (0, 0)), R("A", "1", "2", A0), R("B", "2", "3", B0), R("O4", "0", "3", O4)]
    return table("fourbar", rows, joints, {"joint": "O2", "unit": "deg"}, points=points), (A0, B0)


# Watt II: the rocker O4B carries C (O4C = 0.2 at 100° clockwise from O4→B), which drives a second
# four-bar: CD = 0.3, O6D = 0.25, O6 = (0.55, −0.35); M is a point of the coupler CD.
W_O4C, W_CD, W_O6D, W_O6 = 0.20, 0.30, 0.25, (0.55, -0.35)


def watt_ii_solution(phi):
    """Successive circle intersections: B from A and O4, C carried by the rocker, D from C and O6."""
    A, B = _fourbar_points(phi)
    th, w, e = direction(fixed(FB_O4, len(phi)), B)
    C = crank_point(FB_O4, W_O4C, th - math.radians(100.0), w, e)
    D = dyad(C, fixed(W_O6, len(phi)), W_CD, W_O6D, -1)
    return A, B, C, D


def watt_ii():
    A, B, C, D = (_p0(k) for k in watt_ii_solution(np.array([SIX_PHI0])))
    M = (0.5 * (C[0] + D[0]) + 0.04, 0.5 * (C[1] + D[1]) + 0.05)
    joints = [R("O2", "0", "1", (0, 0)), R("A", "1", "2", A), R("B", "2", "3", B), R("O4", "0", "3", FB_O4),
              R("C", "3", "4", C), R("D", "4", "5", D), R("O6", "0", "5", W_O6)]
    points = [{"name": "M", "link": "4", "at": list(M)},   # drawn, and built on C→D:
              {"name": "N", "link": "4", "along": ["C", "D"], "distance": 0.1, "offset": -0.05}]
    return table("watt_ii", links("1", "2", "3", "4", "5", l3=["O4", "B"], l5=["O6", "D"]), joints,
                 {"joint": "O2", "unit": "rad"}, points=points), (C, D, M)


def test_watt_ii_six_bar_by_successive_circle_intersections():
    text, (C0, D0, M0) = watt_ii()
    engine = engine_of(text)
    assert engine.topology.structure.formula == "I(0,1) → II(2,3) → II(4,5)"
    phi = np.linspace(0.0, TAU, 721)
    motion = mbplanar.analyse(engine, phi)
    assert motion.success
    A, B, C, D = watt_ii_solution(phi)
    M = rigid(C, D, C0, D0, M0)
    u = np.subtract(D0, C0) / W_CD
    N = rigid(C, D, C0, D0, tuple(np.add(C0, 0.1 * u - 0.05 * np.array([-u[1], u[0]]))))  # 0.05 to the right
    tag = "4 Watt II"
    compare_points(tag, motion, {"A": A, "B": B, "C": C, "D": D, "M": M, "N": N})
    n = len(phi)
    for link, (p, q) in {"2": (A, B), "3": (fixed(FB_O4, n), B), "4": (C, D), "5": (fixed(W_O6, n), D)}.items():
        compare_link(tag, motion, link, direction(p, q))


# Stephenson III: the dyad Q–E–O6 hangs on the coupler point Q of the four-bar (AQ = 0.2 along AB and
# 0.15 to its left) and on the ground at O6 = (0.1, 0.45): QE = 0.25, O6E = 0.2.
S_QE, S_O6E, S_O6 = 0.25, 0.20, (0.1, 0.45)


def stephenson_iii_solution(phi, A0=None, B0=None, Q0=None):
    """B from A and O4; Q carried by the coupler (drawn at Q0 with A0, B0); E from Q and O6."""
    A, B = _fourbar_points(phi)
    if Q0 is None:  # the drawn pose: Q at 0.2 along AB and 0.15 to its left
        A0, B0 = _p0(A), _p0(B)
        u = np.subtract(B0, A0) / FB_AB
        Q0 = tuple(np.add(A0, 0.2 * u + 0.15 * np.array([-u[1], u[0]])))
    Q = rigid(A, B, A0, B0, Q0)
    E = dyad(Q, fixed(S_O6, len(phi)), S_QE, S_O6E, +1)
    return A, B, Q, E


def stephenson_iii():
    A0, B0, Q0, E0 = (_p0(k) for k in stephenson_iii_solution(np.array([SIX_PHI0])))
    joints = [R("O2", "0", "1", (0, 0)), R("A", "1", "2", A0), R("B", "2", "3", B0), R("O4", "0", "3", FB_O4),
              R("Q", "2", "4", Q0), R("E", "4", "5", E0), R("O6", "0", "5", S_O6)]
    return table("stephenson_iii", links("1", "2", "3", "4", "5", l3=["O4", "B"], l5=["O6", "E"]), joints,
                 {"joint": "O2", "unit": "rad"}), (A0, B0, Q0)


def test_stephenson_iii_six_bar_by_successive_circle_intersections():
    text, (A0, B0, Q0) = stephenson_iii()
    engine = engine_of(text)
    phi = np.linspace(0.0, TAU, 721)
    motion = mbplanar.analyse(engine, phi)
    assert motion.success
    n = len(phi)
    A, B, Q, E = stephenson_iii_solution(phi, A0, B0, Q0)
    tag = "4 Stephenson III"
    compare_points(tag, motion, {"A": A, "B": B, "Q": Q, "E": E})
    for link, (p, q) in {"2": (A, B), "3": (fixed(FB_O4, n), B), "4": (Q, E), "5": (fixed(S_O6, n), E)}.items():
        compare_link(tag, motion, link, direction(p, q))


@pytest.mark.parametrize("which", ["watt_ii", "stephenson_iii"])
def test_six_bars_driven_at_the_output_rocker_invert_the_forward_solution(which):
    """Driven at O6 (Stephenson III then solves a class III group, links 1–4), the engine's crank angle φ
    fed back into the crank-driven circle construction must give the requested output angle ψ and the
    same points; the rates invert: φ' = 1/ψ_φ, φ'' = −ψ_φφ/ψ_φ³ (ψ_φ, ψ_φφ from the construction)."""
    text, O6, last = {"watt_ii": (watt_ii()[0], W_O6, "D"),
                      "stephenson_iii": (stephenson_iii()[0], S_O6, "E")}[which]
    engine = engine_of(redriven(text, "O6", "rad"))
    (lo, hi), _, _ = _reach_of(engine)
    psi = np.linspace(lo + 0.02, hi - 0.02, 101)
    motion = mbplanar.analyse(engine, psi)
    assert motion.success
    phi = motion.angle[:, motion.link("1")]
    if which == "watt_ii":
        A, B, C, D = watt_ii_solution(phi)
        refs = {"A": A, "B": B, "C": C, "D": D}
    else:
        _, (A0, B0, Q0) = stephenson_iii()
        A, B, Q, E = stephenson_iii_solution(phi, A0, B0, Q0)
        refs = {"A": A, "B": B, "Q": Q, "E": E}
    out, out1, out2 = direction(fixed(O6, len(phi)), refs[last])
    tag = f"4 {which} driven at O6"
    close_angle(f"{tag}: output angle of the forward construction", out, psi, 1e-9)
    for name, ref in refs.items():
        close(f"{tag}: {name} position", motion.xy[:, motion.point(name)], ref.p, 1e-9)
    k = motion.link("1")
    close(f"{tag}: crank rate analogue dφ/dψ", motion.wq[:, k], 1 / out1, 1e-9, "rel")
    close(f"{tag}: crank acceleration analogue d²φ/dψ²", motion.eq[:, k], -out2 / out1 ** 3, 1e-9, "rel")


# == 5. Double sliders ===================================================================================
# A central slider-crank (OA = 0.06, AB = 0.25, slider 3 on the x axis) drives two more sliders:
#  * RRP: the link BC = 0.3 pinned to slider 3 at B moves slider 5 on a guide through G = (0.5, 0) at 120°;
#  * PRP: slider 3 carries a slot at β = 30° through W = B0 + (0.06, 0.02); the block 6 in it is pinned at
#    D to slider 7, which moves on the vertical line x = x_V (a wedge).
DS_R, DS_L, DS_M, DS_G, DS_GUIDE, DS_BETA = 0.06, 0.25, 0.30, (0.5, 0.0), 120.0, 30.0
DS_PHI0 = math.radians(20.0)


def double_slider():
    A = (DS_R * math.cos(DS_PHI0), DS_R * math.sin(DS_PHI0))
    xb = float(slider_closed_form(DS_PHI0, DS_R, DS_L, 0.0)[0])
    B = (xb, 0.0)
    C = _p0(on_line(fixed(B, 1), DS_M, DS_G, DS_GUIDE, +1))
    W = (xb + 0.06, 0.02)
    xv = xb + 0.15
    D = (xv, W[1] + (xv - W[0]) * math.tan(math.radians(DS_BETA)))
    joints = [R("O", "0", "1", (0, 0)), R("A", "1", "2", A), R("B", "2", "3", B), P("Bp", "0", "3", B, 0.0),
              R("B4", "3", "4", B), R("C", "4", "5", C), P("Cp", "0", "5", C, DS_GUIDE),
              P("S", "3", "6", D, DS_BETA), R("D", "6", "7", D), P("V", "0", "7", D, 90.0)]
    return table("double_slider", links(*"1234567", l4=["B4", "C"]), joints, {"joint": "O", "unit": "rad"}), \
        (B, C, D)


def test_double_slider_rrp_and_prp_against_their_closed_forms():
    """x_B from the slider-crank closed form; C = G + t·u on the 120° guide at 0.3 from B (`on_line`);
    the wedge: y_D = y_D0 − Δx_B·tan β, and the block slides −Δx_B / cos β along the slot."""
    text, (B0, C0, D0) = double_slider()
    engine = engine_of(text)
    kinds = sorted(g.kind for g in engine.topology.structure.groups)
    assert kinds == ["PRP", "RRP", "RRP"], kinds
    phi = np.linspace(0.0, TAU, 721)
    motion = mbplanar.analyse(engine, phi)
    assert motion.success
    x, x1, x2 = slider_closed_form(phi, DS_R, DS_L, 0.0)
    zero = np.zeros_like(x)
    B = Kin(np.stack([x, zero], -1), np.stack([x1, zero], -1), np.stack([x2, zero], -1))
    C = on_line(B, DS_M, DS_G, DS_GUIDE, +1)
    tan, cos = math.tan(math.radians(DS_BETA)), math.cos(math.radians(DS_BETA))
    D = Kin(np.stack([np.full_like(x, D0[0]), D0[1] - (x - B0[0]) * tan], -1),
            np.stack([zero, -x1 * tan], -1), np.stack([zero, -x2 * tan], -1))
    tag = "5 double slider"
    compare_points(tag, motion, {"B": B, "C": C, "D": D})
    compare_link(tag, motion, "4", direction(B, C))
    u = np.array([math.cos(math.radians(DS_GUIDE)), math.sin(math.radians(DS_GUIDE))])
    for joint, (val, rate, acc) in {
            "Cp": (dot(C.p - C0, u), dot(C.v, u), dot(C.a, u)),
            "V": (D.p[:, 1] - D0[1], D.v[:, 1], D.a[:, 1]),
            "S": (-(x - B0[0]) / cos, -x1 / cos, -x2 / cos)}.items():
        k = motion.joint(joint)
        close(f"{tag}: joint {joint} value", motion.value[:, k], val, 1e-9)
        close(f"{tag}: joint {joint} rate analogue", motion.rate_q[:, k], rate, 1e-9)
        close(f"{tag}: joint {joint} acceleration analogue", motion.accel_q[:, k], acc, 1e-9)
    for link in ("3", "5", "6", "7"):   # the sliders and the block translate
        k = motion.link(link)
        close(f"{tag}: link {link} does not turn", np.abs(motion.wq[:, k]) + np.abs(motion.eq[:, k]), zero, 1e-12)


# == 6. A crank-rocker driven by its rocker ================================================================
# O = (0, 0), C = (d, 0); crank OA = r, coupler AB = l, rocker CB = c, rocker angle ψ = direction C→B.
CR_R, CR_L, CR_C, CR_D = 0.12, 0.40, 0.30, 0.45
CR_PSI0 = math.radians(125.0)


def rocker_dead_points():
    """Driven at the rocker, the motion ends where crank and coupler line up, |OB| = l ± r; with
    |OB|² = d² + c² + 2dc·cos ψ (cosine rule in triangle OCB), ψ = acos((|OB|² − d² − c²)/(2dc))."""
    return tuple(math.acos((ob ** 2 - CR_D ** 2 - CR_C ** 2) / (2 * CR_D * CR_C))
                 for ob in (CR_L + CR_R, CR_L - CR_R))


def rocker_driven(psi):
    B = crank_point((CR_D, 0.0), CR_C, psi)
    A = dyad(fixed((0, 0), len(np.atleast_1d(psi))), B, CR_R, CR_L, +1)
    return A, B


def rocker_driven_fourbar():
    A, B = (_p0(k) for k in rocker_driven(np.array([CR_PSI0])))
    joints = [R("O", "0", "1", (0, 0)), R("A", "1", "2", A), R("B", "2", "3", B), R("C", "0", "3", (CR_D, 0))]
    return table("rocker_driven", links("1", "2", "3", l3=["C", "B"]), joints, {"joint": "C", "unit": "deg"})


def test_crank_rocker_driven_by_its_rocker_follows_the_circles_and_stops_at_the_dead_points():
    engine = engine_of(rocker_driven_fourbar())
    lo, hi = rocker_dead_points()
    assert lo < CR_PSI0 < hi
    psi = np.linspace(lo + 0.01, hi - 0.01, 301)
    motion = mbplanar.analyse(engine, psi)
    assert motion.success
    A, B = rocker_driven(psi)
    tag = "6 rocker-driven four-bar"
    compare_points(tag, motion, {"A": A, "B": B})
    O = fixed((0, 0), len(psi))
    compare_link(tag, motion, "1", direction(O, A))
    compare_link(tag, motion, "2", direction(A, B))
    # past the dead points: two limits, where the cosine rule puts them (to 1e-10°)
    past = mbplanar.analyse(engine, np.linspace(lo - 0.05, hi + 0.05, 301))
    assert not past.success and len(past.limits) == 2
    assert np.all(np.isfinite(past.xy)) and np.all(np.isfinite(past.wq))
    got = sorted(math.degrees(float(lim.phi[0])) for lim in past.limits)
    close(f"{tag}: motion.limits (deg)", got, [math.degrees(lo), math.degrees(hi)], 1e-10)
    for lim in past.limits:
        assert "A" in lim.joints or " A" in lim.kind, lim
    report = mbplanar.check(engine)
    assert not report.full_turn and report.grashof is not None and not report.grashof.input_turns
    got = sorted(lim.phi for lim in report.limits)
    close(f"{tag}: check limits (deg)", got, [math.degrees(lo), math.degrees(hi)], 1e-10)
    close(f"{tag}: check range (deg)", report.range, (math.degrees(lo), math.degrees(hi)), 1e-10)


# == 7. Kinetostatics by hand ============================================================================
def _force_on(result, joint, link):
    """(B, 2) force on `link` in `joint`, from the reported reaction or its opposite."""
    r = result.reaction(joint)
    assert link in (r.on, r.source)
    sign = 1.0 if r.on == link else -1.0
    return sign * np.stack([r.fx, r.fy], axis=-1)


@pytest.mark.parametrize("height", [0.0, 0.03])
def test_offset_slider_crank_with_a_force_on_the_slider(height):
    """No masses, F = (−F, 0) on the slider at `height` above B. The rod is a two-force member: it pushes
    the slider with S·u, u = (B − A)/l; the slider's balance along the guide gives S = F/u_x, the guide's
    normal force is −S·u_y and its moment about the slider point B (where the README puts it) balances
    the force's: −height·F. The crank: M_b = S·(A × u). Virtual work: M_b·1 + F·v_q(B) = 0."""
    F = 500.0
    _, B0 = offset_slider_crank()
    at = "B" if height == 0 else [B0[0], B0[1] + height]
    text, _ = offset_slider_crank(loads=[{"type": "force", "link": "3", "at": at, "force": [-F, 0.0]}])
    engine = engine_of(text)
    phi = np.linspace(0.0, TAU, 361)
    motion = mbplanar.analyse(engine, phi, omega=0.0, epsilon=0.0)
    result = mbplanar.kinetostatics(engine, motion)
    assert result.success
    x, x1, _ = slider_closed_form(phi)
    A = crank_point((0, 0), SC_R, phi).p
    B = np.stack([x, np.full_like(x, SC_E)], -1)
    u = (B - A) / SC_L
    S = F / u[:, 0]
    tag = "7 slider-crank statics"
    close(f"{tag}: balancing moment = −F·v_q (virtual work)", result.balancing["O"], F * x1, 1e-9)
    close(f"{tag}: balancing moment = S·(A × u)", result.balancing["O"], S * cross(A, u), 1e-9)
    close(f"{tag}: slider pin B on the slider", _force_on(result, "B", "3"), S[:, None] * u, 1e-9, "rel")
    close(f"{tag}: crank pin A on the crank", _force_on(result, "A", "1"), -S[:, None] * u, 1e-9, "rel")
    close(f"{tag}: bearing O on the crank", _force_on(result, "O", "1"), S[:, None] * u, 1e-9, "rel")
    guide = _force_on(result, "Bp", "3")
    close(f"{tag}: guide on the slider", guide, np.stack([0 * S, -S * u[:, 1]], -1), 1e-9, "rel")
    r = result.reaction("Bp")
    close(f"{tag}: guide moment about the slider point", (1 if r.on == "3" else -1) * r.moment,
          np.full_like(S, -height * F), 1e-9, "rel")
    assert np.all(result.virtual_power_residual < 1e-9)


def test_fourbar_with_a_moment_on_the_rocker():
    """M3 on the rocker, no masses: the coupler pushes the rocker at B with f = S·u (u = (B − A)/|AB|),
    rocker balance about O4: M3 + (B − O4) × f = 0; the crank: M_b = A × f; virtual work
    M_b + M3·ω3_q = 0 with ω3_q from the circle construction."""
    M3 = 40.0
    A0, B0 = (_p0(k) for k in _fourbar_points(np.array([SIX_PHI0])))
    joints = [R("O2", "0", "1", (0, 0)), R("A", "1", "2", A0), R("B", "2", "3", B0), R("O4", "0", "3", FB_O4)]
    text = table("fourbar_moment", links("1", "2", "3", l3=["O4", "B"]), joints, {"joint": "O2", "unit": "rad"},
                 loads=[{"type": "moment", "link": "3", "moment": M3}])
    engine = engine_of(text)
    phi = np.linspace(0.0, TAU, 361)
    motion = mbplanar.analyse(engine, phi, omega=0.0)
    result = mbplanar.kinetostatics(engine, motion)
    assert result.success
    A, B = _fourbar_points(phi)
    u = (B.p - A.p) / FB_AB
    S = -M3 / cross(B.p - np.array(FB_O4), u)
    f = S[:, None] * u
    w3 = direction(fixed(FB_O4, len(phi)), B)[1]
    tag = "7 four-bar statics"
    close(f"{tag}: balancing moment = −M3·ω3_q (virtual work)", result.balancing["O2"], -M3 * w3, 1e-9, "rel")
    close(f"{tag}: balancing moment = A × f", result.balancing["O2"], cross(A.p, f), 1e-9, "rel")
    close(f"{tag}: pin B on the rocker", _force_on(result, "B", "3"), f, 1e-9, "rel")
    close(f"{tag}: bearing O4 on the rocker", _force_on(result, "O4", "3"), -f, 1e-9, "rel")
    close(f"{tag}: pin A on the crank", _force_on(result, "A", "1"), -f, 1e-9, "rel")
    close(f"{tag}: bearing O2 on the crank", _force_on(result, "O2", "1"), f, 1e-9, "rel")


def test_offset_slider_crank_slider_inertia_at_speed():
    """A slider of mass m at constant ω with F = (−F, 0): d'Alembert adds −m·a_B; power balance
    M_b·ω + (F_x − m ω² x'')·x' ω = 0, and the slider's balance along the guide
    S·u_x = −(F_x − m ω² x'')."""
    F, m, omega = 500.0, 2.0, 20.0
    text, _ = offset_slider_crank(loads=[{"type": "force", "link": "3", "at": "B", "force": [-F, 0.0]}])
    text = text.replace('{ name = "3" }', '{ name = "3", mass = 2.0, centre = "B" }')
    engine = engine_of(text)
    phi = np.linspace(0.0, TAU, 361)
    result = mbplanar.kinetostatics(engine, mbplanar.analyse(engine, phi, omega=omega, epsilon=0.0))
    x, x1, x2 = slider_closed_form(phi)
    net = -F - m * omega ** 2 * x2
    tag = "7 slider-crank with slider inertia"
    close(f"{tag}: balancing moment", result.balancing["O"], -net * x1, 1e-9, "rel")
    A = crank_point((0, 0), SC_R, phi).p
    u = (np.stack([x, np.full_like(x, SC_E)], -1) - A) / SC_L
    close(f"{tag}: slider pin B on the slider", _force_on(result, "B", "3"), (-net / u[:, 0])[:, None] * u,
          1e-9, "rel")


def test_whitworth_with_a_cutting_force_on_the_ram():
    """No masses, F = (−F, 0) on the ram. The rod CD pushes the ram with S·u (u = (D − C)/L), S = F/u_x;
    the block presses the lever at A with N = n·perp(e) (e = unit O4→A, a frictionless slot), and the
    lever's balance about O4, (C − O4) × (−S u) + ρ_A·n = 0, gives n; the massless block passes N on, so
    the crank needs M_b = A × N. Virtual work: M_b + F·x_D' = 0."""
    F = 800.0
    text, _ = whitworth()
    text = text.replace("[input]", 'loads = [{ type = "force", link = "5", at = "D", force = [-800.0, 0.0] }]\n[input]')
    engine = engine_of(text)
    phi = np.linspace(0.0, TAU, 361)
    result = mbplanar.kinetostatics(engine, mbplanar.analyse(engine, phi, omega=0.0))
    assert result.success
    th, w, e = whitworth_lever(phi)
    O4 = np.array([0.0, -WH_D])
    C = crank_point(O4, WH_RHO, th + math.pi, w, e)
    D = on_line(C, WH_L, O4, 0.0)
    u = (D.p - C.p) / WH_L
    S = F / u[:, 0]
    A = crank_point((0, 0), WH_R, phi).p
    rho = np.linalg.norm(A - O4, axis=-1)
    ev = (A - O4) / rho[:, None]
    n = cross(C.p - O4, S[:, None] * u) / rho
    N = n[:, None] * perp(ev)
    tag = "7 Whitworth statics"
    close(f"{tag}: balancing moment = F·x_D' (virtual work)", result.balancing["O2"], F * D.v[:, 0], 1e-9, "rel")
    close(f"{tag}: balancing moment = A × N", result.balancing["O2"], cross(A, N), 1e-9, "rel")
    close(f"{tag}: crank pin A on the crank", _force_on(result, "A", "1"), -N, 1e-9, "rel")
    close(f"{tag}: rod pin C on the lever", _force_on(result, "C", "3"), -S[:, None] * u, 1e-9, "rel")
    close(f"{tag}: lever bearing O4 on the lever", _force_on(result, "O4", "3"), S[:, None] * u - N, 1e-9, "rel")
    # the block and the ram carry no moment in their guides (every force on them passes through A, D)
    for joint in ("Ap", "Dp"):
        close(f"{tag}: moment in the guide {joint}", result.reaction(joint).moment, np.zeros_like(S), 1e-9, "rel")
    close(f"{tag}: ram guide on the ram", _force_on(result, "Dp", "5"), np.stack([0 * S, -S * u[:, 1]], -1),
          1e-9, "rel")


def test_oscillating_cylinder_balancing_force_against_a_moment_on_the_crank():
    """Driven by its extension (a prismatic input) with a moment M on the crank, no masses: the actuator
    force F_b along the cylinder (u = (A − C)/s) reaches the crank at A, so M + A × (F_b u) = 0; and by
    virtual work F_b + M·φ' = 0 with φ' = dφ/ds from the cosine rule."""
    M = 12.0
    text, s0 = oscillating_cylinder("Cp", "m")
    text = text.replace("[input]", 'loads = [{ type = "moment", link = "1", moment = 12.0 }]\n[input]')
    engine = engine_of(text)
    ext = np.linspace(OC_D - OC_R - s0 + 2e-3, OC_D + OC_R - s0 - 2e-3, 201)
    motion = mbplanar.analyse(engine, ext, omega=0.0)
    result = mbplanar.kinetostatics(engine, motion)
    assert result.success
    phi, w, _ = crank_from_extension(s0 + ext)
    A = crank_point((0, 0), OC_R, phi).p
    u = (A - np.array([OC_D, 0.0])) / (s0 + ext)[:, None]
    tag = "7 oscillating cylinder statics"
    close(f"{tag}: balancing force = −M·φ' (virtual work)", result.balancing["Cp"], -M * w, 1e-9, "rel")
    close(f"{tag}: balancing force from the crank's balance", result.balancing["Cp"], -M / cross(A, u),
          1e-9, "rel")
    close(f"{tag}: crank pin A on the crank", _force_on(result, "A", "1"), (-M / cross(A, u))[:, None] * u,
          1e-9, "rel")


def test_fourbar_with_masses_and_gravity_by_virtual_power():
    """Masses on all three links, gravity, constant ω: the balancing moment is
    M_b = Σ m_i (ω² a_q,i − g)·v_q,i + J_i ω² ε_q,i ω_q,i, with the centres' analogues from the
    circle construction (a centre is a point carried by its link)."""
    omega, g = 12.0, 9.81
    cm = {"1": lambda A0, B0: tuple(0.5 * np.array(A0)),
          "2": lambda A0, B0: tuple(0.5 * (np.array(A0) + np.array(B0)) + np.array([0.0, 0.03])),
          "3": lambda A0, B0: tuple(0.4 * np.array(B0) + 0.6 * np.array(FB_O4))}
    mass = {"1": (1.5, 0.002), "2": (3.0, 0.04), "3": (2.2, 0.02)}
    text, (A0, B0) = fourbar_table(FB_O4, FB_R, FB_AB, FB_O4B, SIX_PHI0,
                                   masses={n: ({"mass": m, "inertia": J}, cm[n]) for n, (m, J) in mass.items()})
    text = text.replace("[input]", "[gravity]\ng = 9.81\n[input]")
    engine = engine_of(text)
    phi = np.linspace(0.0, TAU, 181)
    motion = mbplanar.analyse(engine, phi, omega=omega, epsilon=0.0)
    result = mbplanar.kinetostatics(engine, motion)
    assert result.success
    n = len(phi)
    A, B = _fourbar_points(phi)
    O2, O4 = fixed((0, 0), n), fixed(FB_O4, n)
    frames = {"1": (O2, A, (0, 0), A0), "2": (A, B, A0, B0), "3": (O4, B, FB_O4, B0)}
    gvec = np.array([0.0, -g])
    expect = np.zeros(n)
    for name, (m, J) in mass.items():
        Pk, Qk, P0, Q0 = frames[name]
        S = rigid(Pk, Qk, P0, Q0, cm[name](A0, B0))
        _, wq, eq = direction(Pk, Qk)
        expect += m * dot(omega ** 2 * S.a - gvec, S.v) + J * omega ** 2 * eq * wq
    close("9 four-bar with masses: balancing moment (virtual power)", result.balancing["O2"], expect, 1e-9, "rel")


def test_cli_forces_on_the_offset_slider_crank(tmp_path, capsys):
    """`mbplanar forces --json` at φ = 1 rad: the balancing moment F·x'(1) and the guide's normal force."""
    F = 500.0
    text, _ = offset_slider_crank(loads=[{"type": "force", "link": "3", "at": "B", "force": [-F, 0.0]}])
    model = tmp_path / "offset_slider_crank_forces.toml"
    model.write_text(text, encoding="utf-8")
    code, out, err = cli(["forces", model, "--at", "1.0", "--json"], capsys)
    assert code == 0, err
    doc = json.loads(out)
    x, x1, _ = slider_closed_form(np.array([1.0]))
    A = crank_point((0, 0), SC_R, np.array([1.0])).p[0]
    u = (np.array([x[0], SC_E]) - A) / SC_L
    tag = "7 slider-crank statics (CLI forces)"
    close(f"{tag}: balancing moment", doc["balancing"]["O"], F * x1[0], 1e-9, "rel")
    guide = doc["reactions"]["Bp"]
    assert guide["on"] == "3" and guide["from"] == "0"
    close(f"{tag}: guide on the slider", [guide["fx"], guide["fy"]], [0.0, -F / u[0] * u[1]], 1e-9, "rel")


# == 8. Published numbers ================================================================================
def test_norton_example_4_1_fourbar_from_a_sketch():
    """R. L. Norton, Design of Machinery, Example 4-1 (position analysis of a four-bar): links a = 40,
    b = 120, c = 80, ground d = 100, θ2 = 40°; printed for the open configuration θ3 = 20.298°,
    θ4 = 57.325°. Here the table is a rough sketch (mm, B drawn at (143, 67)) made exact by the lengths."""
    text = table("norton_4_1", [{"name": "2", "length": 40.0}, {"name": "3", "length": 120.0},
                                {"name": "4", "length": 80.0, "angle": ["O4", "B"]}],
                 [R("O2", "0", "2", (0, 0)), R("A", "2", "3", (31, 26)), R("B", "3", "4", (143, 67)),
                  R("O4", "0", "4", (100, 0))], {"joint": "O2", "drawn_at": 40.0})
    text = "length_unit = \"mm\"\n" + text
    engine = engine_of(text)
    motion = mbplanar.analyse(engine, [math.radians(40.0)])
    th3, th4 = (math.degrees(float(motion.angle[0, motion.link(n)])) for n in ("3", "4"))
    tag = "8 Norton Ex. 4-1 (printed, 3 decimals)"
    close(f"{tag}: theta3 (deg)", th3, 20.298, 5e-4)
    close(f"{tag}: theta4 (deg)", th4, 57.325, 5e-4)
    # and to the engine's precision against the circle construction, over a full turn
    fourbar_turn_matches_circles("8 Norton Ex. 4-1", engine, (0.1, 0.0), 0.040, 0.120, 0.080, "4")


def fourbar_turn_matches_circles(tag, engine, pivot, crank, coupler, rocker, rocker_link):
    """Over a full turn of the crank (pivot at the origin), B and the rocker's direction against the
    circle construction of the open assembly."""
    phi = np.linspace(0.0, TAU, 361)
    motion = mbplanar.analyse(engine, phi)
    A = crank_point((0, 0), crank, phi)
    B = dyad(A, fixed(pivot, len(phi)), coupler, rocker, +1)
    compare_points(tag, motion, {"B": B})
    compare_link(tag, motion, rocker_link, direction(fixed(pivot, len(phi)), B))


def test_chebyshev_straight_line_linkage():
    """Chebyshev's linkage (ground 2 : crossed rockers 2.5 : coupler 1; here O1 = (0, 0), O2 = (0.4, 0),
    rockers 0.5, coupler 0.2): the coupler's midpoint P is exactly on the line y = 0.4 in the middle
    position (rocker O1A at atan(4/3), P = (0.2, 0.4)) and at both ends of its straight stretch
    (O1A vertical: P = (0, 0.4); O1A at atan(3/4): A = (0.4, 0.3), B = (0.4, 0.5), P = (0.4, 0.4)).
    Driven at O1, that last end is a dead point (O2, A, B in line: |O2A| = 0.5 − 0.2), and the other
    limit is the stretched one, |O2A| = 0.7: cos ψ = (0.41 − |O2A|²)/0.4 gives ψ ∈ [atan(3/4), acos(−0.2)]."""
    A0, B0 = (0.3, 0.4), (0.1, 0.4)                     # the middle position, rockers crossed
    joints = [R("O1", "0", "1", (0, 0)), R("A", "1", "2", A0), R("B", "2", "3", B0), R("O2", "0", "3", (0.4, 0))]
    text = table("chebyshev", links("1", "2", "3", l1=["O1", "A"]), joints, {"joint": "O1", "unit": "deg"},
                 points=[{"name": "P", "link": "2", "along": ["A", "B"], "fraction": 0.5}])
    engine = engine_of(text)
    exact = {math.degrees(math.atan2(4, 3)): (0.2, 0.4), 90.0: (0.0, 0.4)}
    motion = mbplanar.analyse(engine, np.radians(list(exact)))
    assert motion.success
    close("8 Chebyshev: P on y = 0.4 (middle, end)", motion.xy[:, motion.point("P")],
          np.array(list(exact.values())),
          1e-12)
    report = mbplanar.check(engine)
    lo, hi = math.degrees(math.atan2(3, 4)), math.degrees(math.acos(-0.2))
    close("8 Chebyshev: dead points driven at O1 (deg)", sorted(lim.phi for lim in report.limits), [lo, hi],
          1e-10)
    # next to that dead point (1e-7° inside) P is still where the circles put it, near (0.4, 0.4)
    psi = np.radians([lo + 1e-7])
    near = mbplanar.analyse(engine, psi)
    A = crank_point((0, 0), 0.5, psi).p
    B = dyad(Kin(A, 0 * A, 0 * A), fixed((0.4, 0.0), 1), 0.2, 0.5, -1).p   # B to the right of A→O2
    close("8 Chebyshev: P 1e-7° from the dead point", near.xy[:, near.point("P")], 0.5 * (A + B), 1e-9)
    assert np.abs(0.5 * (A + B) - 0.4).max() < 1e-4
    # the whole stretch against the circles; P deviates from y = 0.4 by the linkage's known small error
    psi = np.radians(np.linspace(lo + 0.01, 90.0, 200))
    motion = mbplanar.analyse(engine, psi)
    A = crank_point((0, 0), 0.5, psi)
    B = dyad(A, fixed((0.4, 0.0), len(psi)), 0.2, 0.5, -1)   # B to the right of A→O2
    compare_points("8 Chebyshev", motion, {"P": Kin(0.5 * (A.p + B.p), 0.5 * (A.v + B.v), 0.5 * (A.a + B.a))})
    assert np.abs(motion.xy[:, motion.point("P"), 1] - 0.4).max() < 0.01


# == 9. More four-bar and slider-crank classics: Grashof's cases, an offset too large, a relative input ======


def test_drag_link_turns_everything_fully():
    """Ground shortest (d = 0.1 < a = 0.3, b = 0.35, c = 0.3): a double crank; crank, coupler and rocker all
    turn, and the circle construction holds over the whole turn."""
    text, _ = fourbar_table((0.1, 0.0), 0.3, 0.35, 0.3, 0.5)
    engine = engine_of(text)
    report = mbplanar.check(engine)
    assert report.full_turn and report.grashof.kind == "double crank" and report.grashof.input_turns
    assert all(e.turns for e in report.extremes)
    fourbar_turn_matches_circles("9 drag link", engine, (0.1, 0.0), 0.3, 0.35, 0.3, "3")


def test_triple_rocker_stops_where_coupler_and_rocker_stretch():
    """Non-Grashof a = 0.35, b = 0.3, c = 0.22, d = 0.45 (s + l = 0.67 > p + q = 0.65): the input rocks
    between ±φ_m where |AO4| = b + c, cos φ_m = (a² + d² − (b + c)²)/(2ad)."""
    a, b, c, d = 0.35, 0.30, 0.22, 0.45
    engine = engine_of(fourbar_table((d, 0.0), a, b, c, 1.2)[0])
    report = mbplanar.check(engine)
    assert not report.full_turn and report.grashof.kind.startswith("non-Grashof")
    phi_m = math.degrees(math.acos((a * a + d * d - (b + c) ** 2) / (2 * a * d)))
    close("9 triple rocker: limits (deg)", sorted(lim.phi for lim in report.limits), [-phi_m, phi_m], 1e-10)
    assert all("stretched at B" in lim.kind for lim in report.limits)


def test_slider_crank_with_an_offset_too_large_to_turn():
    """r + e > l (r = 0.1, l = 0.25, e = 0.2): the rod stands square to the guide, r sin φ − e = −l, at
    sin φ = (e − l)/r = −1/2: the crank rocks between −30° and 210°."""
    r, l, e = 0.10, 0.25, 0.20
    phi0 = math.radians(60.0)
    A = (r * math.cos(phi0), r * math.sin(phi0))
    B = (A[0] + math.sqrt(l * l - (A[1] - e) ** 2), e)
    text = table("big_offset", links("1", "2", "3"), [R("O", "0", "1", (0, 0)), R("A", "1", "2", A),
                                                      R("B", "2", "3", B), P("Bp", "0", "3", B, 0.0)],
                 {"joint": "O", "unit": "deg"})
    engine = engine_of(text)
    report = mbplanar.check(engine)
    assert not report.full_turn
    close("9 large offset slider-crank: limits (deg)", sorted(lim.phi for lim in report.limits), [-30.0, 210.0],
          1e-10)
    phi = np.radians(np.linspace(-29.0, 209.0, 239))
    x, x1, x2 = slider_closed_form(phi, r, l, e)
    motion = mbplanar.analyse(engine, phi)
    assert motion.success
    k = motion.joint("Bp")
    close("9 large offset slider-crank: slider", motion.value[:, k], x - B[0], 1e-9)
    close("9 large offset slider-crank: slider velocity analogue", motion.rate_q[:, k], x1, 1e-9, "rel")
    close("9 large offset slider-crank: slider acceleration analogue", motion.accel_q[:, k], x2, 1e-9, "rel")


def test_fourbar_driven_at_the_coupler_joint():
    """An input between two moving links: the relative angle γ = θ_AB − θ_OA at A (a motor on the crank
    pin). The crank-driven construction gives γ(φ) = θ_AB(φ) − φ, γ_φ = θ_AB' − 1, γ_φφ = θ_AB''; the
    engine's crank angle fed back must give the requested γ, with φ_γ = 1/γ_φ, φ_γγ = −γ_φφ/γ_φ³."""
    text, _ = fourbar_table(FB_O4, FB_R, FB_AB, FB_O4B, SIX_PHI0)
    engine = engine_of(text.split("[input]")[0] + '[input]\njoint = "A"\nunit = "rad"\n')
    (lo, hi), _, full = _reach_of(engine)
    gamma = np.linspace(lo, hi, 203)[1:-1] if not full else lo + np.linspace(0.0, TAU, 201)
    motion = mbplanar.analyse(engine, gamma)
    assert motion.success
    phi = motion.angle[:, motion.link("1")]
    A, B = _fourbar_points(phi)
    th, w, e = direction(A, B)
    tag = "9 four-bar driven at A (relative angle)"
    close_angle(f"{tag}: γ of the construction", th - phi, gamma, 1e-9)
    close(f"{tag}: B position", motion.xy[:, motion.point("B")], B.p, 1e-9)
    k = motion.link("1")
    close(f"{tag}: crank rate analogue", motion.wq[:, k], 1 / (w - 1), 1e-9, "rel")
    close(f"{tag}: crank acceleration analogue", motion.eq[:, k], -e / (w - 1) ** 3, 1e-9, "rel")


# == Every mechanism: verdicts, limits of an output-driven variant, clean errors ===========================


def _slider_crank_stroke():
    _, B0 = offset_slider_crank()
    return [math.sqrt((SC_L - SC_R) ** 2 - SC_E ** 2) - B0[0], math.sqrt((SC_L + SC_R) ** 2 - SC_E ** 2) - B0[0]]


def _whitworth_ram_ends():
    _, D0 = whitworth()
    return [WH_L - WH_RHO - D0[0], WH_L + WH_RHO - D0[0]]


def _cylinder_ends():
    _, s0 = oscillating_cylinder()
    return [OC_D - OC_R - s0, OC_D + OC_R - s0]


def _wedge_ends():
    _, (B0, _, _) = double_slider()
    tan = math.tan(math.radians(DS_BETA))
    return sorted(-(x - B0[0]) * tan for x in (DS_L - DS_R, DS_L + DS_R))


def _watt_output_ends():
    """Driven at O6, the Watt II chain stops where its crank and coupler line up: rocker 3 at the
    extremes the cosine rule gives (|O2B| = AB ± O2A), mapped through the second four-bar."""
    ends = []
    for ob in (FB_AB - FB_R, FB_AB + FB_R):
        B = dyad(fixed((0, 0), 1), fixed(FB_O4, 1), ob, FB_O4B, +1)
        th = direction(fixed(FB_O4, 1), B)[0]
        C = crank_point(FB_O4, W_O4C, th - math.radians(100.0))
        D = dyad(C, fixed(W_O6, 1), W_CD, W_O6D, -1)
        ends.append(math.degrees(float(direction(fixed(W_O6, 1), D)[0][0])))
    return sorted(ends)


def _stephenson_output_ends():
    """Driven at O6, the Stephenson III chain stops where the output angle ψ(φ) of the crank-driven
    construction is stationary, ψ_φ = 0: the first sign changes of ψ_φ on either side of the drawn crank
    angle, refined by bisection."""
    _, (A0, B0, Q0) = stephenson_iii()

    def rate(phi):
        E = stephenson_iii_solution(np.atleast_1d(phi), A0, B0, Q0)[3]
        return direction(fixed(S_O6, len(np.atleast_1d(phi))), E)

    ends = []
    for way in (+1, -1):
        grid = SIX_PHI0 + way * np.linspace(0.0, TAU, 3601)
        w = rate(grid)[1]
        k = int(np.flatnonzero(np.sign(w[1:]) != np.sign(w[0]))[0])
        a, b = grid[k], grid[k + 1]
        for _ in range(60):
            m = 0.5 * (a + b)
            a, b = (m, b) if np.sign(rate(m)[1][0]) == np.sign(rate(a)[1][0]) else (a, m)
        ends.append(math.degrees(float(rate(0.5 * (a + b))[0][0])) % 360.0)   # as drawn: 147° … 189°
    return sorted(ends)


# name: (table, turns fully as drawn, (joint, unit) of a limited driver or None, its closed-form range or
# None, (link row, replacement, drawn_at) that cannot be assembled or None)
CLASSICS = {
    "offset_slider_crank": (lambda: offset_slider_crank()[0], True, ("Bp", "m"), _slider_crank_stroke,
                            ('{ name = "2" }', '{ name = "2", length = 0.01 }', math.pi / 2)),
    "whitworth": (lambda: whitworth()[0], True, ("Dp", "m"), _whitworth_ram_ends,
                  ('{ name = "4" }', '{ name = "4", length = 0.01 }', WH_PHI0)),
    "oscillating_cylinder": (lambda: oscillating_cylinder()[0], True, ("Cp", "m"), _cylinder_ends, None),
    "watt_ii": (lambda: watt_ii()[0], True, ("O6", "deg"), _watt_output_ends,
                ('{ name = "2" }', '{ name = "2", length = 10.0 }', None)),
    "stephenson_iii": (lambda: stephenson_iii()[0], True, ("O6", "deg"), _stephenson_output_ends,
                       ('{ name = "4" }', '{ name = "4", length = 10.0 }', None)),
    "double_slider": (lambda: double_slider()[0], True, ("V", "m"), _wedge_ends,
                      ('{ name = "4", angle', '{ name = "4", length = 0.01, angle', None)),
    "rocker_driven": (rocker_driven_fourbar, False, ("C", "deg"),
                      lambda: [math.degrees(x) for x in rocker_dead_points()],
                      ('{ name = "2" }', '{ name = "2", length = 10.0 }', None)),
}


@pytest.mark.parametrize("name", list(CLASSICS))
def test_verdicts_limits_and_clean_errors(name, tmp_path, capsys):
    """`mbplanar check` gives the right verdict; driven at a joint whose range ends, the limits sit where
    the closed form puts them, a request past them is a clean one-line error (exit 1) and no NaN; a table
    whose dimensions cannot be assembled is a clean error too. (Walking to a limit costs about a second,
    so each limited model is walked once by the API and once by the command line.)"""
    make, turns, (joint, unit), ends, impossible = CLASSICS[name]
    text = make()
    model = tmp_path / f"{name}.toml"
    model.write_text(text, encoding="utf-8")
    code, out, err = cli(["check", model], capsys)
    assert code == 0 and not err
    assert ("the input turns fully" in out) == turns and ("does NOT turn fully" in out) == (not turns), out

    # driven at a joint whose range ends: the located limits, the rows and rates up to them are finite
    limited = tmp_path / f"{name}_limited.toml"
    limited.write_text(redriven(text, joint, unit), encoding="utf-8")
    engine = engine_of(limited.read_text(encoding="utf-8"))
    report = mbplanar.check(engine)
    assert not report.full_turn and len(report.limits) == 2
    lo, hi = report.range
    if ends is not None:
        tol = 1e-10 if unit == "deg" else 1e-13   # degrees, metres
        close(f"limits of {name} driven at {joint} ({unit})", [lo, hi], ends(), tol)
    scale = math.pi / 180 if unit == "deg" else 1.0
    span = hi - lo
    past = mbplanar.analyse(engine, scale * np.linspace(lo - span, hi + span, 61))
    assert not past.success and len(past.limits) == 2 and len(past.phi) > 0
    for arr in (past.xy, past.vq, past.aq, past.angle, past.wq, past.eq, past.value, past.rate_q, past.accel_q):
        assert np.all(np.isfinite(arr))
    # the command line: a position inside, and one past the upper limit
    code, out, err = cli(["solve", limited, "--at", repr(0.5 * (lo + hi)), "--json"], capsys)
    assert code == 0, err
    doc = json.loads(out)
    assert all(math.isfinite(v) for p in doc["points"].values() for v in p.values())
    code, out, err = cli(["solve", limited, "--at", repr(hi + 0.25 * span)], capsys)
    assert_clean_failure(code, err)
    assert "cannot reach" in err and "motion limit" in err and str(limited) in err, err

    # dimensions that cannot be assembled at the drawn input: a clean error from the API and the CLI
    if impossible is None:
        return
    old, new, drawn_at = impossible
    assert old in text
    bad = text.replace(old, new, 1)
    if drawn_at is not None:
        bad = bad.rstrip("\n") + f"\ndrawn_at = {drawn_at!r}\n"
    with pytest.raises((mbplanar.ModelError, mbplanar.MotionError)):
        engine_of(bad)
    broken = tmp_path / f"{name}_broken.toml"
    broken.write_text(bad, encoding="utf-8")
    for command in (["check", broken], ["solve", broken, "--at", "0.1"]):
        code, out, err = cli(command, capsys)
        assert not out
        assert_clean_failure(code, err, (1, 2))
        assert "cannot be assembled" in err or "misses" in err, err


# == Positions a hair inside a located limit (once dropped: the guess landed on the mirror branch) =====
def test_rows_inside_a_located_limit_are_solved():
    """Driven at the rocker (and a non-Grashof triple rocker), positions 3e-10 … 1e-6 rad inside the lower
    limit `check` located are all on the branch; every one should be solved (or a limit reported)."""
    offsets = np.logspace(-9.5, -6, 36)
    failures = []
    for name, text in (("rocker-driven", rocker_driven_fourbar()),
                       ("triple rocker", fourbar_table((0.45, 0.0), 0.35, 0.30, 0.22, 1.2)[0])):
        engine = engine_of(text)
        lo = math.radians(mbplanar.check(engine).range[0])
        motion = mbplanar.analyse(engine, lo + offsets)
        if not motion.success and not motion.limits:
            failures.append(f"{name}: {len(offsets) - len(motion.phi)} of {len(offsets)} rows dropped, no limit")
    assert not failures, failures


def test_check_extremes_of_the_rocker_driven_crank_at_its_dead_points():
    """At the dead points O, A, B are in line: the crank points along OB (stretched, |OB| = l + r) or
    against it (folded, |OB| = l − r). The crank angle moves like a square root of the input there, so a
    sample next to the limit would be off by ~0.005°; `check` takes it from the configuration solved at
    the limit itself."""
    report = mbplanar.check(engine_of(rocker_driven_fourbar()))
    crank = next(e for e in report.extremes if e.name == "1")
    want = []
    for psi, sign in zip(rocker_dead_points(), (+1, -1)):
        B = np.array([CR_D + CR_C * math.cos(psi), CR_C * math.sin(psi)])
        want.append(math.degrees(math.atan2(sign * B[1], sign * B[0])) % 360.0)
    got = sorted(math.degrees(x) % 360.0 for x in (crank.minimum, crank.maximum))
    close("6 rocker-driven four-bar: crank extremes from check (deg)", got, sorted(want), 1e-9)
