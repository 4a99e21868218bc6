"""Structural analysis of a planar linkage: decomposition into Assur groups (Artobolevsky).

The mechanism is given as plain data — a ground link, the moving links, a table of lower
pairs ``(name, kind, link_a, link_b)`` with kind ``'R'`` (revolute) or ``'P'`` (prismatic),
and the names of the input (driving) joints — so this module depends only on the standard
library, networkx and :mod:`mbplanar.errors`.

Counting
--------
* ``dof = 3·n − 2·p`` (Chebyshev–Grübler; ``n`` moving links, ``p`` pairs, all lower pairs).
* ``loops = p − n``, the cycle rank of the link–joint multigraph (ground included).

Inputs
------
* An input joint between ground and a link makes that link an *input link*: the class I
  mechanism ``I(ground,link)``.
* An input joint between two moving links (a driven actuator, e.g. a hydraulic cylinder)
  has a known variable, so for the group search the two links count as **one rigid body**
  and the input joint counts as no constraint in ``3n = 2p``.  The group that contains the
  body is reported with both links, with the input joint among its internal pairs (and in
  :attr:`AssurGroup.inputs`).  Class, order and kind of such a group are computed on the
  bodies, e.g. a hydraulic cylinder pinned to ground and to a boom that is pinned to ground
  is an RRR dyad.
* Rule decision: if one side of an actuator is already known (ground or an input link),
  the other side is known too.  It is reported as one more class I mechanism, e.g.
  ``I(0,1) → I(1,2)``, in :attr:`Structure.input_mechanisms`; only links driven directly
  from ground are :attr:`Structure.input_links`.  Input joints must not close a loop.

Assur groups
------------
With ``K`` the known links (ground, input links, earlier groups), an Assur group is a
minimal set ``S`` of unknown bodies with ``3·|S| = 2·p(S)``, where ``p(S)`` counts the
pairs between bodies of ``S`` and between ``S`` and ``K`` (pairs to still unknown links
are not part of the group).  Since ``2p`` is even, ``|S|`` is even.  Groups are searched
smallest first (2, 4, 6, ... bodies) among connected sets of unknown bodies grown from the
frontier of ``K``; all minimal groups of the smallest size are taken, then the search
repeats until every link is known.  The search only re-examines sets whose count changed
(those next to the newly known links) up to the size already searched exhaustively, so a
chain of many groups costs about the same per group.

Before the search the whole chain is checked for over-constraint with the (3,3) pebble
game of body–bar frameworks (each pair = 2 bars, the known part = one body): every set of
unknown bodies must satisfy ``3·|S| ≥ 2·p(S)`` counted with ``K`` and ``3·(|S|−1) ≥
2·p(S)`` counted among themselves.  When that holds and ``dof`` equals the number of
inputs, the decomposition exists and is unique.  A closed contour made only of prismatic
pairs is refused (it has a redundant rotational constraint that the count cannot see).

Classification (Artobolevsky)
-----------------------------
* A dyad (2 bodies, 3 pairs) is class II; its kind reads the three pair types
  external–internal–external, reported as ``max(s, s[::-1])``: RRR, RRP, RPR, PRP, RPP.
* Otherwise, if the internal pairs form a closed contour, the class is the number of pairs
  of the largest contour (a four-sided contour gives class IV); if they form no contour,
  the class is the largest number of internal pairs on one body (a triad's base link has 3:
  class III).
* The order is the number of external pairs; the mechanism class is the highest group
  class (1 with no groups).

Errors (:class:`~mbplanar.errors.ModelError`, naming the links or joints at fault)
-----------------------------------------------------------------------------------
duplicate or unknown names, a joint naming an unknown link, an input that is not a joint,
a link not connected to ground, a closed contour of prismatic pairs, ``dof`` different from
the number of inputs, input joints closing a loop, a pair between two links whose relative
position the inputs already fix, and an over-constrained (rigid) sub-chain — which, when
the DOF count is right, always comes with links that keep their own mobility: both are
named.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Iterable, Sequence

if TYPE_CHECKING:  # networkx is imported where a graph is made (it costs ~0.1 s)
    import networkx as nx

from ..errors import ModelError

__all__ = ["AssurGroup", "Structure", "decompose", "roman", "replacing_link"]

KINDS = ("R", "P")
_KNOWN = 0  # body id of the known part: ground and the links of class I mechanisms


# ---------------------------------------------------------------------------------------
# Public results
# ---------------------------------------------------------------------------------------


@dataclass(frozen=True)
class AssurGroup:
    """One Assur group, in the order it can be solved.

    `links` its links; `joints` all its pairs, `internal` those between two of its links, `external`
    those joining it to ground, input links or earlier groups; `group_class` (2: a dyad, 3, 4, ...) and
    `order` (its external pairs, Artobolevsky); `kind` a dyad's pair types ('RRR', 'RRP', 'RPR', 'PRP',
    'RPP'; None for larger groups); `inputs` the actuator joints among its internal pairs;
    `attached_to` the known links its external pairs reach; `label` its structural-formula notation.

    Examples
    --------
    >>> from mbplanar.structure import decompose
    >>> fourbar = decompose("0", ["1", "2", "3"], [("O", "R", "0", "1"), ("A", "R", "1", "2"),
    ...                                           ("B", "R", "2", "3"), ("C", "R", "3", "0")], ["O"])
    >>> dyad = fourbar.groups[0]
    >>> dyad.label, dyad.kind, dyad.internal, dyad.external, dyad.attached_to
    ('II(2,3)', 'RRR', ('B',), ('A', 'C'), ('0', '1'))
    """

    links: tuple[str, ...]  # the group's links
    joints: tuple[str, ...]  # all its pairs: internal ones first, then external ones
    internal: tuple[str, ...]  # pairs between two links of the group
    external: tuple[str, ...]  # pairs joining the group to ground, input links or earlier groups
    group_class: int  # 2 = dyad, 3, 4, ... (Artobolevsky)
    order: int  # number of external pairs
    kind: str | None  # dyads only: 'RRR', 'RRP', 'RPR', 'PRP', 'RPP'; None for other groups
    inputs: tuple[str, ...] = ()  # input (actuator) joints among the internal pairs
    attached_to: tuple[str, ...] = ()  # known links reached by the external pairs

    @property
    def label(self) -> str:
        """The group in structural-formula notation, e.g. ``II(2,3)``."""
        return f"{roman(self.group_class)}({','.join(self.links)})"


@dataclass(frozen=True)
class Structure:
    """Result of :func:`decompose`: mobility, loops, input mechanisms and Assur groups in solving order.

    `dof` (Chebyshev: 3·n − 2·p5 − p4), `loops` (p − n), `inputs` the driving joints, `input_links` the
    links they drive from ground, `groups` the Assur groups (`AssurGroup`) in solving order, `mechanism_class` the
    highest group class (1 with none), `formula` the structural formula, `input_mechanisms` the class I
    mechanisms (driver, driven). With higher pairs the groups are those of the equivalent lower-pair
    mechanism: `replaced` maps the name of each link that replaces a higher pair to the pair's name
    (its two pairs are named ``pair:link``), and `higher` lists the higher pairs (`p4` of them).

    Examples
    --------
    >>> from mbplanar import Engine, read_model
    >>> structure = Engine(read_model("models/class3_triad.toml")).topology.structure
    >>> structure.formula, structure.mechanism_class, structure.dof, structure.loops
    ('I(0,1) → III(2,3,4,5)', 3, 1, 2)
    """

    dof: int  # Chebyshev: 3·n_moving − 2·p5 − p4
    loops: int  # independent loops = p − n_moving (cycle rank of the link–joint multigraph)
    inputs: tuple[str, ...]  # input (driving) joints
    input_links: tuple[str, ...]  # links driven directly from ground by an input joint
    groups: tuple[AssurGroup, ...]  # in solving order
    mechanism_class: int  # highest group class (1 if there are no groups)
    formula: str  # e.g. "I(0,1) → II(2,3) → II(4,5)"
    input_mechanisms: tuple[tuple[str, str], ...] = ()  # class I mechanisms (driver, driven)
    higher: tuple[str, ...] = ()  # the higher pairs (p4 of them)
    replaced: dict = field(default_factory=dict)  # replacing link → higher pair

    @property
    def p4(self) -> int:
        return len(self.higher)

    def real_links(self, group: AssurGroup) -> tuple[str, ...]:
        """The group's own links, without the links that replace higher pairs."""
        return tuple(link for link in group.links if link not in self.replaced)

    def pairs_of(self, group: AssurGroup) -> tuple[str, ...]:
        """The higher pairs whose replacing link is in the group."""
        return tuple(self.replaced[link] for link in group.links if link in self.replaced)


