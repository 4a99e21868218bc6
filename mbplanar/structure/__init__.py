"""Structure: the link-joint graph, degrees of freedom, loops and solving blocks (`analyse_topology`),
and the Assur-group decomposition (`decompose`, Artobolevsky).

    >>> from mbplanar.model import read_model
    >>> from mbplanar.structure import analyse_topology
    >>> topology = analyse_topology(read_model("models/slider_crank.toml"))
    >>> topology.dof, topology.structure.formula, topology.structure.groups[0].kind
    (1, 'I(0,1) → II(2,3)', 'RRP')
"""

from ._assur import AssurGroup, Structure, decompose, roman
from ._topology import Topology, analyse_topology, check_mobility

__all__ = ["AssurGroup", "Structure", "decompose", "roman", "Topology", "analyse_topology", "check_mobility"]
