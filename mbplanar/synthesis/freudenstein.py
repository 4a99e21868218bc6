"""Function generation with a four-bar by Freudenstein's equation.

Ground O→C of length d on the x axis, crank a at angle φ from O, rocker c at angle ψ from C, coupler b:

    K1·cos ψ − K2·cos φ + K3 = cos(φ − ψ),   K1 = d/a, K2 = d/c, K3 = (a² − b² + c² + d²)/(2ac).

It is linear in K: three (φ, ψ) pairs give K exactly, more pairs by least squares. A function y = f(x)
on [x0, x1] is mapped linearly onto the crank's range [φ0, φ1] and the rocker's [ψ0, ψ1]; precision
points at Chebyshev spacing keep the structural error (achieved minus wanted ψ over the range) small.
"""

from __future__ import annotations

import ast
import math
import operator
import time
from dataclasses import dataclass

import numpy as np

from ..engine import Engine
from ..errors import ModelError
from ..kinematics import analyse
from ._models import fourbar_toml, read_design
from .defects import Defects, check_defects
from .guiding import chebyshev_nodes

__all__ = ["freudenstein_coefficients", "fourbar_lengths", "FunctionTask", "FunctionResult",
           "synthesise_function", "synthesise_angle_pairs", "evaluate_expression"]


def freudenstein_coefficients(phi, psi) -> tuple[np.ndarray, np.ndarray]:
    """K = (K1, K2, K3) from angle pairs (rad, (n,) each; exact for n = 3, least squares for more)
    and the equation's residuals (n,)."""
    phi, psi = np.asarray(phi, float), np.asarray(psi, float)
    if phi.shape != psi.shape or phi.ndim != 1:
        raise ModelError("the input and output angles must be two lists of the same length")
    if len(phi) < 3:
        raise ModelError(f"function generation needs at least 3 precision points, got {len(phi)}")
    m = np.column_stack([np.cos(psi), -np.cos(phi), np.ones_like(phi)])
    rhs = np.cos(phi - psi)
    if np.linalg.matrix_rank(m) < 3:
        raise ModelError("the precision points do not determine a four-bar (repeated or degenerate angles)")
    k, *_ = np.linalg.lstsq(m, rhs, rcond=None)
    return k, m @ k - rhs


def fourbar_lengths(k, ground: float = 1.0) -> tuple[float, float, float, float]:
    """Signed crank a, coupler b, signed rocker c and ground d of K (a < 0 or c < 0: that link points
    the opposite way to φ or ψ)."""
    k1, k2, k3 = (float(v) for v in k)
    if abs(k1) < 1e-12 or abs(k2) < 1e-12:
        raise ModelError("no feasible four-bar: K1 or K2 is zero (a crank or rocker of infinite length)")
    d = float(ground)
    a, c = d / k1, d / k2
    b2 = a * a + c * c + d * d - 2 * a * c * k3
    if not b2 > 0:
        raise ModelError("no feasible four-bar: the coupler's squared length a² + c² + d² − 2ac·K3 is not positive")
    return a, math.sqrt(b2), c, d


_OPS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
        ast.Pow: operator.pow, ast.USub: operator.neg, ast.UAdd: operator.pos}
_FUNCS = {name: getattr(np, name) for name in ("sin", "cos", "tan", "exp", "log", "log10", "log2", "sqrt",
                                               "arcsin", "arccos", "arctan", "sinh", "cosh", "tanh", "abs")}
_CONSTS = {"pi": math.pi, "e": math.e}


def evaluate_expression(text: str, x):
    """y = f(x) of a formula in x: numbers, + − * / **, pi, e and numpy's sin, cos, tan, exp, log,
    log10, log2, sqrt, arcsin, arccos, arctan, sinh, cosh, tanh, abs. Nothing else is evaluated."""
    try:
        tree = ast.parse(str(text), mode="eval")
    except SyntaxError:
        raise ModelError(f"function {text!r}: not a formula in x") from None

    def ev(node):
        if isinstance(node, ast.Expression):
            return ev(node.body)
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and not isinstance(node.value, bool):
            return float(node.value)
        if isinstance(node, ast.Name):
            if node.id == "x":
                return np.asarray(x, float)
            if node.id in _CONSTS:
                return _CONSTS[node.id]
        if isinstance(node, ast.BinOp) and type(node.op) in _OPS:
            return _OPS[type(node.op)](ev(node.left), ev(node.right))
        if isinstance(node, ast.UnaryOp) and type(node.op) in _OPS:
            return _OPS[type(node.op)](ev(node.operand))
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in _FUNCS
                and len(node.args) == 1 and not node.keywords):
            return _FUNCS[node.func.id](ev(node.args[0]))
        raise ModelError(f"function {text!r}: '{ast.unparse(node)}' is not allowed (a formula in x with "
                         f"+ - * / **, pi, e and {', '.join(sorted(_FUNCS))})")
    with np.errstate(all="ignore"):
        y = np.asarray(ev(tree), float) * np.ones_like(np.asarray(x, float))
    if not np.all(np.isfinite(y)):
        raise ModelError(f"function {text!r} is not finite over the range")
    return y