def replacing_link(name: str, taken) -> str:
    """The name of the link that replaces higher pair `name` in the equivalent mechanism: the pair's
    name primed, with more primes while the name is taken."""
    link = name + "'"
    while link in taken:
        link += "'"
    return link


def _decompose_equivalent(ground, links, joints, inputs, higher) -> Structure:
    """`decompose` of a chain with higher pairs: the equivalent lower-pair mechanism's groups."""
    links = tuple(links)
    n, p5, p4 = len(links), len(joints), len(higher)
    dof = 3 * n - 2 * p5 - p4
    if dof != len(inputs):
        raise ModelError(
            f"the chain has DOF = 3·n − 2·p5 − p4 = 3·{n} − 2·{p5} − {p4} = {dof} (n = {n} moving links, p5 = "
            f"{p5} lower pairs, p4 = {p4} higher pairs) but {len(inputs)} input joint(s) are given "
            f"({_names(inputs) or 'none'})")
    taken = {ground, *links, *(j[0] for j in joints)}
    extra_links, extra_joints, replaced = [], [], {}
    for name, a, b, kind_a, kind_b in higher:
        for link in (a, b):
            if link != ground and link not in links:
                raise ModelError(f"joint {name!r} names unknown link {link!r}")
        v = replacing_link(name, taken)
        taken.add(v)
        replaced[v] = name
        extra_links.append(v)
        extra_joints += [(f"{name}:{a}", kind_a, a, v), (f"{name}:{b}", kind_b, b, v)]
    found = decompose(ground, links + tuple(extra_links), tuple(joints) + tuple(extra_joints), inputs)
    return replace(found, loops=p5 + p4 - n, higher=tuple(h[0] for h in higher), replaced=replaced)


