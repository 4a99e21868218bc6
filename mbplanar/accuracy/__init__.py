"""The accuracy of mechanisms: how toleranced dimensions and joint clearances move every point, link angle
and joint value over the cycle (docs/accuracy.md).

- `read_tolerances`, `Tolerance`, `Clearance`, `ToleranceSpec`: a model's `[tolerances]` section;
- `DesignSpace`, `Dimension`, `catalogue`: what each toleranced dimension means, the made geometry;
- `sensitivities`: exact ∂(outputs)/∂(dimensions) over the cycle from the loop equations' Jacobian;
- `stack`: worst-case and statistical (root sum of squares) errors, each dimension's share;
- `monte_carlo`: seeded samples through the design batch, failures and their causes;
- `clearance_errors`: clearances taken up along the reactions (effective links), knocks;
- `accuracy`: all of it for a model file, as one `Accuracy` record.

    >>> import mbplanar.accuracy as acc
    >>> result = acc.accuracy("models/fourbar.toml", samples=1000, positions=36)
    >>> [o.name for o in result.outputs]
    ['M.x', 'M.y', '3.angle']
    >>> result.stack.share.shape, result.monte_carlo.count
    ((3, 7), 1000)
"""

from .clearance import ClearanceErrors, clearance_errors
from .geometry import DesignSpace, Dimension, Sided, catalogue
from .montecarlo import Cause, MonteCarlo, draw, monte_carlo
from .run import Accuracy, accuracy, cycle
from .sensitivity import Output, Sensitivities, resolve_outputs, sensitivities
from .spec import Clearance, Tolerance, ToleranceSpec, read_tolerances
from .stacks import Stack, stack

__all__ = ["Tolerance", "Clearance", "ToleranceSpec", "read_tolerances", "DesignSpace", "Dimension", "Sided",
           "catalogue", "Output", "Sensitivities", "resolve_outputs", "sensitivities", "Stack", "stack",
           "MonteCarlo", "Cause", "draw", "monte_carlo", "ClearanceErrors", "clearance_errors", "Accuracy",
           "accuracy", "cycle"]
