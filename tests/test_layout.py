"""The package layout: subpackages export their names, imports run one way (model → structure → engine →
kinematics → forces → backends → analysis → study → io, viz → accuracy → cam → gears → synthesis → formats →
cli), and the module paths of the old flat layout are gone."""

import ast
import functools
import importlib
import pathlib
import warnings

import pytest

import mbplanar

PACKAGE = pathlib.Path(mbplanar.__file__).parent
LAYERS = ["errors", "_lazy", "_progress", "model", "structure", "engine", "kinematics", "forces", "backends", "analysis",
          "study", "io", "viz", "accuracy", "cam", "gears", "synthesis", "formats", "web",
          "cli"]  # cams, gears, synthesis, formats, studies, the workbench use what precedes them


def _layer(module: str) -> int:
    """Rank of a module given as a path under `mbplanar` ('engine._solver', 'cli', ...)."""
    top = module.split(".")[0]
    return LAYERS.index(top)


def _imports(path: pathlib.Path):
    """The package-internal modules imported by `path` (at module level or inside a function, relative or
    absolute, or by ``importlib.import_module`` with a name it can read), as paths under `mbplanar`."""
    rel = path.relative_to(PACKAGE).with_suffix("")
    yield from (target for target, _, _ in imports_in(path.read_text(), list(rel.parts)))


def imports_in(source: str, module: list[str]):
    """(target, names, line) of every package-internal import in `source`, the text of the module
    `module` (its path under `mbplanar`, as parts); target is a path under `mbplanar` ('engine._solver'),
    names the names imported from it (empty for ``import x`` and ``import_module``)."""
    package = module[:-1] if module[-1] != "__init__" else module[:-1]
    tree = ast.parse(source)
    typing_only = {id(n) for block in ast.walk(tree) if isinstance(block, ast.If)
                   and getattr(block.test, "id", None) == "TYPE_CHECKING" for n in ast.walk(block)}
    for node in ast.walk(tree):
        if id(node) in typing_only:     # names for annotations only
            continue
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[:len(package) - (node.level - 1)] if node.level > 1 else package
                target = base + (node.module.split(".") if node.module else [])
            elif node.module == "mbplanar" or (node.module or "").startswith("mbplanar."):
                target = node.module.split(".")[1:]
            else:
                continue
            names = [alias.name for alias in node.names]
            if target:
                yield ".".join(target), names, node.lineno
            else:                       # from . import x (at the top level): the modules x
                yield from ((name, [], node.lineno) for name in names)
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("mbplanar."):
                    yield alias.name.split(".", 1)[1], [], node.lineno
        elif isinstance(node, ast.Call) and getattr(node.func, "attr", getattr(node.func, "id", None)) == "import_module":
            target = _module_named(node, package, module if module[-1] != "__init__" else package)
            if target:
                yield target, [], node.lineno


def _module_named(call: ast.Call, package: list[str], name_of: list[str]) -> str | None:
    """The module an ``import_module(...)`` call names, as a path under `mbplanar`, where the call spells it
    out: "mbplanar.x.y", f"{__package__}.x" (`package`'s x) or f"{__name__}.x" (`name_of`'s); None
    otherwise."""
    if not call.args:
        return None
    name = call.args[0]
    if isinstance(name, ast.Constant) and isinstance(name.value, str):
        return name.value.split(".", 1)[1] if name.value.startswith("mbplanar.") else None
    if isinstance(name, ast.JoinedStr) and len(name.values) == 2:
        head, tail = name.values
        if (isinstance(head, ast.FormattedValue) and getattr(head.value, "id", None) in ("__name__", "__package__")
                and isinstance(tail, ast.Constant) and tail.value.startswith(".")):
            base = package if head.value.id == "__package__" else name_of
            return ".".join(base + tail.value[1:].split(".")) or None
    return None


def test_the_import_reader_follows_absolute_imports_and_import_module():
    source = ("from .. import errors\nfrom ..engine._solver import Engine\nimport mbplanar.viz._plotting\n"
              "from mbplanar.forces import kinetostatics\nimport importlib, numpy\n"
              "def f(m):\n    importlib.import_module('mbplanar.cam.design')\n"
              "    importlib.import_module(f'{__package__}._motion')\n    importlib.import_module(m)\n")
    found = [(target, names) for target, names, _ in imports_in(source, ["kinematics", "_single"])]
    assert found == [("errors", []), ("engine._solver", ["Engine"]), ("viz._plotting", []),
                     ("forces", ["kinetostatics"]), ("cam.design", []), ("kinematics._motion", [])]


#: subpackages whose names other subpackages still import from a private module or under a private name;
#: one per line, removed as each is made public (issue 29, item 7)
PRIVATE_YET: set = set()
SUBPACKAGES = sorted(p.name for p in PACKAGE.iterdir() if (p / "__init__.py").exists())


def private_imports_of(subpackage: str) -> list[str]:
    """Imports, in the other subpackages (and the command line), of `subpackage`'s private modules or of
    its private names: ``from ..engine._tables import X`` or ``from ..engine import _x``."""
    found = []
    for rel, target, names, line in _every_import():
        parts = target.split(".")
        if rel.parts[0] != subpackage and parts[0] == subpackage and (
                any(p.startswith("_") for p in parts[1:]) or any(n.startswith("_") for n in names)):
            found.append(f"{rel}.py:{line} imports {target} {names}")
    return found


@functools.lru_cache(maxsize=1)
def _every_import() -> list:
    """(importing module's path under `mbplanar`, target, names, line) of every import in the package."""
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).with_suffix("")
        found += [(rel, *row) for row in imports_in(path.read_text(), list(rel.parts))]
    return found


@pytest.mark.parametrize("subpackage", [pytest.param(s, marks=pytest.mark.xfail(strict=True, reason="not yet"))
                                        if s in PRIVATE_YET else s for s in SUBPACKAGES])
def test_other_subpackages_use_only_public_names(subpackage):
    """A subpackage's names used by another are public in it: exported by its `__init__` (or living in a
    public module) under a name without a leading underscore."""
    wrong = private_imports_of(subpackage)
    assert not wrong, "\n".join(wrong)


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
