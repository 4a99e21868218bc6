"""Structure: the link-joint graph, degrees of freedom, loops and solving blocks (`analyse_topology`),
and the Assur-group decomposition (`decompose`, Artobolevsky).

This subpackage replaces the old module ``mbplanar.structure`` and keeps its names (`AssurGroup`,
`Structure`, `decompose`, `roman`); ``mbplanar.topology`` is a deprecated alias of
``mbplanar.structure._topology``.
"""

from .. import _deprecated
from ._assur import AssurGroup, Structure, decompose, roman
from ._topology import Topology, analyse_topology

__all__ = ["AssurGroup", "Structure", "decompose", "roman", "Topology", "analyse_topology"]

__getattr__ = _deprecated.forwarder(__name__, __name__ + "._assur")
