"""Re-dimensioning a compiled engine (`Engine.with_dimensions`), as the study names it."""

from ..engine import same_structure, with_dimensions

__all__ = ["with_dimensions", "same_structure"]