# ---------------------------------------------------------------------------------------
# Entry point
# ---------------------------------------------------------------------------------------


def decompose(
    ground: str,
    links: Sequence[str],
    joints: Sequence[tuple[str, str, str, str]],
    inputs: Sequence[str],
    higher: Sequence[tuple[str, str, str, str, str]] = (),
) -> Structure:
    """Decompose a planar linkage into input mechanisms and Assur groups (Artobolevsky).

    See the module docstring for the rules.

    Parameters
    ----------
    ground : str
        The ground link.
    links : sequence of str
        The moving links (ground excluded).
    joints : sequence of (str, str, str, str)
        The lower pairs: (name, kind 'R' or 'P', link_a, link_b).
    inputs : sequence of str
        The input (driving) joints' names.
    higher : sequence of (str, str, str, str, str), optional
        The higher pairs (name, link_a, link_b, kind_a, kind_b), each decomposed as the link that replaces
        it in the equivalent lower-pair mechanism, with a pair of kind_a ('R' or 'P') on link_a and one of
        kind_b on link_b.

    Returns
    -------
    Structure

    Raises
    ------
    ModelError
        The table does not describe a decomposable mechanism: a duplicate or unknown name, a link not
        connected to ground, a contour of prismatic pairs, a DOF other than the inputs' number, inputs
        closing a loop, an over-constrained sub-chain; the message names the links or joints at fault.

    Examples
    --------
    >>> from mbplanar.structure import decompose
    >>> slider_crank = decompose("0", ["1", "2", "3"], [("O", "R", "0", "1"), ("A", "R", "1", "2"),
    ...                                                ("B", "R", "2", "3"), ("S", "P", "0", "3")], ["O"])
    >>> slider_crank.formula, slider_crank.groups[0].kind
    ('I(0,1) → II(2,3)', 'RRP')
    >>> decompose("0", ["1", "2"], [("O", "R", "0", "1"), ("A", "R", "1", "2"), ("B", "R", "2", "0")], ["O"])
    Traceback (most recent call last):
    mbplanar.errors.ModelError: the chain has DOF = 3·n − 2·p = 3·2 − 2·3 = 0 (n = 2 moving links, ...
    """
    if higher:
        return _decompose_equivalent(ground, links, joints, inputs, higher)
    chain = _read_chain(ground, links, joints, inputs)
    _check_connected_to_ground(chain)
    _check_no_prismatic_contour(chain)
    dof = _check_dof(chain)
    bodies = _bodies_after_inputs(chain)
    _check_constraint_counts(bodies)
    groups = tuple(_describe_group(bodies, members, known)
                   for members, known in _assur_groups_in_solving_order(bodies))
    return Structure(
        dof=dof,
        loops=len(chain.joints) - len(chain.links),
        inputs=chain.inputs,
        input_links=tuple(driven for driver, driven in bodies.input_mechanisms if driver == ground),
        groups=groups,
        mechanism_class=max((g.group_class for g in groups), default=1),
        formula=_structural_formula(bodies.input_mechanisms, groups),
        input_mechanisms=bodies.input_mechanisms,
    )


