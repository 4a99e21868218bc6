"""The package layout: subpackages export their names, imports run one way (model → structure → engine →
kinematics → forces → backends → analysis → io, viz → cam → cli), and the module paths of the old flat layout
are gone."""

import ast
import importlib
import pathlib
import warnings

import pytest

import mbplanar

PACKAGE = pathlib.Path(mbplanar.__file__).parent
LAYERS = ["errors", "model", "structure", "engine", "kinematics", "forces", "backends", "analysis",
          "study", "io", "viz", "cam", "synthesis", "cli"]  # cams, synthesis, studies use what precedes them


def _layer(module: str) -> int:
    """Rank of a module given as a path under `mbplanar` ('engine._solver', 'cli', ...)."""
    top = module.split(".")[0]
    return LAYERS.index(top)


def _imports(path: pathlib.Path):
    """The package-internal modules imported by `path` (at module level or inside a function), as paths
    under `mbplanar`."""
    rel = path.relative_to(PACKAGE).with_suffix("")
    parts = list(rel.parts)
    package = parts[:-1]                # the package a relative import starts from
    tree = ast.parse(path.read_text())
    typing_only = {id(n) for block in ast.walk(tree) if isinstance(block, ast.If)
                   and getattr(block.test, "id", None) == "TYPE_CHECKING" for n in ast.walk(block)}
    for node in ast.walk(tree):
        if id(node) in typing_only:     # names for annotations only
            continue
        if isinstance(node, ast.ImportFrom) and node.level:
            base = package[:len(package) - (node.level - 1)] if node.level > 1 else package
            target = base + (node.module.split(".") if node.module else [])
            if target:
                yield ".".join(target)
            else:                       # from . import x (at the top level)
                yield from (alias.name for alias in node.names)


def test_imports_run_one_way():
    """Also inside functions: the compiled backend is loaded by name (`engine._backend.load`), not imported
    by the kinematics or the forces it serves."""
    wrong = []
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE)
        if rel.name in ("__init__.py", "__main__.py") and len(rel.parts) == 1:
            continue                    # the public API and `python -m` sit above everything
        here = _layer(".".join(rel.with_suffix("").parts))
        for target in _imports(path):
            if _layer(target) > here:
                wrong.append(f"{rel} imports {target}")
    assert not wrong, wrong


@pytest.mark.parametrize("old", ["solver", "loads", "plotting", "check", "kinetostatics", "topology", "table",
                                 "_numba_kinematics", "report"])
def test_the_old_module_paths_are_gone(old):
    """The module paths of the flat layout (never released) do not import: no import hook forwards them."""
    with pytest.raises(ImportError):
        importlib.import_module("mbplanar." + old)


def test_a_misspelt_name_is_an_error_not_a_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for module, name in ((mbplanar, "Engin"), (mbplanar.kinematics, "describe_limits"),
                             (mbplanar.model, "read_modle"), (mbplanar.structure, "decompse"),
                             (mbplanar.engine, "TOL"), (importlib.import_module("mbplanar.engine._tolerances"), "TOL")):
            with pytest.raises(AttributeError):
                getattr(module, name)
        with pytest.raises(ImportError):
            exec("from mbplanar.kinematics import analyze", {})


def test_public_functions_are_not_shadowed_by_modules():
    import mbplanar.analysis  # noqa: F401
    assert callable(mbplanar.check) and mbplanar.check.__module__ == "mbplanar.analysis._check"
    assert callable(mbplanar.kinetostatics)


@pytest.mark.parametrize("package", ["model", "structure", "engine", "kinematics", "forces", "backends",
                                     "analysis", "io", "viz"])
def test_each_subpackage_exports_what_it_lists(package):
    module = importlib.import_module("mbplanar." + package)
    for name in module.__all__:
        assert getattr(module, name) is not None
