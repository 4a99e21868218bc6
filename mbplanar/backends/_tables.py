"""Names numba's on-disk cache indexes may hold: the kernels' tables are the engine's
(`mbplanar.engine._tables`) and the kinetostatics program's loads the forces layer's
(`mbplanar.forces._program`). Indexes written before they moved there name them here: importable, they
unpickle, and the cache sees its stamp is old and compiles again (else it fails).
"""

from __future__ import annotations

from ..engine import BlockTables, CutTables, JointTables, StepTables  # noqa: F401

__all__: list = []