# ---------------------------------------------------------------------------------------
# Reading and checking the table
# ---------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Joint:
    name: str
    kind: str
    a: str
    b: str

    def other(self, link: str) -> str:
        return self.b if link == self.a else self.a


@dataclass(frozen=True)
class _Chain:
    ground: str
    links: tuple[str, ...]
    joints: tuple[_Joint, ...]
    inputs: tuple[str, ...]
    position: dict[str, int]  # ground -1, moving links 0, 1, ... (for a stable order)
    incident: dict[str, tuple[int, ...]]  # link -> rows of the joints on it

    def joint(self, name: str) -> _Joint:
        return next(j for j in self.joints if j.name == name)

    def joints_touching(self, links: Iterable[str]) -> list[_Joint]:
        """Joints with an end on one of `links`, in table order."""
        touching = {row for link in links for row in self.incident[link]}
        return [self.joints[row] for row in sorted(touching)]

    def sorted_links(self, names: Iterable[str]) -> tuple[str, ...]:
        return tuple(sorted(set(names), key=self.position.__getitem__))


def _read_chain(ground, links, joints, inputs) -> _Chain:
    links = tuple(links)
    _refuse_duplicates("link", (ground, *links))
    position = {ground: -1, **{link: i for i, link in enumerate(links)}}
    table = tuple(_read_joint(row, position) for row in joints)
    _refuse_duplicates("joint", [j.name for j in table])
    inputs = tuple(inputs)
    _refuse_duplicates("input", inputs)
    names = {j.name for j in table}
    for name in inputs:
        if name not in names:
            raise ModelError(f"input {name!r} is not a joint of the table")
    incident: dict[str, list[int]] = {link: [] for link in position}
    for row, joint in enumerate(table):
        incident[joint.a].append(row)
        incident[joint.b].append(row)
    return _Chain(ground, links, table, inputs, position,
                  {link: tuple(rows) for link, rows in incident.items()})


def _refuse_duplicates(what: str, names: Iterable[str]) -> None:
    repeated = [name for name, count in Counter(names).items() if count > 1]
    if repeated:
        raise ModelError(f"{what} name(s) given more than once: {_names(repeated)}")


def _read_joint(row, position) -> _Joint:
    try:
        name, kind, a, b = row
    except (TypeError, ValueError):
        raise ModelError(f"joint row {row!r} must be (name, kind, link_a, link_b)") from None
    if kind not in KINDS:
        raise ModelError(f"joint {name!r}: kind {kind!r} is not 'R' or 'P'")
    for link in (a, b):
        if link not in position:
            raise ModelError(f"joint {name!r} names unknown link {link!r}")
    if a == b:
        raise ModelError(f"joint {name!r} joins link {a!r} to itself")
    return _Joint(name, kind, a, b)


