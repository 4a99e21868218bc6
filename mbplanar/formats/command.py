"""The command line of the formats: ``mbplanar schema``, ``import``, ``export`` and ``examples`` (their
options and what they print; the work is in the modules beside this one)."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

from ..errors import ModelError

__all__ = ["add_arguments", "run"]

def add_arguments(name: str, s) -> None:
    """The options of command `name` on its parser `s`."""
    if name == "schema":
        s.add_argument("-o", "--output", help="write the schema to this file instead of printing it")
    elif name == "import":
        from .importing import FORMATS
        s.add_argument("file", help="the peer's file: .txt (Pyslvs expression, PMKS+ link), .pyslvs/.yml, .csv, "
                                    ".pmks, .json")
        s.add_argument("-o", "--output", help="MODEL.toml (default: print the model)")
        s.add_argument("--from", dest="fmt", choices=tuple(FORMATS), help="the file's format (default: from its "
                                                                          "suffix and text)")
    elif name == "export":
        s.add_argument("model")
        s.add_argument("--at", help="the input value(s), comma-separated, in the inputs' units (default: the drawn "
                                    "pose)")
        s.add_argument("-o", "--output", required=True, help="FILE.dxf or FILE.svg")
        s.add_argument("--paths", help="joints or points whose paths over the input's sweep are drawn, comma-"
                                       "separated (default: the points of interest that are not centres of mass; "
                                       "'' for none)")
        s.add_argument("--steps", type=int, default=360, help="positions along each path (default 360)")
    elif name == "examples":
        s.add_argument("names", nargs="*", metavar="NAME", help="examples to copy out (default: list them)")
        s.add_argument("-o", "--output", metavar="DIR", help="copy into this folder (every example when no NAME)")
        s.add_argument("--json", action="store_true", help="the list as JSON")
        s.add_argument("--force", action="store_true", help="replace files that exist")


def run(name: str, args) -> int:
    return {"schema": _schema, "import": _import, "export": _export, "examples": _examples}[name](args)


def _schema(args) -> int:
    from .schema import schema_text
    text = schema_text()
    if args.output:
        Path(args.output).write_text(text, encoding="utf-8")
    else:
        sys.stdout.write(text)
    return 0


def _notes(notes, source) -> None:
    for note in notes:
        print(f"mbplanar: {source}: note: {note}", file=sys.stderr)


def _import(args) -> int:
    from .importing import import_model
    result = import_model(args.file, args.fmt)
    if args.output:
        Path(args.output).write_text(result.text, encoding="utf-8")
    else:
        sys.stdout.write(result.text)
    _notes(result.notes, args.file)
    return 0


def _values(engine, text) -> list[float]:
    """--at: one finite value per input, in its unit."""
    try:
        values = [float(v) for v in str(text).split(",")]
    except ValueError:
        values = [math.nan]
    if len(values) != len(engine.inputs) or not all(math.isfinite(v) for v in values):
        raise ModelError(f"--at needs {len(engine.inputs)} finite value(s) separated by commas "
                         f"({', '.join(i.name for i in engine.inputs)})")
    return values


def _export(args) -> int:
    import numpy as np
    from ..engine import load_engine
    from .sheet import export_drawing
    if args.steps < 1:
        raise ModelError(f"--steps must be a positive whole number, got {args.steps}")
    engine = load_engine(args.model, backend="numpy", use_cache=not getattr(args, "no_cache", False))
    if args.at is None:
        phi = np.asarray(engine.phi_drawn, float)
    else:
        phi = np.array([inp.to_si(v) for inp, v in zip(engine.inputs, _values(engine, args.at))])
    mech = engine.mech
    if args.paths is None:
        centres = {link.centre for link in mech.links.values()}
        paths = [p for p in mech.points if p not in centres and not p.endswith(":centre")]
    else:
        paths = [p.strip() for p in args.paths.split(",") if p.strip()]
    sheet = export_drawing(engine, phi, args.output, paths=paths, steps=args.steps)
    layers = sorted({layer for _, layer, _ in sheet.entities})
    print(f"{args.output}: {mech.name} drawn in {sheet.unit} on layers {', '.join(layers)}"
          + (f"; paths of {', '.join(paths)}" if paths else ""))
    return 0


def _examples(args) -> int:
    from .examples import copy_examples, list_examples
    if not args.names and not args.output:
        found = list_examples()
        if args.json:
            print(json.dumps([{"name": e.name, "file": e.file, "kind": e.kind, "title": e.title} for e in found],
                             indent=2, ensure_ascii=False))
            return 0
        width = max(len(e.name) for e in found)
        for e in found:
            print(f"{e.name:{width}s}  {e.kind:9s}  {e.title}")
        return 0
    written = copy_examples(args.names, args.output or ".", overwrite=args.force)
    for path in written:
        print(path)
    return 0
