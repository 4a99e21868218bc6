"""Sphinx configuration of the mbplanar documentation (MyST Markdown pages, numpydoc docstrings).

Small directives are defined here rather than in an extra dependency:

* ``mbplanar-cli`` writes the command-line reference from ``mbplanar.cli.build_parser()`` at build time, so
  the page always matches the parser;
* ``mbplanar-api`` writes an autosummary table and the autodoc entries of every name in
  ``mbplanar.__all__`` and in each subpackage's ``__all__``, so the reference follows the code wherever its
  modules live;
* ``mbplanar-if-page`` links pages only where they exist (pages other work adds), so that the site builds
  with warnings as errors either way.
"""

from __future__ import annotations

import importlib
import inspect
import os
import pkgutil
import sys
from pathlib import Path

from docutils import nodes
from docutils.statemachine import StringList
from sphinx.util.docutils import SphinxDirective
from sphinx.util.nodes import nested_parse_with_titles

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import mbplanar  # noqa: E402

project = "mbplanar"
author = "mbplanar contributors"
copyright = "2026, mbplanar contributors"
release = version = mbplanar.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
]
source_suffix = {".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "**.ipynb_checkpoints", "Thumbs.db", ".DS_Store"]
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
suppress_warnings = ["myst.header",        # a page may skip a heading level
                    "misc.highlighting_failure"]   # a block that is not quite its language (an excerpt)

autosummary_generate = False
autodoc_member_order = "bysource"
autodoc_typehints = "none"
autodoc_default_options = {"members": False}
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks: set = set()

html_theme = "alabaster"
html_title = "mbplanar"
html_static_path: list = []
# The pages link the repository's files (models, notebook) with relative paths: they are copied as downloads.
html_extra_path: list = []


class CliReference(SphinxDirective):
    """The reference of every command, written from the argument parser."""

    def run(self):
        from mbplanar.cli import build_parser
        os.environ["COLUMNS"] = "100"            # argparse wraps its help to this width
        parser = build_parser()
        lines = ["Global options", "--------------", "", ".. code-block:: text", ""]
        lines += ["    " + ln for ln in parser.format_help().splitlines()] + [""]
        for action in parser._subparsers._group_actions:
            for name, sub in action.choices.items():
                title = f"mbplanar {name}"
                lines += [title, "-" * len(title), ""]
                helps = {a.dest: a.help for a in action._choices_actions}
                if helps.get(name):
                    lines += [helps[name][0].upper() + helps[name][1:] + ".", ""]
                lines += [".. code-block:: text", ""] + ["    " + ln for ln in sub.format_help().splitlines()] + [""]
        return _parse(self, lines)


class ApiReference(SphinxDirective):
    """An autosummary table and the autodoc entry of every public name: first ``mbplanar.__all__``, then, per
    subpackage, the names its ``__all__`` adds (so the reference follows the code wherever it moves)."""

    def run(self):
        seen = {id(getattr(mbplanar, n)) for n in mbplanar.__all__}
        lines = _api_lines("mbplanar", list(mbplanar.__all__))
        for info in sorted(pkgutil.iter_modules(mbplanar.__path__), key=lambda m: m.name):
            if not info.ispkg or info.name.startswith("_"):
                continue
            module = importlib.import_module(f"mbplanar.{info.name}")
            names = [n for n in getattr(module, "__all__", []) if id(getattr(module, n)) not in seen
                     and (inspect.isclass(getattr(module, n)) or callable(getattr(module, n)))]
            seen |= {id(getattr(module, n)) for n in names}
            if names:
                title = f"mbplanar.{info.name}"
                doc = (inspect.getdoc(module) or "").split("\n\n")[0]
                lines += [title, "-" * len(title), "", doc, ""] + _api_lines(title, names)
        return _parse(self, lines)


def _api_lines(module: str, names) -> list:
    """reST of an autosummary table and the autodoc entries of `names` of `module`."""
    target = importlib.import_module(module)
    lines = [f".. currentmodule:: {module}", "", ".. autosummary::", ""] + [f"   {n}" for n in names] + [""]
    for n in names:
        kind = "autoclass" if inspect.isclass(getattr(target, n)) else "autofunction"
        lines += [f".. {kind}:: {n}"] + (["   :members:"] if kind == "autoclass" else []) + [""]
    return lines


class IfPage(SphinxDirective):
    """Its content, and with ``:list:`` links to the pages, only for those of the named pages that exist.

    Pages written alongside this one (a cam tutorial, the units page) are linked where they are present,
    so that the site builds with warnings as errors either way.
    """

    required_arguments = 1
    optional_arguments = 20
    has_content = True
    option_spec = {"list": lambda arg: True}

    def run(self):
        present = [name for name in self.arguments if name in self.env.found_docs]
        if not present:
            return []
        lines = list(self.content) + [""]
        if "list" in self.options:
            lines += [f"- :doc:`{name}`" for name in present] + [""]
        return _parse(self, lines)


def _parse(directive, lines):
    node = nodes.container()
    nested_parse_with_titles(directive.state, StringList(lines, "<mbplanar-docs>"), node)
    return node.children


def _plain_bars(app, what, name, obj, options, lines):
    """Docstrings write |x| for a magnitude; reST would read it as a substitution. Escape bars outside
    tables and line blocks (lines that start with a bar or a plus sign)."""
    for k, line in enumerate(lines):
        if "|" in line and not line.lstrip().startswith(("|", "+")):
            lines[k] = line.replace("\\|", "|").replace("|", "\\|")


def setup(app):
    app.connect("autodoc-process-docstring", _plain_bars, priority=600)
    app.add_directive("mbplanar-cli", CliReference)
    app.add_directive("mbplanar-api", ApiReference)
    app.add_directive("mbplanar-if-page", IfPage)
    return {"parallel_read_safe": True}