def _link_graph(chain: _Chain, joints: Iterable[_Joint]) -> nx.MultiGraph:
    import networkx as nx
    graph = nx.MultiGraph()
    graph.add_nodes_from((chain.ground, *chain.links))
    graph.add_edges_from((j.a, j.b, j.name) for j in joints)
    return graph


def _check_connected_to_ground(chain: _Chain) -> None:
    import networkx as nx
    reached = nx.node_connected_component(_link_graph(chain, chain.joints), chain.ground)
    loose = [link for link in chain.links if link not in reached]
    if loose:
        raise ModelError(f"{_listed('link', loose)} not connected to ground {chain.ground!r}")


def _check_no_prismatic_contour(chain: _Chain) -> None:
    import networkx as nx
    prismatic = _link_graph(chain, (j for j in chain.joints if j.kind == "P"))
    try:
        contour = nx.find_cycle(prismatic)
    except nx.NetworkXNoCycle:
        return
    raise ModelError(
        f"joints {_names(key for _, _, key in contour)} form a closed contour of prismatic "
        "pairs only: its rotational constraint is redundant and the structure count fails"
    )


def _check_dof(chain: _Chain) -> int:
    n, p = len(chain.links), len(chain.joints)
    dof = 3 * n - 2 * p
    if dof != len(chain.inputs):
        raise ModelError(
            f"the chain has DOF = 3·n − 2·p = 3·{n} − 2·{p} = {dof} "
            f"(n = {n} moving links, p = {p} lower pairs) but {len(chain.inputs)} input "
            f"joint(s) are given ({_names(chain.inputs) or 'none'})"
        )
    return dof


# ---------------------------------------------------------------------------------------
# Inputs: class I mechanisms and rigid actuator bodies
# ---------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Bodies:
    """The chain seen as bodies: body 0 is the known part, the others are unknown.

    Links joined by input joints form one body; bars are the joints that are not inputs.
    """

    chain: _Chain
    input_mechanisms: tuple[tuple[str, str], ...]
    members: dict[int, tuple[str, ...]]  # body -> its links
    body_of: dict[str, int]  # link -> body
    bars: tuple[_Joint, ...]  # joints that are not inputs
    incident: dict[int, tuple[tuple[_Joint, int], ...]]  # body -> (bar, body at the other end)

    @property
    def unknown(self) -> list[int]:
        return [body for body in self.members if body != _KNOWN]

    def links_of(self, bodies: Iterable[int]) -> tuple[str, ...]:
        return self.chain.sorted_links(link for body in bodies for link in self.members[body])


def _bodies_after_inputs(chain: _Chain) -> _Bodies:
    import networkx as nx
    input_joints = [chain.joint(name) for name in chain.inputs]
    driven = _link_graph(chain, input_joints)
    _refuse_input_loops(driven)
    mechanisms = _class_one_mechanisms(chain, input_joints)
    known = {chain.ground, *(link for _, link in mechanisms)}
    actuated = sorted(
        (chain.sorted_links(part) for part in nx.connected_components(driven) if chain.ground not in part),
        key=lambda part: chain.position[part[0]],
    )
    members = {_KNOWN: chain.sorted_links(known), **{i: part for i, part in enumerate(actuated, 1)}}
    body_of = {link: body for body, part in members.items() for link in part}
    inputs = set(chain.inputs)
    bars = tuple(j for j in chain.joints if j.name not in inputs)
    _refuse_bars_inside_a_body(chain, bars, body_of)
    incident: dict[int, list[tuple[_Joint, int]]] = {body: [] for body in members}
    for bar in bars:
        a, b = body_of[bar.a], body_of[bar.b]
        incident[a].append((bar, b))
        incident[b].append((bar, a))
    return _Bodies(chain, mechanisms, members, body_of, bars,
                   {body: tuple(pairs) for body, pairs in incident.items()})


def _refuse_input_loops(driven: nx.MultiGraph) -> None:
    import networkx as nx
    try:
        loop = nx.find_cycle(driven)
    except nx.NetworkXNoCycle:
        return
    raise ModelError(
        f"input joints {_names(key for _, _, key in loop)} close a loop among links "
        f"{_names(u for u, _, _ in loop)}: their variables cannot all be given"
    )


