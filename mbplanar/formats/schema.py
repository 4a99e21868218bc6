"""The JSON Schema of the model table, generated from the keys the readers declare.

The table reader (`mbplanar.model._table`), the cam's (`mbplanar.cam.spec`), the gears' (`mbplanar.gears.spec`)
and the forces' sections (`[friction]`, `[simulate]`) read their keys through `Section`s of `Key`s
(`mbplanar.model._keys`);
`model_schema` turns those very sections into a JSON Schema (draft-07, the dialect editors read): every section, key, type,
unit (in the description and as "x-unit"), default and bound. The package ships it as
`mbplanar/formats/model.schema.json` (a test holds the file equal to this function's output), and
``mbplanar schema`` prints it. An editor that reads JSON Schemas for TOML (taplo, Even Better TOML)
completes and checks a model file that names it on its first line::

    #:schema ./model.schema.json
"""

from __future__ import annotations

import json
from importlib import resources

from ..model import DOCUMENT, HIGHER, JOINT, LOADS, MISSING, PARAMETER, UNITS, Key, Section

__all__ = ["model_schema", "schema_text", "SCHEMA_FILE", "sections"]

SCHEMA_FILE = "model.schema.json"   # beside this module, in the package
DRAFT = "http://json-schema.org/draft-07/schema#"   # the dialect taplo and VS Code read


def sections() -> dict[str, Section]:
    """Every section of the format by name: the model's, the cam's, the forces'."""
    from ..cam.spec import CAM, CAM_DYNAMICS, CAM_EVENT, CAM_FILE, CAM_PHASE
    from ..forces import FRICTION, FRICTION_PAIR, SIMULATE
    from ..gears.spec import GEARS, GEARS_PAIR, GEARS_PLANETARY
    from ..model import SECTIONS
    return {**SECTIONS, **{s.name: s for s in (CAM, CAM_PHASE, CAM_EVENT, CAM_DYNAMICS, CAM_FILE, FRICTION,
                                                 FRICTION_PAIR, SIMULATE, GEARS, GEARS_PAIR, GEARS_PLANETARY)}}


def model_schema() -> dict:
    """The JSON Schema of a model file (or of a cam file that names its model), as ``mbplanar schema``
    prints it and `model.schema.json` ships it.

    Generated from the keys the readers declare (`mbplanar.model`'s key tables), so an editor can check
    and complete a model file as it is typed.

    Returns
    -------
    dict
        The schema (draft 2020-12).

    Raises
    ------
    ValueError
        A key declared with a kind the schema has no rule for (a programming error, caught by the
        tests).

    Examples
    --------
    >>> import tomllib
    >>> import jsonschema
    >>> from mbplanar.formats import model_schema
    >>> schema = model_schema()
    >>> schema["title"], "joints" in schema["properties"]
    ('mbplanar model table', True)
    >>> jsonschema.validate(tomllib.load(open("models/fourbar.toml", "rb")), schema)    # no error
    """
    every = sections()
    defs: dict[str, dict] = {}

    def ref(section) -> dict:
        section = every[section] if isinstance(section, str) else section
        if section.name not in defs:
            defs[section.name] = {}            # (placeholder: a section may refer to itself)
            defs[section.name] = _object(section, value_of)
        return {"$ref": f"#/definitions/{section.name}"}

    def value_of(key: Key, section: Section) -> dict:
        if section is DOCUMENT and key.name == "joints":   # a lower pair's row, or a higher pair's by its type
            for kind in (JOINT, *HIGHER.values()):
                ref(kind)
                free = f"{kind.name}_named"
                if free not in defs:
                    defs[free] = dict(_object(kind, value_of), required=[k.name for k in kind.keys
                                                                         if k.required and k.name != "name"])

            def by_type(suffix: str) -> dict:       # each row checked against its type's section
                higher = {"properties": {"type": {"enum": list(HIGHER)}}, "required": ["type"]}
                rules = [{"if": {"properties": {"type": {"const": kind}}, "required": ["type"]},
                          "then": {"$ref": f"#/definitions/{section.name}{suffix}"}} for kind, section in HIGHER.items()]
                return {"allOf": rules + [{"if": {"not": higher}, "then": {"$ref": f"#/definitions/{JOINT.name}{suffix}"}}]}
            return {"type": ["array", "object"], "items": by_type(""), "additionalProperties": by_type("_named")}
        if key.kind == "table":
            return ref(key.section)
        if key.kind == "rows":
            rows = {"type": "array", "items": ref(key.section)}
            if not key.named:
                return rows
            named = every[key.section] if isinstance(key.section, str) else key.section
            free = f"{named.name}_named"
            if free not in defs:           # [links.2] style: the table's key is the row's name
                defs[free] = dict(_object(named, value_of), required=[k.name for k in named.keys
                                                                      if k.required and k.name != "name"])
            return {"type": ["array", "object"], "items": rows["items"],       # (a list, or named tables)
                    "additionalProperties": {"$ref": f"#/definitions/{free}"}}
        if section is DOCUMENT and key.name == "loads":
            return {"type": "array", "items": {"oneOf": [ref(s) for s in LOADS.values()]}}
        if section is DOCUMENT and key.name == "parameters":
            return {"type": "object", "additionalProperties": {"anyOf": [{"type": "number"}, ref(PARAMETER)]}}
        return _value(key)

    for kind, section in LOADS.items():   # each load row says its type: one definition per type
        ref(section)
        defs[section.name]["properties"]["type"] = {"const": kind, "description": f"{kind}: {section.doc}"}
    top = _object(DOCUMENT, value_of)
    top.pop("required")                  # (a model needs joints, a cam file a [cam]: below)
    cam_file = every["cam_file"]
    top.pop("description")
    schema = {"$schema": DRAFT, "title": "mbplanar model table",
              "description": "A planar mechanism as a table of kinematic pairs (docs/format.md), or a cam file "
                             "whose [cam] names its model (docs/cam.md). Generated from the keys mbplanar's "
                             "readers declare.", **top,
              "anyOf": [{"required": ["joints"], "oneOf": [{"required": ["input"]}, {"required": ["inputs"]}]},
                        {"required": ["cam"], "propertyNames": {"enum": sorted(cam_file.names)}}],
              "definitions": {name: defs[name] for name in sorted(defs)}}
    return schema


