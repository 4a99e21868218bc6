"""The model: links, joints, points and inputs (`Mechanism`), read from a TOML table and assembled.

`read_model` / `parse_model` turn a table into a `Mechanism` (SI units inside); `assemble` closes a
sketched pose onto the exact one.
"""

from ._assembly import assemble, reference_points
from ._model import Curve, HigherPair, Input, Joint, Link, Mechanism, Point, Units
from ._scale import drawing_size, warn_scale
from ._table import crank_input, parse_model, read_model, read_model_text
from ._units import add_units_option

__all__ = ["Link", "Joint", "HigherPair", "Curve", "Point", "Input", "Mechanism", "Units", "read_model",
           "read_model_text", "parse_model", "assemble", "reference_points", "crank_input", "drawing_size",
           "warn_scale", "add_units_option"]