def _class_one_mechanisms(chain: _Chain, input_joints: list[_Joint]) -> tuple[tuple[str, str], ...]:
    """Input links in breadth-first order from ground: (driver, driven) pairs."""
    mechanisms, reached, queue = [], {chain.ground}, [chain.ground]
    for driver in queue:
        for joint in input_joints:
            if driver in (joint.a, joint.b) and joint.other(driver) not in reached:
                reached.add(joint.other(driver))
                queue.append(joint.other(driver))
                mechanisms.append((driver, joint.other(driver)))
    return tuple(mechanisms)


def _refuse_bars_inside_a_body(chain: _Chain, bars: Iterable[_Joint], body_of: dict[str, int]) -> None:
    for bar in bars:
        if body_of[bar.a] == body_of[bar.b]:
            fixed_by = "ground and the inputs" if body_of[bar.a] == _KNOWN else "input joints"
            raise ModelError(
                f"joint {bar.name!r} joins links {bar.a!r} and {bar.b!r}, whose relative "
                f"position {fixed_by} already fix: the chain is over-constrained there"
            )


# ---------------------------------------------------------------------------------------
# Over-constraint check: (3,3) pebble game on the body–bar multigraph
# ---------------------------------------------------------------------------------------


class _PebbleGame:
    """The (3,3) pebble game (Jacobs–Hendrickson, Lee–Streinu) for body–bar frameworks.

    Each body holds 3 pebbles; an accepted bar is covered by a pebble of one of its ends
    and directed away from it.  A bar ``uv`` is independent iff 4 pebbles can be gathered
    on ``u`` and ``v``; otherwise the bodies reachable from ``u`` and ``v`` span a tight
    set (``bars = 3·bodies − 3``) that the new bar over-constrains.
    """

    PEBBLES = 3

    def __init__(self, bodies: Iterable[int]):
        self.free = {body: self.PEBBLES for body in bodies}
        self.out: dict[int, Counter] = {body: Counter() for body in self.free}

    def add_bar(self, u: int, v: int) -> bool:
        if not self.gather(u, v, self.PEBBLES + 1):
            return False
        payer, other = (u, v) if self.free[u] else (v, u)
        self.free[payer] -= 1
        self.out[payer][other] += 1
        return True

    def gather(self, u: int, v: int, wanted: int) -> bool:
        """Move free pebbles onto u and v until they hold `wanted`; False if impossible."""
        while self.free[u] + self.free[v] < wanted:
            if not (self._fetch_pebble(u, keep={u, v}) or self._fetch_pebble(v, keep={u, v})):
                return False
        return True

    def reach(self, *starts: int) -> set[int]:
        seen, stack = set(starts), list(starts)
        while stack:
            for nxt in self.out[stack.pop()]:
                if nxt not in seen:
                    seen.add(nxt)
                    stack.append(nxt)
        return seen

    def _fetch_pebble(self, start: int, keep: set[int]) -> bool:
        parent, stack = {start: start}, [start]
        while stack:
            node = stack.pop()
            for nxt in self.out[node]:
                if nxt in parent:
                    continue
                parent[nxt] = node
                if self.free[nxt] and nxt not in keep:
                    self._move_pebble_along(parent, nxt, start)
                    return True
                stack.append(nxt)
        return False

    def _move_pebble_along(self, parent: dict[int, int], source: int, start: int) -> None:
        self.free[source] -= 1
        self.free[start] += 1
        node = source
        while node != start:
            previous = parent[node]
            self.out[previous][node] -= 1
            if not self.out[previous][node]:
                del self.out[previous][node]
            self.out[node][previous] += 1
            node = previous