@dataclass(frozen=True)
class FunctionTask:
    """y = `expression`(x) on [x0, x1], mapped onto the crank's φ0 → φ1 and the rocker's ψ0 → ψ1
    (degrees): φ = φ0 + (x − x0)/(x1 − x0)·(φ1 − φ0), ψ = ψ0 + (y − y(x0))/(y(x1) − y(x0))·(ψ1 − ψ0);
    `points` precision points at `spacing` ("chebyshev" or "uniform") over [x0, x1]."""

    expression: str
    x_range: tuple[float, float]
    phi_deg: tuple[float, float]
    psi_deg: tuple[float, float]
    points: int = 3
    spacing: str = "chebyshev"

    def y(self, x):
        return evaluate_expression(self.expression, x)

    def phi(self, x):
        x0, x1 = self.x_range
        return np.radians(self.phi_deg[0] + (np.asarray(x) - x0) / (x1 - x0) * (self.phi_deg[1] - self.phi_deg[0]))

    def psi_of_y(self, y):
        y0, y1 = self.y(np.array(self.x_range, float))
        return np.radians(self.psi_deg[0] + (np.asarray(y) - y0) / (y1 - y0) * (self.psi_deg[1] - self.psi_deg[0]))

    def precision_x(self) -> np.ndarray:
        x0, x1 = self.x_range
        if self.spacing == "chebyshev":
            return chebyshev_nodes(self.points, x0, x1)
        if self.spacing == "uniform":
            return np.linspace(x0, x1, self.points)
        raise ModelError(f"spacing must be 'chebyshev' or 'uniform', got {self.spacing!r}")

    def validate(self):
        x0, x1 = self.x_range
        if not x1 != x0 or self.phi_deg[0] == self.phi_deg[1] or self.psi_deg[0] == self.psi_deg[1]:
            raise ModelError("the x range and the input and output angle ranges must not be empty")
        y0, y1 = self.y(np.array(self.x_range, float))
        if y0 == y1:
            raise ModelError(f"function {self.expression!r} takes the same value at both ends of the range")


@dataclass(frozen=True)
class FunctionResult:
    """A defect-free function generator and its errors from mbplanar's analysis of `toml`.

    `design`: a, b, c, d (lengths), K1..K3 and the links' directions; `phi`, `psi_target` (n,) the
    precision points (rad), `point_errors_deg` (n,) achieved − wanted ψ there; `range_phi`,
    `range_error_deg` (P,) the structural error over the input range (also in the function's units,
    `range_error_y`, when a function was given)."""

    design: dict
    toml: str
    mechanism: object
    phi: np.ndarray
    psi_target: np.ndarray
    point_errors_deg: np.ndarray
    range_phi: np.ndarray
    range_error_deg: np.ndarray
    range_error_y: np.ndarray | None
    defects: Defects
    seconds: float


def _wrap(x):
    return (np.asarray(x) + math.pi) % (2 * math.pi) - math.pi


def _fourbar_text(a, b, c, d, phi0, psi0, sense):
    """The four-bar drawn at (φ0, ψ0) of the Freudenstein geometry; input zero so that the model's φ is
    Freudenstein's φ (a crank with a < 0 points at φ + 180°)."""
    a0, b0 = np.zeros(2), np.array([d, 0.0])
    a1 = a * np.array([math.cos(phi0), math.sin(phi0)])
    b1 = b0 + c * np.array([math.cos(psi0), math.sin(psi0)])
    zero = 180.0 if a < 0 else 0.0
    return fourbar_toml(a0, a1, b1, b0, {}, name="function_generator", title="Function generator (Freudenstein)",
                        zero_deg=zero, sense=sense,
                        comment=f"Synthesised by mbplanar synth function: a = {a!r}, b = {b!r}, c = {c!r}, d = {d!r}.")


