"""Circuit, branch and order defects of a synthesised design, found by mbplanar's own engine.

A design reaches its precision nodes (points, poses, angle pairs) at known input values φ_i. Starting
from node 1 (the model's drawn pose) the engine continues the motion along the input on one assembly
branch:

* order defect: no input sense reaches the nodes in the given order (a crank's angles are compared
  modulo a turn; a limited input's must be monotonic);
* branch defect: a singular position between the first and the last node (a dead point, where the
  motion stops, or a change point, where another assembly branch crosses), or, when a full crank turn is
  asked for, anywhere in the turn;
* circuit defect: at a node's input value the branch holds another configuration than the one the
  synthesis meant (the node lies on the other circuit), i.e. some named point differs by more than `tol`.

A design with any defect is never reported as a solution.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..kinematics import analyse

__all__ = ["Defects", "check_defects"]

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class Defects:
    """What `check_defects` found in a synthesised design; `ok` is True when it found nothing.

    Attributes
    ----------
    circuit : tuple of int
        1-based nodes where the analysed design is not where the synthesis meant it (another circuit).
    unreached : tuple of int
        Nodes beyond a motion limit.
    branch : tuple of str
        The singular positions met between the nodes (limits and change points), described.
    order : bool
        True for an order defect: no input sense meets the nodes in their order.
    sense : int
        The input sense used: +1 (increasing input) or -1.
    full_turn : bool or None
        Whether the input turned fully without a singular position; None when not asked.
    node_phi : tuple of float
        The nodes' input values (SI) in that sense, as the model's continuation reaches them.

    Examples
    --------
    >>> import numpy as np, mbplanar
    >>> from mbplanar.synthesis import check_defects
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> phi = np.radians([60, 100, 140])
    >>> m = mbplanar.analyse(engine, phi)
    >>> d = check_defects(engine, phi[::-1], {"M": m.xy[::-1, m.point("M")]})   # the nodes backwards
    >>> d.ok, d.sense, d.describe()
    (True, -1, 'no defect')
    """

    circuit: tuple
    unreached: tuple
    branch: tuple
    order: bool
    sense: int
    full_turn: bool | None
    node_phi: tuple

    @property
    def ok(self) -> bool:
        return not (self.circuit or self.unreached or self.branch or self.order) and self.full_turn is not False

    def as_dict(self) -> dict:
        return {"ok": self.ok, "circuit": list(self.circuit), "branch": list(self.branch),
                "unreached": list(self.unreached), "order": self.order, "sense": self.sense,
                "full_turn": self.full_turn}

    def describe(self) -> str:
        parts = []
        if self.order:
            parts.append("order defect (no input sense reaches the nodes in the given order)")
        if self.circuit:
            parts.append("circuit defect at node(s) " + ", ".join(map(str, self.circuit)))
        if self.unreached:
            parts.append("node(s) " + ", ".join(map(str, self.unreached)) + " beyond a motion limit")
        parts += [f"branch defect: {b}" for b in self.branch]
        if self.full_turn is False:
            parts.append("the crank does not turn fully")
        return "; ".join(parts) or "no defect"


def _offsets(phi, sense: int, periodic: bool) -> np.ndarray:
    """Input travelled from node 1 to every node in `sense` (modulo a turn for a crank)."""
    u = sense * (phi - phi[0])
    return np.mod(u, TWO_PI) if periodic else u


def _in_order(u) -> bool:
    return bool(np.all(np.diff(u) > 0))


def check_defects(engine, phi, intended: dict, *, periodic: bool = True, full_turn: bool = False,
                  travel=None, tol: float = 1e-6, steps: int = 720) -> Defects:
    """Circuit, branch and order defects of a synthesised design, by mbplanar's own analysis.

    The design is run by continuation from its first node through the others (in the sense that meets
    them in order, if one does): a node where a named point is not where the synthesis meant it is a
    circuit defect; a limit or change point on the way a branch defect.

    Parameters
    ----------
    engine : mbplanar.Engine
        The design, drawn in its configuration at the first node.
    phi : (n,) array_like
        The model's input value (SI) at each node, in the nodes' order.
    intended : dict
        {point or joint name: (n, 2) positions (m) the synthesis meant at each node}.
    periodic : bool
        The input is a crank angle (compared modulo 2π).
    full_turn : bool
        Also require a full turn of the input without a singular position.
    travel : (2,) array_like, optional
        The whole input range (SI, the model's φ) the design must run through without a singular
        position, beyond the nodes (e.g. a function generator's range).
    tol : float
        Largest distance (m) between the analysed and the intended positions at a node.
    steps : int
        Positions of the continuation over the travel.

    Returns
    -------
    Defects
        What was found (`ok` True for none).

    Raises
    ------
    KeyError
        A name of `intended` that is neither a joint nor a point of the model.

    Examples
    --------
    The four-bar's own positions are met; one moved by 1 cm is on no circuit of it:

    >>> import numpy as np, mbplanar
    >>> from mbplanar.synthesis import check_defects
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> phi = np.radians([60, 100, 140])
    >>> m = mbplanar.analyse(engine, phi)
    >>> want = m.xy[:, m.point("M")].copy()
    >>> check_defects(engine, phi, {"M": want}, full_turn=True).ok
    True
    >>> want[1] += 0.01
    >>> check_defects(engine, phi, {"M": want}).circuit
    (2,)
    """
    phi = np.asarray(phi, float)
    # the engine measures the drawn input within its default sweep: node 1 moved there by whole turns
    rotary = engine.mech.joints[engine.inputs[0].joint].kind == "R"       # a sliding input is not moved by turns
    shift = TWO_PI * round((float(engine.phi_drawn[0]) - phi[0]) / TWO_PI) if rotary else 0.0
    phi = phi + shift
    senses = [s for s in (1, -1) if _in_order(_offsets(phi, s, periodic))]
    order = not senses
    sense = senses[0] if senses else 1
    u = _offsets(phi, sense, periodic)
    lo, span = 0.0, TWO_PI if full_turn else float(u[-1])
    if travel is not None:
        ends = sense * (np.asarray(travel, float) + shift - phi[0])
        lo, span = min(lo, float(ends.min())), max(span, float(ends.max()))
    grid = np.unique(np.r_[np.linspace(lo, span, steps + 1), u])
    motion = analyse(engine, phi[0] + sense * grid)
    reached = motion.phi[:, 0]
    branch = [f"{lim.kind or 'limit'} at {_deg(lim.phi[0])}° (links {', '.join(map(str, lim.links))})"
              for lim in motion.limits]
    branch += [f"change point at {_deg(c.phi[0])}° (links {', '.join(map(str, c.links))})"
               for c in motion.crossings if _between(c.phi[0], phi[0], sense, lo, span)]
    circuit, unreached = [], []
    for i, ui in enumerate(u):
        row = np.flatnonzero(np.isclose(reached, phi[0] + sense * ui, rtol=0, atol=1e-12))
        if not len(row):
            unreached.append(i + 1)
            continue
        for name, where in intended.items():
            got = motion.xy[row[0], motion.point(name)]
            if not np.hypot(*(got - where[i])) <= tol:
                circuit.append(i + 1)
                break
    turned = None
    if full_turn:
        turned = bool(len(reached) == len(grid) and not motion.limits)
    return Defects(tuple(circuit), tuple(unreached), tuple(branch), order, sense, turned,
                   tuple(float(phi[0] + sense * x) for x in u))


def _deg(x) -> str:
    return f"{math.degrees(float(x)):.4f}"


def _between(x, start, sense, lo, hi) -> bool:
    t = sense * (float(x) - start)
    return lo - 1e-12 <= t <= hi + 1e-12