def _check_constraint_counts(bodies: _Bodies) -> None:
    game = _PebbleGame(bodies.members)
    first_surplus = None
    for bar in bodies.bars:
        u, v = bodies.body_of[bar.a], bodies.body_of[bar.b]
        for _ in range(2):  # a lower pair is two bars
            if not game.add_bar(u, v) and first_surplus is None:
                first_surplus = game.reach(u, v)
    if first_surplus is None:
        return
    mobile = [body for body in bodies.unknown
              if game.gather(_KNOWN, body, _PebbleGame.PEBBLES + 1)]
    raise ModelError(_over_constraint_message(bodies, first_surplus, mobile))


def _over_constraint_message(bodies: _Bodies, tight: set[int], mobile: list[int]) -> str:
    unknown = [body for body in tight if body != _KNOWN]
    joints = [bar.name for bar in bodies.bars
              if bodies.body_of[bar.a] in tight and bodies.body_of[bar.b] in tight]
    n, p = len(unknown), len(joints)
    if _KNOWN in tight:
        count = f"3·n = 3·{n} = {3 * n} < 2·p = 2·{p} = {2 * p} counted with the known links"
    else:
        count = f"3·(n − 1) = {3 * (n - 1)} < 2·p = {2 * p} counted among themselves"
    message = (f"over-constrained (rigid) sub-chain: {_listed('link', bodies.links_of(unknown))} "
               f"with {_listed('joint', joints)}: {count}")
    if mobile:
        message += (f"; the surplus constraint leaves {_listed('link', bodies.links_of(mobile))} "
                    "with a mobility of their own, so the chain cannot be decomposed into Assur groups")
    return message


# ---------------------------------------------------------------------------------------
# Group search
# ---------------------------------------------------------------------------------------


def _assur_groups_in_solving_order(bodies: _Bodies) -> list[tuple[frozenset[int], frozenset[int]]]:
    """Assur groups as (bodies of the group, bodies known before it), in solving order.

    Bookkeeping that keeps long chains cheap: every connected frontier set of at most
    `exhausted` bodies has been checked, except those next to the `dirty` known bodies
    (whose counts changed since), so a stage first re-checks only the sets next to them.
    """
    known, unknown = {_KNOWN}, set(bodies.unknown)
    dirty, exhausted = {_KNOWN}, 0
    order = []
    while unknown:
        search = _GroupSearch(bodies, known, unknown)
        found = search.smallest_groups(search.unknown_next_to(dirty), check_from=1, max_size=exhausted)
        if not found:
            found = search.smallest_groups(search.unknown_next_to(known), check_from=exhausted + 1,
                                           max_size=len(unknown))
            if not found:
                raise ModelError(f"{_listed('link', bodies.links_of(unknown))} left over: a sub-chain with "
                                 "a mobility of its own that cannot be decomposed into Assur groups")
            exhausted = len(found[0])
        if len(found[0]) == exhausted:  # every set next to `dirty` was checked up to `exhausted`
            dirty = set()
        before = frozenset(known)
        for group in sorted(found, key=lambda g: bodies.chain.position[bodies.links_of(g)[0]]):
            order.append((group, before))
        newly_known = set().union(*found)
        dirty |= newly_known
        known |= newly_known
        unknown -= newly_known
    return order


class _GroupSearch:
    """Connected sets of unknown bodies grown from a frontier, checked for 3·|S| = 2·p(S)."""

    def __init__(self, bodies: _Bodies, known: set[int], unknown: set[int]):
        self.bodies, self.known, self.unknown = bodies, known, unknown

    def unknown_next_to(self, group: Iterable[int]) -> set[int]:
        return {other for body in group for _, other in self.bodies.incident[body]
                if other in self.unknown}

    def pairs_counted(self, group: frozenset[int]) -> int:
        """p(S): pairs inside S and between S and the known bodies."""
        twice = sum(2 if other in self.known else 1
                    for body in group for _, other in self.bodies.incident[body]
                    if other in self.known or other in group)
        return twice // 2

    def is_group(self, group: frozenset[int]) -> bool:
        return 3 * len(group) == 2 * self.pairs_counted(group)

    def smallest_groups(self, seeds: set[int], check_from: int, max_size: int) -> list[frozenset[int]]:
        """All groups of the smallest size in [check_from, max_size] that contain a seed."""
        level = {frozenset([seed]) for seed in seeds}
        for size in range(1, max_size + 1):
            if size >= check_from and size % 2 == 0:
                groups = [group for group in level if self.is_group(group)]
                if groups:
                    return groups
            if size < max_size:
                level = {group | {other} for group in level for other in self.unknown_next_to(group)
                         if other not in group}
            if not level:
                break
        return []


