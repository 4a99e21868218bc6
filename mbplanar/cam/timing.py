"""Cam timing from the linkage it serves: events on a model's motion.

An event is a condition on one coordinate of a point of the model over one turn of its input:

- ``fraction``: the point's displacement from the start of its forward stroke (its smallest coordinate)
  equals a fraction of its stroke H (the seed's s_D(φ) = 0.05·H: 28.0° and −23.684° on the shaper);
- ``forward_angle``: the input angle of the forward stroke, from the smallest coordinate to the largest
  (the shaper's working angle π + β = 221.538°).

Every root is found (sign changes on a grid, then Brent's method on the model), with its direction
(``rising`` or ``falling``). Angles are in the model's input unit, in (−180°, 180°].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError, did_you_mean

__all__ = ["Root", "EventResult", "Stroke", "point_stroke", "event_roots", "solve_event"]

GRID = 721          # samples of the input over one turn for bracketing


@dataclass(frozen=True)
class Root:
    """An input value (model unit) where the event holds, and whether the quantity is rising there."""

    value: float
    direction: str


@dataclass(frozen=True)
class Stroke:
    """A point coordinate's extremes over one turn (SI lengths, input values in the model's unit)."""

    point: str
    coordinate: str
    low: float
    high: float
    at_low: float
    at_high: float

    @property
    def stroke(self) -> float:
        return self.high - self.low

    @property
    def forward_angle(self) -> float:
        """Input angle from the smallest coordinate to the largest (model unit, in [0, turn))."""
        return float(np.mod(self.at_high - self.at_low, _turn_of(self.unit)))

    unit: str = "deg"


@dataclass(frozen=True)
class EventResult:
    """An event's name, its roots, and the value chosen (the root with the asked direction)."""

    name: str
    roots: tuple[Root, ...]
    value: float
    stroke: Stroke | None = None


def _turn_of(unit):
    return 360.0 if unit == "deg" else 2 * math.pi


def _coordinate(engine, point, axis, values_si):
    from ..kinematics import analyse
    motion = analyse(engine, np.atleast_1d(values_si))
    if not motion.success:
        raise ModelError(f"timing: the model cannot make a full turn ({motion.message})")
    try:
        k = motion.point(point)
    except KeyError:
        raise ModelError(f"timing: the model has no point or pair '{point}'; "
                         f"{did_you_mean(point, motion.point_names, 'points and pairs')}") from None
    return motion.xy[:, k, axis], motion.vq[:, k, axis]


def _wrap(value, unit):
    turn = _turn_of(unit)
    return float(turn / 2 - np.mod(turn / 2 - value, turn))


def point_stroke(engine, point: str, coordinate: str) -> Stroke:
    """Extremes of `point`'s `coordinate` ("x" or "y") over one turn of the single input."""
    axis = _axis(coordinate)
    inp = _input(engine)
    turn = _turn_of(inp.unit)
    grid = np.linspace(-turn / 2, turn / 2, GRID)
    _, vel = _coordinate(engine, point, axis, grid * inp.scale)
    roots = _roots(lambda x: _coordinate(engine, point, axis, x * inp.scale)[1], grid, vel)
    if len(roots) < 2:
        raise ModelError(f"timing: {point}.{coordinate} has no forward and return stroke over one turn")
    values = np.array([r.value for r in roots])
    pos = _coordinate(engine, point, axis, values * inp.scale)[0]
    lo, hi = int(np.argmin(pos)), int(np.argmax(pos))
    return Stroke(point, coordinate, float(pos[lo]), float(pos[hi]), float(values[lo]),
                  float(values[hi]), inp.unit)


def event_roots(engine, point: str, coordinate: str, fraction: float) -> tuple[tuple[Root, ...], Stroke]:
    """Every input value where `point` is `fraction` of its stroke past the start of its forward stroke."""
    if not 0 <= fraction <= 1:
        raise ModelError(f"timing: an event's fraction must lie in [0, 1], got {fraction}")
    axis = _axis(coordinate)
    inp = _input(engine)
    stroke = point_stroke(engine, point, coordinate)
    target = stroke.low + fraction * stroke.stroke
    turn = _turn_of(inp.unit)
    grid = np.linspace(-turn / 2, turn / 2, GRID)
    pos, _ = _coordinate(engine, point, axis, grid * inp.scale)
    roots = _roots(lambda x: _coordinate(engine, point, axis, x * inp.scale)[0] - target, grid, pos - target)
    return tuple(Root(_wrap(r.value, inp.unit), r.direction) for r in roots), stroke


def _roots(fun, grid, values) -> list[Root]:
    """Sign changes of `values` on `grid`, each refined by Brent's method on the scalar `fun`."""
    from scipy.optimize import brentq
    out = []
    sign = np.sign(values)
    for i in np.flatnonzero(sign[:-1] * sign[1:] < 0):
        x = brentq(lambda t: float(fun(t)[0]), grid[i], grid[i + 1], xtol=1e-13, rtol=1e-15)
        out.append(Root(float(x), "rising" if values[i + 1] > values[i] else "falling"))
    for i in np.flatnonzero(sign == 0):
        if 0 < i < len(grid) - 1:
            out.append(Root(float(grid[i]), "rising" if values[i + 1] > values[i - 1] else "falling"))
    return out


def solve_event(engine, name: str, point: str, coordinate: str = "x", fraction: float | None = None,
                measure: str = "fraction", direction: str | None = None) -> EventResult:
    """One event of a `[cam]` timing table (see the module).

    Parameters
    ----------
    engine : Engine of a one-input linkage whose input turns
    name : the event's name (for messages)
    point, coordinate : the point (pair or point name) and "x" or "y"
    fraction : for measure "fraction": fraction of the stroke past the start of the forward stroke
    measure : "fraction" or "forward_angle"
    direction : "rising", "falling" or None (then exactly one root must exist)

    Returns
    -------
    EventResult
        every root with its direction, the chosen value (model's input unit) and the point's stroke.
    """
    if measure == "forward_angle":
        stroke = point_stroke(engine, point, coordinate)
        return EventResult(name, (), stroke.forward_angle, stroke)
    if measure != "fraction":
        raise ModelError(f"timing event '{name}': measure must be 'fraction' or 'forward_angle', got "
                         f"'{measure}'")
    if fraction is None:
        raise ModelError(f"timing event '{name}': missing 'fraction'")
    roots, stroke = event_roots(engine, point, coordinate, fraction)
    chosen = [r for r in roots if direction in (None, "any", r.direction)]
    if direction not in (None, "any", "rising", "falling"):
        raise ModelError(f"timing event '{name}': direction must be 'rising' or 'falling', got '{direction}'")
    if not chosen:
        raise ModelError(f"timing event '{name}': {point}.{coordinate} never reaches {fraction:g} of its "
                         f"stroke {'while ' + direction if direction else ''}")
    if len(chosen) > 1:
        listed = ", ".join(f"{r.value:.6g} ({r.direction})" for r in chosen)
        raise ModelError(f"timing event '{name}' has several roots ({listed}): give 'direction'")
    return EventResult(name, roots, chosen[0].value, stroke)


def _axis(coordinate):
    if coordinate not in ("x", "y"):
        raise ModelError(f"timing: coordinate must be 'x' or 'y', got '{coordinate}'")
    return 0 if coordinate == "x" else 1


def _input(engine):
    if len(engine.inputs) != 1:
        raise ModelError("timing: the model must have exactly one input")
    inp = engine.inputs[0]
    if inp.unit not in ("deg", "rad"):
        raise ModelError("timing: the model's input must turn (a revolute input)")
    return inp
