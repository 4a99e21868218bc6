"""The model: links, joints, points and inputs (`Mechanism`), read from a TOML table and assembled.

`read_model` / `parse_model` turn a table into a `Mechanism` (SI units inside); `assemble` closes a
sketched pose onto the exact one.

This subpackage replaces the old module ``mbplanar.model`` and keeps its names; ``mbplanar.table`` and
``mbplanar.assembly`` are deprecated aliases of ``mbplanar.model._table`` and ``mbplanar.model._assembly``.
"""

from ._assembly import assemble, reference_points
from ._model import Input, Joint, Link, Mechanism, Point
from ._table import parse_model, read_model, read_model_text

__all__ = ["Link", "Joint", "Point", "Input", "Mechanism", "read_model", "read_model_text", "parse_model",
           "assemble", "reference_points"]

from .. import _deprecated  # noqa: E402  (after the names: the forwarder serves only the old module's others)

__getattr__ = _deprecated.forwarder(__name__, __name__ + "._model")
