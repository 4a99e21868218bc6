"""Re-dimensioning a compiled engine: the same structure (topology, Assur groups, solving blocks) with
another design's coordinates, without decomposing the link-joint graph again."""

from __future__ import annotations

import copy
import math

import numpy as np

from ._blocks import BlockSolver
from ._constraints import make_law
from ..errors import ModelError
from ..model import Mechanism, assemble, check_far, frame_origin

__all__ = ["with_dimensions", "same_structure"]


def same_structure(a: Mechanism, b: Mechanism) -> bool:
    """Whether two mechanisms have one structure: a design batch's variants must.

    Parameters
    ----------
    a, b : Mechanism
        The two models.

    Returns
    -------
    bool
        True when their ground, links, joints (names, kinds, links, guides), inputs, points and higher
        pairs agree; their coordinates and dimensions may differ.

    Raises
    ------
    Nothing on two mechanisms.

    Examples
    --------
    >>> from mbplanar.engine import same_structure
    >>> from mbplanar.model import read_model, translated
    >>> fourbar = read_model("models/fourbar.toml")
    >>> same_structure(fourbar, translated(fourbar, (1.0, 0.0)))
    True
    >>> same_structure(fourbar, read_model("models/slider_crank.toml"))
    False
    """
    return (a.ground == b.ground and list(a.links) == list(b.links)
            and [(n, j.kind, j.links, j.guide_points) for n, j in a.joints.items()]
            == [(n, j.kind, j.links, j.guide_points) for n, j in b.joints.items()]
            and [(i.joint, i.unit, i.sense) for i in a.inputs] == [(i.joint, i.unit, i.sense) for i in b.inputs]
            and [(n, p.link) for n, p in a.points.items()] == [(n, p.link) for n, p in b.points.items()]
            and [(n, h.kind, h.links, h.follower) for n, h in a.higher.items()]
            == [(n, h.kind, h.links, h.follower) for n, h in b.higher.items()])


def with_dimensions(engine, mechanism: Mechanism, higher=None):
    """A copy of `engine` for `mechanism`, a re-dimensioned variant of its model (same links, joints,
    points and inputs; other coordinates, dimensions, guides or input zero).

    The topology and structure are kept; the drawn pose is assembled, and the joint laws, drawn angles
    and solving plans are rebuilt from it (microseconds, against milliseconds for a new `Engine`).

    Parameters
    ----------
    engine : Engine
        A compiled engine of the reference design.
    mechanism : Mechanism
        The variant (assembled or a sketch).
    higher : callable, optional
        higher(centre) → the higher pairs' laws in the engine's frame centred on `centre` (a made design's,
        `mbplanar.accuracy`); default: built from the variant's drawing and checked against it.

    Returns
    -------
    Engine
        An independent engine: its atlas starts empty.

    Raises
    ------
    ModelError
        When the variant's structure differs from the engine's.
    MotionError
        When the variant's drawn pose cannot be assembled.

    Examples
    --------
    >>> import tomllib
    >>> from mbplanar.engine import Engine, with_dimensions
    >>> from mbplanar.model import Template, parse_model, read_model
    >>> with open("models/fourbar_design.toml", "rb") as f:
    ...     template = Template(tomllib.load(f), "models/fourbar_design.toml")
    >>> engine = Engine(parse_model(template.bind()))
    >>> longer = with_dimensions(engine, parse_model(template.bind({"a": 0.12})))   # a 120 mm crank
    >>> longer.topology is engine.topology, [round(v, 4) for v in longer.mech.joints["A"].at]
    (True, [0.06, 0.1039])
    >>> with_dimensions(engine, read_model("models/slider_crank.toml"))
    Traceback (most recent call last):
    mbplanar.errors.ModelError: models/slider_crank.toml: the variant's links, joints, points or inputs differ ...
    """
    from ._solver import higher_laws, wheels
    if not same_structure(engine.mech, mechanism):
        raise ModelError(f"{mechanism.source}: the variant's links, joints, points or inputs differ from "
                         f"the model's ({engine.mech.source}); re-dimensioning keeps the structure")
    new = copy.copy(engine)
    new.prepared = {}  # tables of the old dimensions
    new._atlas = None
    check_far(mechanism)
    new.mech = mech = assemble(mechanism)
    new.inputs = mech.inputs
    new.size = max([1e-9] + [math.dist(a.at, b.at) for a in mech.joints.values() for b in mech.joints.values()])
    new.centre = frame_origin([j.at for j in mech.joints.values()] or [(0.0, 0.0)], new.size)
    new.laws = {name: make_law(j, new.centre) for name, j in mech.joints.items()}
    new.laws.update(higher_laws(mech, new.centre) if higher is None else higher(new.centre))
    new.reference_angle = {link: new._drawn_link_angle(link) for link in new.links}
    new.phi_drawn = np.array([new._drawn_phi(inp) for inp in new.inputs])
    new.joint_value_drawn = {name: new._drawn_joint_value(name) for name in mech.joints}
    new.solver = BlockSolver(mech, new.laws, new.topology.blocks, new.links, new.size, new.phi_drawn, new.tol)
    new.solver.wheels = wheels(mech)
    new.blocks = new.solver.blocks
    return new