def _object(section: Section, value_of) -> dict:
    out = {"type": "object", "description": section.doc,
           "properties": {k.name: value_of(k, section) for k in section.keys},
           "additionalProperties": False}
    required = [k.name for k in section.keys if k.required]
    if required:
        out["required"] = required
    out.update(section.extra)
    return out


def _value(key: Key) -> dict:
    """The JSON Schema of one key's value, with its description, unit and default."""
    kind = key.kind
    name = {"type": ["string", "integer"]}
    if key.schema is not None:
        out = dict(key.schema)
    elif kind == "text":
        out = dict(name)
    elif kind in ("number", "integer"):
        out = {"type": kind}
        if key.positive:
            out["exclusiveMinimum"] = 0
        if key.minimum is not None and not (key.positive and key.minimum == 0):
            out["exclusiveMinimum" if key.exclusive else "minimum"] = key.minimum
        if key.maximum is not None:
            out["exclusiveMaximum" if key.exclusive else "maximum"] = key.maximum
        if key.nonzero:
            out["not"] = {"const": 0}
        if key.parameter:
            out = {"anyOf": [out, {"type": "string", "description": "the name of a [parameters] entry"}]}
    elif kind == "boolean":
        out = {"type": "boolean"}
    elif kind == "choice":
        out = {"enum": list(key.choices)}
    elif kind == "pair":
        out = {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}
    elif kind == "names":
        out = {"type": "array", "items": name, "minItems": key.count, "maxItems": key.count}
    elif kind == "numbers":
        out = {"type": "array", "items": {"type": "number"}}
    elif kind == "any":
        out = {}
    else:
        raise ValueError(f"key '{key.name}': no JSON Schema for kind {kind!r}")
    words = [key.doc]
    if key.unit:
        words.append(f"unit: {UNITS[key.unit]}")
    if key.default_doc:
        words.append(f"default: {key.default_doc}")
    elif key.default is not MISSING:
        words.append(f"default: {json.dumps(key.default)}")
    if key.required:
        words.append("required")
    out["description"] = "; ".join(words)
    if key.unit:
        out["x-unit"] = key.unit
    if key.default is not MISSING:
        out["default"] = key.default
    return out


def schema_text() -> str:
    """The shipped schema file's text (what `mbplanar schema` prints)."""
    return resources.files(__package__).joinpath(SCHEMA_FILE).read_text(encoding="utf-8")


def render(schema: dict) -> str:
    """The schema as the file holds it: indented JSON, keys in their order, a final newline."""
    return json.dumps(schema, indent=2, ensure_ascii=False) + "\n"


if __name__ == "__main__":                 # python -m mbplanar.formats.schema: write the shipped file again
    target = resources.files(__package__).joinpath(SCHEMA_FILE)
    with resources.as_file(target) as path:
        path.write_text(render(model_schema()), encoding="utf-8")
    print(f"wrote {target}")
