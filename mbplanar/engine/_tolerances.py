"""The engine's tuning constants: tolerances, step sizes and thresholds of the block Newton, the
continuation and the singular-position solvers (lengths relative to the mechanism's size, angles in
rad)."""

import math

__all__ = ["TOL", "TOL_FINE", "MAX_NEWTON", "H_START", "H_MAX", "H_MIN", "H_DENSE", "MAX_CORRECTION", "RATE_JUMP",
           "H_CROSS", "CROSS_DIST", "PIVOT_POLISH", "PIVOT_CROSS", "FOLD_ITERATIONS", "FOLD_DELTA", "FOLD_STEP",
           "FOLD_SQRT_LAW"]

TOL = 1e-13          # closure residual (lengths relative to the mechanism's size)
TOL_FINE = 1e-14     # while some position still needs a step, the others below TOL are polished to this
MAX_NEWTON = 14
H_START = math.radians(6.0)   # first continuation step (relative to the input's scale)
H_MAX = math.radians(15.0)
H_MIN = 1e-10
H_DENSE = math.radians(1.0)   # widest atlas interval the predictor interpolates over (see _Atlas._densify)
MAX_CORRECTION = 0.05  # largest accepted corrector distance (rad, or lengths / size)
RATE_JUMP = 0.25       # largest accepted change of the unknowns' derivatives against their prediction,
                       # relative to 1 + |q'|: a larger one means the corrector found another branch
H_CROSS = 2e-2         # widest step across a change point (relative to the input's scale); the nodes
                       # that bracket it are half of it away, where the Jacobian is still well enough
                       # conditioned for rates to ~1e-12
CROSS_DIST = 1e-6      # largest corrector distance of a step across a change point
PIVOT_POLISH = 0.05    # below this pivot ratio a converged position gets one more Newton step
PIVOT_CROSS = 1e-9     # nodes on either side of a change point must be at least this far from singular
FOLD_ITERATIONS = 8
FOLD_DELTA = 1e-6    # central-difference step of the augmented Jacobian (scaled unknowns, s)
FOLD_STEP = 1e-14    # converged when a Newton step moves no scaled unknown and s by more than this
FOLD_SQRT_LAW = 0.1  # largest relative departure from the square-root law between a node and its fold
