"""Formats: the table's JSON Schema, importers from the peers' files, the mechanism as CAD, the bundled
examples.

- `model_schema()`: the JSON Schema of a model file, generated from the keys the readers declare
  (shipped as `model.schema.json`, printed by ``mbplanar schema``);
- `import_model(path)`, `import_object(obj)`: a Pyslvs expression or project, a PMKS+ CSV file or link,
  a pylinkage JSON file or live object as an mbplanar model (``mbplanar import``);
- `drawing(engine, phi)`, `export_drawing(engine, phi, path)`: the mechanism at one position as CAD
  geometry on named layers, DXF or SVG (``mbplanar export``);
- `list_examples()`, `example_text(name)`, `copy_examples(names, directory)`: the bundled models
  (``mbplanar examples``), in the folder `examples_folder()`.

Each name is imported on first use.
"""

from .._lazy import lazy_attributes

__all__ = ["model_schema", "import_model", "import_object", "Imported", "drawing", "export_drawing",
           "list_examples", "example_text", "copy_examples", "Example", "examples_folder"]

_HOME = {"model_schema": "schema", "import_model": "importing", "import_object": "importing",
         "Imported": "importing", "drawing": "sheet", "export_drawing": "sheet",
         "list_examples": "examples", "example_text": "examples", "copy_examples": "examples",
         "Example": "examples", "examples_folder": "examples"}


__getattr__, __dir__ = lazy_attributes(__name__, _HOME)
