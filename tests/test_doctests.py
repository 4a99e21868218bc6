"""The docstrings' examples run (as ``pytest --doctest-modules`` would run them, here inside the README's test
command): the package's, every subpackage's and every module that defines a public name; and every name
of the public API (`mbplanar.__all__`) has a numpydoc docstring with its sections and a runnable example."""

from __future__ import annotations

import doctest
import importlib
import inspect

import pytest

import mbplanar

from conftest import MODELS

ROOT = MODELS.parent
SUBPACKAGES = ("model", "structure", "engine", "kinematics", "forces", "backends", "analysis", "io", "viz", "cam",
               "study", "accuracy", "synthesis", "gears", "formats", "web")
#: subpackages whose public names do not all have their numpydoc docstring yet; one per line, removed as each
#: is completed (issue 29, item 7)
DOCS_YET: set = set()


#: public modules outside the subpackages' `__all__`: the commands' work, which the command line calls
COMMAND_MODULES = ("mbplanar.io.commands", "mbplanar.io.sweep", "mbplanar.io.inputs", "mbplanar.kinematics.plan",
                   "mbplanar.viz.command")


def public_modules() -> list[str]:
    """The package, its subpackages, the modules that define their public names, and `COMMAND_MODULES`."""
    found = {"mbplanar", "mbplanar.errors", *COMMAND_MODULES}
    for name in SUBPACKAGES:
        package = importlib.import_module(f"mbplanar.{name}")
        found.add(package.__name__)
        for public in package.__all__:
            home = getattr(getattr(package, public), "__module__", None)
            if home and home.startswith("mbplanar."):
                found.add(home)
    return sorted(found)


@pytest.mark.parametrize("module", public_modules())
def test_docstring_examples_run(module, monkeypatch):
    """Each module's examples, from the repository's root (they read ``models/...``)."""
    monkeypatch.chdir(ROOT)
    imported = importlib.import_module(module)
    finder = doctest.DocTestFinder(exclude_empty=True)
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE | doctest.ELLIPSIS)
    for test in finder.find(imported, module):
        if test.examples:
            runner.run(test, out=lambda text: None)
    results = runner.summarize(verbose=False)
    assert results.failed == 0, f"{module}: {results.failed} of {results.attempted} examples failed " \
                                f"(python -m pytest --doctest-modules {module.replace('.', '/')}.py says which)"
    if module == "mbplanar":
        assert results.attempted >= 10  # the package docstring's tour


def _sections(obj) -> dict:
    from numpydoc.docscrape import ClassDoc, FunctionDoc
    return (ClassDoc if inspect.isclass(obj) else FunctionDoc)(obj, config={"show_class_members": False})


def _public_functions_of_command_modules() -> list[str]:
    """"module:name" of every public function of `COMMAND_MODULES`, and of the io documents they added."""
    found = [f"{m}:{n}" for m in COMMAND_MODULES for n in importlib.import_module(m).__all__
             if inspect.isfunction(getattr(importlib.import_module(m), n))]
    return found + [f"mbplanar.io:{n}" for n in ("simulate_document", "simulate_table", "balance_document")]


def _public_names_of_subpackages() -> list:
    """"mbplanar.sub:name" of every class and function a subpackage exports, as pytest params (those of the
    subpackages in `DOCS_YET` expected to fail)."""
    found = []
    for sub in SUBPACKAGES:
        package = importlib.import_module(f"mbplanar.{sub}")
        for name in package.__all__:
            if inspect.isclass(getattr(package, name)) or inspect.isfunction(getattr(package, name)):
                marks = [pytest.mark.xfail(reason="not yet documented")] if sub in DOCS_YET else []
                found.append(pytest.param(f"mbplanar.{sub}:{name}", marks=marks))
    return found


@pytest.mark.parametrize("name", mbplanar.__all__ + _public_functions_of_command_modules()
                         + _public_names_of_subpackages())
def test_public_names_have_numpydoc_docstrings_with_examples(name):
    """A function: Parameters, Returns, Raises and Examples; a class: Examples (its fields described in
    its docstring); every example with ``>>>`` (run by the test above)."""
    pytest.importorskip("numpydoc")
    module, _, name = name.rpartition(":")
    obj = getattr(importlib.import_module(module or "mbplanar"), name)
    doc = _sections(obj)
    assert any(">>>" in line for line in doc["Examples"]), f"{name}: no Examples section"
    if inspect.isclass(obj):
        return
    documented = {part.strip().lstrip("*") for p in doc["Parameters"] for part in p.name.split(",")}  # **kw as **kw
    wanted = {p for p in inspect.signature(obj).parameters if p not in ("self", "args", "kwargs")}
    assert wanted <= documented, f"{name}: parameters without a description: {sorted(wanted - documented)}"
    assert doc["Returns"], f"{name}: no Returns section"
    assert doc["Raises"], f"{name}: no Raises section"
