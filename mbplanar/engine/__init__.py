"""The engine: loop-closure equations solved by block Newton–Raphson, rates, branch continuation (the
atlas) and singular positions.

`Engine(mechanism)` compiles a mechanism once; `Engine.solve`, `Engine.solve_limits`, `Engine.rates` and
`Engine.atlas` answer for batches of input values. ``mbplanar.solver``, ``mbplanar.constraints`` and
``mbplanar._linalg`` are deprecated aliases of the modules here.
"""

from ._solver import Crossing, Engine, Limit, Solution
from ._tolerances import Tolerances

__all__ = ["Engine", "Tolerances", "Solution", "Limit", "Crossing"]
