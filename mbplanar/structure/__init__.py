"""Structure: the link-joint graph, degrees of freedom, loops and solving blocks (`analyse_topology`),
and the Assur-group decomposition (`decompose`, Artobolevsky).
"""

from ._assur import AssurGroup, Structure, decompose, roman
from ._topology import Topology, analyse_topology, check_mobility

__all__ = ["AssurGroup", "Structure", "decompose", "roman", "Topology", "analyse_topology", "check_mobility"]
