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
    """Freudenstein's coefficients K = (K1, K2, K3) of the four-bar through angle pairs (φ_i, ψ_i).

    K1·cos ψ − K2·cos φ + K3 = cos(φ − ψ) is linear in K: 3 pairs give K exactly, more pairs by least
    squares (K1 = d/a, K2 = d/c, K3 = (a² − b² + c² + d²)/(2ac), ground on the x axis).

    Parameters
    ----------
    phi, psi : (n,) array_like
        Crank angle φ at O and rocker angle ψ at C of each pair, rad (n ≥ 3).

    Returns
    -------
    k : (3,) ndarray
        K1, K2, K3.
    residuals : (n,) ndarray
        The equation's residual at each pair (zero for n = 3).

    Raises
    ------
    ModelError
        Lists of different lengths or not one-dimensional, fewer than 3 pairs, or pairs that do not
        determine K (repeated or degenerate angles).

    Examples
    --------
    The angle pairs of models/fourbar.toml (OA 0.1, AB 0.3, BC 0.25, OC 0.3 m) give back its K:

    >>> import numpy as np, mbplanar
    >>> from mbplanar.synthesis import freudenstein_coefficients
    >>> m = mbplanar.analyse(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), np.radians([40, 80, 120]))
    >>> b = m.xy[:, m.point("B")]
    >>> k, residuals = freudenstein_coefficients(m.phi[:, 0], np.arctan2(b[:, 1], b[:, 0] - 0.3))
    >>> k.round(9).tolist()                  # d/a, d/c, (a² − b² + c² + d²)/(2ac)
    [3.0, 1.2, 1.45]
    """
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
    """A function y = f(x) to generate with a four-bar: the crank turns with x, the rocker with y.

    x on [x0, x1] maps linearly onto the crank's φ0 → φ1 and y onto the rocker's ψ0 → ψ1:
    φ = φ0 + (x − x0)/(x1 − x0)·(φ1 − φ0), ψ = ψ0 + (y − y(x0))/(y(x1) − y(x0))·(ψ1 − ψ0).

    Attributes
    ----------
    expression : str
        The function, a formula in x (numbers, ``+ - * / **``, pi, e and sin, cos, tan, exp, log, log10,
        log2, sqrt, arcsin, arccos, arctan, sinh, cosh, tanh, abs).
    x_range : (2,) tuple of float
        [x0, x1].
    phi_deg, psi_deg : (2,) tuple of float
        The crank's and the rocker's ranges, degrees.
    points : int
        Precision points (3: exact; more: least squares).
    spacing : {"chebyshev", "uniform"}
        Where the precision points lie on [x0, x1].

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.synthesis import FunctionTask
    >>> task = FunctionTask("1/x", (1.0, 2.0), phi_deg=(30.0, 120.0), psi_deg=(60.0, 150.0))
    >>> x = task.precision_x()
    >>> x.round(4).tolist()                                  # Chebyshev points on [1, 2]
    [1.067, 1.5, 1.933]
    >>> np.degrees(task.psi_of_y(task.y(x))).round(3).tolist()   # the rocker angles they ask for
    [71.301, 120.0, 146.881]
    """

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
    """A defect-free function generator and its errors, from mbplanar's analysis of the model `toml`.

    Attributes
    ----------
    design : dict
        a, b, c, d (crank, coupler, rocker, ground lengths; d is the `ground` asked for), K (K1, K2,
        K3), crank_reversed / rocker_reversed (that link points the opposite way to φ or ψ) and sense
        (+1: φ increases from the first precision point to the last).
    toml : str
        The model's TOML text (crank joint "A0", rocker joint "B0").
    mechanism : Mechanism
        The model read back from `toml`.
    phi, psi_target : (n,) ndarray
        The precision points, rad.
    point_errors_deg : (n,) ndarray
        Achieved − wanted ψ at the precision points, degrees (zero to rounding for 3 points).
    range_phi : (P,) ndarray
        Crank angles over the input range, rad.
    range_error_deg : (P,) ndarray
        The structural error there (achieved − wanted ψ), degrees.
    range_error_y : (P,) ndarray or None
        The same in the function's units; None for bare angle pairs.
    defects : Defects
        mbplanar's check of the design.
    seconds : float
        Wall time.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.synthesis import FunctionTask, synthesise_function
    >>> r = synthesise_function(FunctionTask("1/x", (1.0, 2.0), (30.0, 120.0), (60.0, 150.0)), steps=90)
    >>> r.range_phi.shape, round(float(np.abs(r.range_error_deg).max()), 4)    # largest error, degrees
    ((91,), 0.1061)
    """

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
    """A four-bar through the angle pairs (φ_i, ψ_i), checked for defects and analysed by mbplanar.

    Parameters
    ----------
    phi, psi : (n,) array_like
        Crank and rocker angles of the precision points, rad, in the order the crank meets them
        (n ≥ 3; more than 3 by least squares).
    ground : float
        Ground length d, m (the synthesis fixes the lengths' ratios only).
    task : FunctionTask, optional
        The function the pairs come from: the error is then also reported in its units and over its
        whole x range.
    steps : int
        Intervals of the input range analysed for the structural error.

    Returns
    -------
    FunctionResult
        The design, its model text and the errors from mbplanar's analysis.

    Raises
    ------
    ModelError
        Fewer than 3 pairs or degenerate ones, K giving no four-bar (a link of infinite or imaginary
        length), a design that cannot be assembled at a precision point, or one with a circuit, branch
        or order defect or a motion limit inside the range.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.synthesis import synthesise_angle_pairs
    >>> r = synthesise_angle_pairs(np.radians([30, 75, 120]), np.radians([60, 100, 150]), steps=90)
    >>> r.defects.ok, round(r.design["a"], 4), round(r.design["b"], 4), round(r.design["c"], 4)
    (True, 1.6494, 1.7136, 1.6494)
    >>> bool(np.abs(r.point_errors_deg).max() < 1e-9)        # met exactly
    True
    """
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
    """The four-bar generating a function: Freudenstein's equation at its precision points, the error over
    the whole range from mbplanar's analysis.

    Parameters
    ----------
    task : FunctionTask
        The function, its ranges and precision points.
    ground : float
        Ground length d, m.
    steps : int
        Intervals of the x range analysed for the structural error.

    Returns
    -------
    FunctionResult
        The design; `range_error_y` gives the structural error in the function's units.

    Raises
    ------
    ModelError
        An expression that is not a formula in x or not finite over the range, an empty range, a
        function equal at both ends, an unknown spacing, or no feasible design (see
        `synthesise_angle_pairs`).

    Examples
    --------
    y = 1/x on [1, 2], the crank over 30° → 120°, the rocker over 60° → 150°:

    >>> import numpy as np
    >>> from mbplanar.synthesis import FunctionTask, synthesise_function
    >>> r = synthesise_function(FunctionTask("1/x", (1.0, 2.0), (30.0, 120.0), (60.0, 150.0)), steps=90)
    >>> [round(r.design[k], 4) for k in "abcd"]                    # lengths for d = 1
    [2.475, 0.9121, 2.4743, 1.0]
    >>> round(float(np.abs(r.range_error_y).max()), 5)             # largest error in y
    0.00059
    """
    task.validate()
    x = task.precision_x()
    return synthesise_angle_pairs(task.phi(x), task.psi_of_y(task.y(x)), ground, task, steps)