# ---------------------------------------------------------------------------------------
# Describing a group
# ---------------------------------------------------------------------------------------


def _describe_group(bodies: _Bodies, members: frozenset[int], known: frozenset[int]) -> AssurGroup:
    chain = bodies.chain
    links = bodies.links_of(members)
    inside, before = set(links), set(bodies.links_of(known))
    touching = chain.joints_touching(links)
    internal = tuple(j.name for j in touching if j.a in inside and j.b in inside)
    external_joints = [j for j in touching if j.a in before or j.b in before]
    external = tuple(j.name for j in external_joints)
    inputs = set(chain.inputs)
    bars = [j for j in touching if j.a in inside and j.b in inside and j.name not in inputs]
    group_class = _group_class(members, bars, bodies.body_of)
    return AssurGroup(
        links=links,
        joints=internal + external,
        internal=internal,
        external=external,
        group_class=group_class,
        order=len(external),
        kind=_dyad_kind(bodies, members, bars, external_joints) if group_class == 2 else None,
        inputs=tuple(name for name in internal if name in inputs),
        attached_to=chain.sorted_links(j.a if j.b in inside else j.b for j in external_joints),
    )


def _group_class(members: frozenset[int], internal_bars: list[_Joint], body_of: dict[str, int]) -> int:
    import networkx as nx
    if len(members) == 2:
        return 2
    graph = nx.Graph()
    graph.add_nodes_from(members)
    graph.add_edges_from((body_of[bar.a], body_of[bar.b]) for bar in internal_bars)
    largest_contour = max((len(cycle) for cycle in nx.simple_cycles(graph)), default=0)
    if largest_contour:
        return largest_contour
    return max(degree for _, degree in graph.degree)


def _dyad_kind(bodies: _Bodies, members: frozenset[int], internal_bars: list[_Joint],
               external: list[_Joint]) -> str:
    first, second = sorted(members)
    (middle,) = internal_bars

    def outer_kind(body: int) -> str:
        (joint,) = [j for j in external if body in (bodies.body_of[j.a], bodies.body_of[j.b])]
        return joint.kind

    reading = outer_kind(first) + middle.kind + outer_kind(second)
    return max(reading, reading[::-1])


# ---------------------------------------------------------------------------------------
# Formula
# ---------------------------------------------------------------------------------------


def _structural_formula(mechanisms: Sequence[tuple[str, str]], groups: Sequence[AssurGroup]) -> str:
    parts = [f"I({driver},{driven})" for driver, driven in mechanisms]
    parts += [group.label for group in groups]
    return " → ".join(parts)


_ROMAN = ((1000, "M"), (900, "CM"), (500, "D"), (400, "CD"), (100, "C"), (90, "XC"),
          (50, "L"), (40, "XL"), (10, "X"), (9, "IX"), (5, "V"), (4, "IV"), (1, "I"))


def roman(number: int) -> str:
    """Roman numeral of a positive integer (group classes: II, III, IV, ...).

    Parameters
    ----------
    number : int
        A positive integer.

    Returns
    -------
    str
        Its Roman numeral; "" for 0 or a negative number.

    Raises
    ------
    TypeError
        Something that is not a number.

    Examples
    --------
    >>> from mbplanar.structure import roman
    >>> roman(2), roman(4), roman(14)
    ('II', 'IV', 'XIV')
    """
    digits = []
    for value, symbol in _ROMAN:
        count, number = divmod(number, value)
        digits.append(symbol * count)
    return "".join(digits)


def _names(names: Iterable[str]) -> str:
    return ", ".join(str(name) for name in names)


def _listed(what: str, names: Sequence[str]) -> str:
    """'link 5' or 'links 2, 3, 4'."""
    return f"{what}{'s' if len(names) != 1 else ''} {_names(names)}"