def _assembled_rocker(a_pos, b0, b, c, wanted) -> np.ndarray:
    """Rocker joint B (n, 2) closing the loop at each crank tip `a_pos` (n, 2): of the two assemblies,
    the one nearer `wanted` (the synthesis's B; the same point when the pair is met exactly)."""
    delta = b0 - a_pos
    dist = np.hypot(delta[:, 0], delta[:, 1])
    along = (b * b - c * c + dist * dist) / (2 * dist)
    h2 = b * b - along * along
    if np.any(h2 < -1e-12 * b * b):
        raise ModelError("no feasible design: the four-bar cannot be assembled at a precision point")
    h = np.sqrt(np.maximum(h2, 0.0))
    unit = delta / dist[:, None]
    normal = np.column_stack([-unit[:, 1], unit[:, 0]])
    base = a_pos + along[:, None] * unit
    one, two = base + h[:, None] * normal, base - h[:, None] * normal
    near = np.hypot(*(one - wanted).T) <= np.hypot(*(two - wanted).T)
    return np.where(near[:, None], one, two)


def synthesise_angle_pairs(phi, psi, ground: float = 1.0, task: FunctionTask | None = None,
                           steps: int = 720) -> FunctionResult:
    """A four-bar through the angle pairs (φ_i, ψ_i) (rad, in the order the crank meets them), checked
    for defects and evaluated by mbplanar over [φ_first, φ_last]."""
    t0 = time.perf_counter()
    phi, psi = np.asarray(phi, float), np.asarray(psi, float)
    k, _ = freudenstein_coefficients(phi, psi)
    a, b, c, d = fourbar_lengths(k, ground)
    sense = 1 if phi[-1] >= phi[0] else -1
    apos = a * np.column_stack([np.cos(phi), np.sin(phi)])
    bpos = _assembled_rocker(apos, np.array([d, 0.0]), b, abs(c),
                             np.array([d, 0.0]) + c * np.column_stack([np.cos(psi), np.sin(psi)]))
    # drawn at the first point, the rocker assembled as the synthesis meant (ψ1 itself when exact)
    psi_drawn = math.atan2(*(bpos[0] - [d, 0.0])[::-1]) + (math.pi if c < 0 else 0.0)
    text = _fourbar_text(a, b, c, d, phi[0], psi_drawn, sense)
    mech = read_design(text)
    engine = Engine(mech)
    grid = np.linspace(phi[0], phi[-1], steps + 1) if task is None else \
        task.phi(np.linspace(*task.x_range, steps + 1))
    defects = check_defects(engine, sense * phi, {"A": apos, "B": bpos}, periodic=False,
                            travel=sense * grid[[0, -1]], tol=1e-7 * (abs(a) + b + abs(c) + d))
    if not defects.ok:
        raise ModelError(f"no feasible design: the four-bar through the precision points has a defect: "
                         f"{defects.describe()}")
    rocker_offset = math.pi if c < 0 else 0.0
    shift = defects.node_phi[0] - sense * phi[0]          # whole turns to the engine's drawn input
    m_pts = analyse(engine, shift + sense * phi)
    got = m_pts.value[:, m_pts.joint("B0")] - rocker_offset
    point_err = np.degrees(_wrap(got - psi))
    m = analyse(engine, shift + sense * grid)
    if len(m.phi) != len(grid):
        raise ModelError("no feasible design: the four-bar meets a motion limit inside the input range")
    achieved = m.value[:, m.joint("B0")] - rocker_offset
    err_y = None
    if task is not None:
        xs = np.linspace(*task.x_range, steps + 1)
        wanted = task.psi_of_y(task.y(xs))
        y0, y1 = task.y(np.array(task.x_range, float))
        err_y = _wrap(achieved - wanted) / math.radians(task.psi_deg[1] - task.psi_deg[0]) * (y1 - y0)
    else:
        wanted = np.interp(grid, phi, psi) if np.all(np.diff(sense * phi) > 0) else np.full_like(grid, np.nan)
    design = {"a": abs(a), "b": b, "c": abs(c), "d": d, "K": [float(v) for v in k],
              "crank_reversed": bool(a < 0), "rocker_reversed": bool(c < 0), "sense": sense}
    return FunctionResult(design, text, mech, phi, psi, point_err, grid, np.degrees(_wrap(achieved - wanted)),
                          err_y, defects, time.perf_counter() - t0)


def synthesise_function(task: FunctionTask, ground: float = 1.0, steps: int = 720) -> FunctionResult:
    """The four-bar generating `task`'s function: its precision points exactly (3) or by least squares
    (more), the structural error over the whole range from mbplanar's analysis."""
    task.validate()
    x = task.precision_x()
    return synthesise_angle_pairs(task.phi(x), task.psi_of_y(task.y(x)), ground, task, steps)
