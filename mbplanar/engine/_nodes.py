"""Solved positions on the branch with their derivatives (`Node`), and the quintic Hermite interpolant
between two of them: what the continuation (`_atlas`) walks with and the singular-position solvers
(`_singular`) start from."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._blocks import BlockSolver
from ._continuation import HERMITE5, hermite_coefficients, hermite_value

__all__ = ["HERMITE5", "Node", "node_at", "hermite_between"]


@dataclass
class Node:
    """A solved position on the branch with the derivatives of its unknowns along `direction`.

    `phi` (n_in,) the input values; `direction` (n_in,) dφ/ds of the walk; per block `q`, `qd`, `qdd`
    (m,) the unknowns and their first and second derivatives along the walk; `dets` (n_blocks,) the
    blocks' Jacobian determinants (`signs`: the assembly branch); `pivot` the smallest pivot ratio.
    The atlas' nodes (`Atlas.nodes`) are these; `per_input` gives the derivatives per input.

    Examples
    --------
    >>> import numpy as np
    >>> from mbplanar.engine import Engine
    >>> from mbplanar.model import read_model
    >>> atlas = Engine(read_model("models/fourbar.toml")).atlas()
    >>> node = atlas.nodes[0]
    >>> round(float(np.degrees(node.phi[0])), 6), node.signs.tolist()     # the drawn pose
    (60.0, [1.0, -1.0])
    >>> qd, qdd = node.per_input()
    >>> [v.shape for v in qd]                                              # the crank's block has none
    [(0,), (2,)]
    """

    phi: np.ndarray
    direction: np.ndarray
    q: list
    qd: list
    qdd: list
    dets: np.ndarray
    pivot: float = 1.0

    @property
    def signs(self) -> np.ndarray:
        return np.sign(self.dets)

    def per_input(self, k: int = 0) -> tuple[list, list]:
        """q' and q'' of every block with respect to input k (the walk's are per unit s, dφ/ds =
        direction)."""
        d = self.direction[k]
        return [qd / d for qd in self.qd], [qdd / (d * d) for qdd in self.qdd]


def node_at(solver: BlockSolver, phi: np.ndarray, direction: np.ndarray, guesses) -> Node | None:
    sol = solver.solve_batch(phi[None, :], guesses)
    if not sol.valid[0]:
        return None
    solver.rates(sol, direction[None, :], np.zeros((1, len(solver.inputs))))
    return Node(phi.copy(), direction, [s.q[:, 0] for s in sol.blocks], [s.qd[:, 0] for s in sol.blocks],
                 [s.qdd[:, 0] for s in sol.blocks], solver.dets(sol)[0], float(solver.pivots(sol)[0]))



def hermite_between(a: Node, b: Node, phi: np.ndarray) -> list:
    """Every block's unknowns (m, 1) at φ between two nodes of a walk, by the quintic Hermite
    interpolant of their q, q', q'' along the segment from a to b."""
    k = int(np.argmax(np.abs(b.phi - a.phi)))
    h = float(b.phi[k] - a.phi[k])
    t = float((phi[k] - a.phi[k]) / h)
    (qda, qdda), (qdb, qddb) = a.per_input(k), b.per_input(k)
    return [hermite_value(*hermite_coefficients(q0, q1, h * d0, h * d1, h * h * dd0, h * h * dd1, HERMITE5),
                          t)[:, None] for q0, q1, d0, d1, dd0, dd1 in zip(a.q, b.q, qda, qdb, qdda, qddb)]

