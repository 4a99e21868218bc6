"""The engine: loop-closure equations solved by block Newton–Raphson, rates, branch continuation (the
atlas) and singular positions.

`Engine(mechanism)` compiles a mechanism once; `solve_positions`, `Engine.solve_limits`, `Engine.rates` and
`Engine.atlas` answer for batches of input values (the layers above use them; users call `analyse`).
"""

from ._atlas import FAR_TURNS, LOST_PRECISION
from ._solver import Crossing, Engine, Limit, Solution, solve_positions
from ._tolerances import Tolerances

__all__ = ["Engine", "Tolerances", "Solution", "Limit", "Crossing", "solve_positions", "FAR_TURNS", "LOST_PRECISION"]
