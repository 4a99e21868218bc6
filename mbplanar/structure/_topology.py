"""Topology of a mechanism: the link–joint graph, its mobility, its loops and its solving blocks.

The engine solves a mechanism block by block. A block is a set of links whose pose follows from the
links solved before it (ground, input links, earlier blocks). Inside a block a spanning tree hangs every
link on a known link through one joint (its tree joint, whose variable is an unknown or, for a driving
joint, an input); the block's other joints are cut joints whose closure gives its equations. With the
Assur decomposition (`mbplanar.structure.decompose`) every group is a block; the single global block is kept as a
cross-check and fallback.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # networkx is imported where a graph is made (it costs ~0.1 s)
    import networkx as nx

from ..errors import ModelError
from ..model import Mechanism

__all__ = ["TreeJoint", "Block", "Topology", "analyse_topology", "check_mobility"]


@dataclass(frozen=True)
class TreeJoint:
    """A tree joint: it places `child` from the already placed `parent`."""

    joint: str
    parent: str
    child: str
    input: int | None  # index of the input driving it, None if its variable is unknown


@dataclass(frozen=True)
class Block:
    """Links solved together: their tree joints (in placing order), the cut joints that close them, and
    the higher pairs that close them too (a higher pair is never a tree joint: it does not place a link)."""

    links: tuple[str, ...]
    tree: tuple[TreeJoint, ...]
    cuts: tuple[str, ...]
    group: object = None  # the AssurGroup it came from, if any
    higher: tuple[str, ...] = ()

    @property
    def unknowns(self) -> tuple[TreeJoint, ...]:
        return tuple(t for t in self.tree if t.input is None)

    def counts(self, mech: Mechanism) -> tuple[int, int]:
        """(closure equations, unknowns): two per cut joint and one or two per higher pair; one per tree
        joint that is not driven and one per contact parameter of a higher pair (cam, slot)."""
        pairs = [mech.higher[name] for name in self.higher]
        return (2 * len(self.cuts) + sum(h.equations for h in pairs),
                len(self.unknowns) + sum(h.parameters for h in pairs))


@dataclass(frozen=True)
class Topology:
    """The link–joint graph of a mechanism as the engine solves it.

    `dof` its degrees of freedom; `loops` its independent loops, each as its joints in order; `blocks`
    the solving blocks in order (each a `Block`: links, tree joints, cut joints, higher pairs);
    `structure` the Assur decomposition (`Structure`), None where it could not be made.

    Examples
    --------
    >>> from mbplanar.model import read_model
    >>> from mbplanar.structure import analyse_topology
    >>> topology = analyse_topology(read_model("models/six_bar_press.toml"))
    >>> topology.dof, len(topology.loops), [block.links for block in topology.blocks]
    (1, 2, [('1',), ('2', '3'), ('4', '5')])
    """

    dof: int
    loops: tuple[tuple[str, ...], ...]  # independent loops, each as its joints in order
    blocks: tuple[Block, ...]
    structure: object = None  # mbplanar.structure.Structure when the decomposition succeeded


def link_joint_graph(mech: Mechanism) -> nx.Graph:
    """Bipartite graph: a node per link ('L', name) and per joint ('J', name)."""
    import networkx as nx
    g = nx.Graph()
    for link in mech.all_links:
        g.add_node(("L", link))
    for j in list(mech.joints.values()) + list(mech.higher.values()):
        g.add_edge(("J", j.name), ("L", j.links[0]))
        g.add_edge(("J", j.name), ("L", j.links[1]))
    return g


def mobility(mech: Mechanism) -> int:
    """Chebyshev: W = 3n − 2p₅ − p₄ for n moving links, p₅ lower pairs and p₄ higher pairs."""
    return 3 * len(mech.moving_links) - 2 * len(mech.joints) - len(mech.higher)


def independent_loops(mech: Mechanism) -> tuple[tuple[str, ...], ...]:
    import networkx as nx
    basis = nx.cycle_basis(link_joint_graph(mech), ("L", mech.ground))
    return tuple(tuple(name for kind, name in cycle if kind == "J") for cycle in basis)


def _check_connected(mech: Mechanism, g: nx.Graph):
    import networkx as nx
    reached = nx.node_connected_component(g, ("L", mech.ground))
    lost = [link for link in mech.moving_links if ("L", link) not in reached]
    if lost:
        raise ModelError(f"link(s) {', '.join(lost)} not connected to the ground '{mech.ground}' through any "
                         "joint", source=mech.source)


def _dangling(mech: Mechanism) -> list[str]:
    """The moving links held by one pair that no input drives: each adds a free degree of freedom."""
    driven = {inp.joint for inp in mech.inputs}
    return [name for name in mech.moving_links
            if len(joints := mech.joints_of(name)) == 1 and joints[0].name not in driven and not mech.higher_of(name)]


def _check_dof(mech: Mechanism, dof: int):
    n, p, p4 = len(mech.moving_links), len(mech.joints), len(mech.higher)
    dangling = _dangling(mech)
    if dangling and dof > len(mech.inputs):
        j = mech.joints_of(dangling[0])[0]
        other = j.other(dangling[0])
        raise ModelError(f"link '{dangling[0]}' hangs on one pair ({j.name}, to link '{other}'), so it swings "
                         f"freely (DOF = {dof} for {len(mech.inputs)} input(s)): give its second pair, drive "
                         f"{j.name} as an input, or make it a point of link '{other}'"
                         + (f"; links {', '.join(dangling[1:])} hang on one pair too" if dangling[1:] else ""),
                         source=mech.source, where=f"links '{dangling[0]}'")
    if dof != len(mech.inputs):
        count = (f"3·n − 2·p5 − p4 = 3·{n} − 2·{p} − {p4}, n moving links, p5 lower and p4 higher pairs" if p4
                 else f"3·n − 2·p = 3·{n} − 2·{p}, n moving links, p pairs")
        why = f"DOF = {dof} (structural count {count}), but the table has {len(mech.inputs)} input(s)"
        if dof <= 0:
            why += ": the chain is rigid or over-constrained (a missing link, or a joint too many?)"
        else:
            why += ": give one input per degree of freedom (or a missing joint?)"
        raise ModelError(why, source=mech.source)


def check_mobility(mech: Mechanism) -> int:
    """The structural DOF of a model, checked against its inputs.

    Run before the assembly, so that a rigid chain is reported as "DOF = 0", not as a drawn pose that
    misses.

    Parameters
    ----------
    mech : Mechanism
        The model.

    Returns
    -------
    int
        W = 3n − 2p₅ − p₄.

    Raises
    ------
    ModelError
        A link not connected to the ground, or a DOF other than the number of inputs: the message says
        which links, or the count.

    Examples
    --------
    >>> from mbplanar.model import read_model
    >>> from mbplanar.structure import check_mobility
    >>> check_mobility(read_model("models/five_bar.toml"))          # two inputs
    2
    """
    _check_connected(mech, link_joint_graph(mech))
    dof = mobility(mech)
    _check_dof(mech, dof)
    return dof


def build_block(mech: Mechanism, links, known: set[str], group=None) -> Block:
    """Spanning tree of `links` hung on the `known` links: driving joints first, then revolute, then
    prismatic ones (Kruskal on a union-find where every known link is one node)."""
    links = list(links)
    inside = set(links)
    input_index = {inp.joint: k for k, inp in enumerate(mech.inputs)}
    def closes(j):
        return (j.links[0] in inside or j.links[1] in inside) and all(link in inside or link in known
                                                                      for link in j.links)
    joints = [j for j in mech.joints.values() if closes(j)]
    higher = tuple(h.name for h in mech.higher.values() if closes(h))
    joints.sort(key=lambda j: (j.name not in input_index, j.kind != "R"))
    KNOWN = "<known>"
    root = {link: link for link in links}
    root[KNOWN] = KNOWN

    def find(link):
        if link in known:
            return KNOWN
        while root[link] != link:
            root[link] = root[root[link]]
            link = root[link]
        return link

    tree_edges, cuts = [], []
    for j in joints:
        a, b = find(j.links[0]), find(j.links[1])
        if a == b:
            if j.name in input_index:
                raise ModelError(f"driving joint '{j.name}' closes a loop of links whose "
                                 "motion is already fixed: the inputs are redundant", source=mech.source)
            cuts.append(j.name)
        else:
            tree_edges.append(j)
            if a == KNOWN:
                root[b] = KNOWN
            else:
                root[a] = b
    # orient the tree edges outward from the known links, in placing order
    placed, tree, pending = set(known), [], list(tree_edges)
    while pending:
        progress = False
        for j in list(pending):
            a, b = j.links
            if (a in placed) != (b in placed):
                parent, child = (a, b) if a in placed else (b, a)
                tree.append(TreeJoint(j.name, parent, child, input_index.get(j.name)))
                placed.add(child)
                pending.remove(j)
                progress = True
        if not progress:
            break
    unplaced = [link for link in links if link not in placed]
    if unplaced:
        raise ModelError(f"link(s) {', '.join(unplaced)} cannot be reached from the ground "
                         "through the joints", source=mech.source)
    return Block(tuple(links), tuple(tree), tuple(cuts), group, higher)


def _driven_links(mech: Mechanism) -> list[str]:
    """Links driven straight from the ground by an input joint (class I mechanisms)."""
    out = []
    for inp in mech.inputs:
        a, b = mech.joints[inp.joint].links
        if mech.ground in (a, b):
            out.append(b if a == mech.ground else a)
    return out


def global_blocks(mech: Mechanism) -> tuple[Block, ...]:
    """Input links as one block, every other link in one global block."""
    driven = _driven_links(mech)
    known = {mech.ground}
    blocks = []
    if driven:
        blocks.append(build_block(mech, driven, known))
        known |= set(driven)
    rest = [link for link in mech.moving_links if link not in known]
    if rest:
        blocks.append(build_block(mech, rest, known))
    return tuple(blocks)


def group_blocks(mech: Mechanism, structure) -> tuple[Block, ...]:
    """A block for the input links, then one per Assur group in solving order."""
    driven = [link for link in structure.input_links]
    known = {mech.ground}
    blocks = []
    if driven:
        blocks.append(build_block(mech, driven, known))
        known |= set(driven)
    for group in structure.groups:
        links = structure.real_links(group)
        blocks.append(build_block(mech, links, known, group))
        known |= set(links)
    return tuple(blocks)


def _replacements(mech: Mechanism) -> list[tuple[str, str, str, str, str]]:
    """Each higher pair as (name, link a, link b, kind on a, kind on b): the pairs of the link that
    replaces it in the equivalent lower-pair mechanism (`mbplanar.model._drawn.replacement`)."""
    if not mech.higher:
        return []
    from ..model import drawn_pairs, mechanism_size, replacement
    size = mechanism_size(mech)
    out = []
    for name, g in drawn_pairs(mech).items():
        (kind_a, a, _), (kind_b, b, _) = replacement(g, size).pairs
        out.append((name, a, b, kind_a, kind_b))
    return out


def analyse_topology(mech: Mechanism, grouped: bool = True) -> Topology:
    """Check the link–joint graph and split the mechanism into solving blocks.

    Parameters
    ----------
    mech : Mechanism
        The model.
    grouped : bool, optional
        True: a block per Assur group (when the mechanism decomposes); False: one global block after the
        input links.

    Returns
    -------
    Topology

    Raises
    ------
    ModelError
        The mobility check fails (`check_mobility`), the decomposition refuses the chain (`decompose`), or
        a block has other than as many closure equations as unknowns.

    Examples
    --------
    >>> from mbplanar.model import read_model
    >>> from mbplanar.structure import analyse_topology
    >>> press = read_model("models/six_bar_press.toml")
    >>> analyse_topology(press).structure.formula
    'I(0,1) → II(2,3) → II(4,5)'
    >>> [block.links for block in analyse_topology(press, grouped=False).blocks]
    [('1',), ('2', '3', '4', '5')]
    """
    dof = check_mobility(mech)
    loops = independent_loops(mech)
    structure = None
    try:
        from ._assur import decompose
    except ImportError:  # structure module not available
        decompose = None
    if decompose is not None:
        joints = [(j.name, j.kind, j.links[0], j.links[1]) for j in mech.joints.values()]
        structure = decompose(mech.ground, mech.moving_links, joints, [i.joint for i in mech.inputs],
                              _replacements(mech))
    if grouped and structure is not None:
        blocks = group_blocks(mech, structure)
    else:
        blocks = global_blocks(mech)
    for block in blocks:
        equations, unknowns = block.counts(mech)
        if equations != unknowns:
            raise ModelError(f"links {', '.join(block.links)} give {equations} closure "
                             f"equations for {unknowns} unknowns: the chain is over- or under-constrained",
                             source=mech.source)
    return Topology(dof, loops, blocks, structure)
