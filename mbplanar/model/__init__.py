"""The model: links, joints, points and inputs (`Mechanism`), read from a TOML table and assembled.

`read_model` / `parse_model` turn a table into a `Mechanism` (SI units inside); `assemble` closes a
sketched pose onto the exact one. The names the other subpackages build on are exported here too: the
table's declared keys (`Key`, `Section` and the sections), the units (`DisplayUnits`, `LENGTH_UNITS`, ...),
the one scale rule (`warn_scale`, `out_of_scale`), the higher pairs' curves (`Shape`, `Circle`, `Spline`,
`Offset`) and drawn geometry (`drawn_pairs`), and the parametrised tables (`Template`).

    >>> from mbplanar.model import read_model
    >>> mech = read_model("models/fourbar.toml")
    >>> sorted(mech.joints), mech.units.length
    (['A', 'B', 'C', 'O'], 'm')
"""

from .._lazy import lazy_attributes
from ._assembly import assemble, reference_points, translated
from ._curves import Circle, Offset, Shape, Spline
from ._drawn import PairGeometry, drawn_pairs, mechanism_size, replacement
from ._keys import (CLEARANCE, DOCUMENT, HIGHER, JOINT, LOADS, MISSING, PARAMETER, SECTIONS, TOLERANCE, TOLERANCES,
                    UNITS, Key, Section)
from ._model import (ANGLE_UNITS, ELEMENT_TYPES, LENGTH_UNITS, LOAD_TYPES, RHO_STEEL, Curve, DynamicsSpec,
                     FlywheelSpec, Gravity, HigherPair, Input, Joint, Link, Load, Mechanism, Point, Units,
                     unit_spelling)
from ._scale import check_far, drawing_size, frame_origin, out_of_scale, scale_message, warn_scale
from ._table import Row, crank_input, parse_model, read_model, read_model_text, read_text
from ._units import SYSTEMS, DisplayUnits, add_units_option, convert_table, display_units

__all__ = ["Link", "Joint", "HigherPair", "Curve", "Point", "Input", "Mechanism", "Units", "Load", "Gravity",
           "FlywheelSpec", "DynamicsSpec", "read_model", "read_model_text", "read_text", "parse_model", "Row",
           "assemble", "reference_points", "translated", "crank_input", "drawing_size", "out_of_scale",
           "scale_message", "warn_scale", "frame_origin", "check_far", "add_units_option", "DisplayUnits",
           "display_units", "convert_table", "SYSTEMS", "LENGTH_UNITS", "ANGLE_UNITS", "unit_spelling",
           "LOAD_TYPES", "ELEMENT_TYPES", "RHO_STEEL", "Key", "Section", "MISSING", "UNITS", "DOCUMENT", "JOINT",
           "HIGHER", "LOADS", "PARAMETER", "TOLERANCE", "CLEARANCE", "TOLERANCES", "SECTIONS", "Shape", "Circle",
           "Spline", "Offset", "PairGeometry", "drawn_pairs", "replacement", "mechanism_size", "Parameter",
           "Template", "higher_rows", "view"]

#: public name → the private module defining it, imported on first use (PEP 562): the parametrised
#: tables and the views of a result are not needed to read and solve a model
_LAZY = {"Parameter": "_parameters", "Template": "_parameters", "higher_rows": "_parameters", "view": "_views"}


__getattr__, __dir__ = lazy_attributes(__name__, _LAZY)
