"""The package layout: subpackages export their names, imports run one way (model → structure → engine →
kinematics → forces → backends → analysis → io, viz → cam → synthesis → formats → cli), and the old module
paths still work for one release, warning on every name read from them."""

import ast
import importlib
import pathlib
import warnings

import pytest

import mbplanar
from mbplanar import _deprecated

PACKAGE = pathlib.Path(mbplanar.__file__).parent
LAYERS = ["errors", "_deprecated", "model", "structure", "engine", "kinematics", "forces", "backends", "analysis",
          "study", "io", "viz", "cam", "synthesis", "formats", "web", "cli"]  # cams, synthesis, formats, studies,
# the workbench use what precedes them


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


@pytest.mark.parametrize("old", sorted(_deprecated.MOVED))
def test_an_old_module_path_warns_and_gives_the_same_objects(old):
    moved = _deprecated.MOVED[old]
    new = importlib.import_module("mbplanar." + (moved if isinstance(moved, str) else moved[0]))
    shim = importlib.import_module("mbplanar." + old)
    names = list(new.__all__)
    assert names and sorted(dir(shim)) == sorted(names)
    for name in names:
        with pytest.warns(DeprecationWarning, match=rf"mbplanar\.{old}\.{name} is deprecated"):
            assert getattr(shim, name) is getattr(new, name)
    with pytest.raises(AttributeError):
        getattr(shim, "no_such_name")


def test_old_import_statements_still_work():
    with pytest.warns(DeprecationWarning, match="use mbplanar.engine.Engine"):
        from mbplanar.solver import Engine
    assert Engine is mbplanar.Engine
    with pytest.warns(DeprecationWarning, match="use mbplanar.viz.register_figure"):
        from mbplanar.plotting import register_figure  # noqa: F401
    with pytest.warns(DeprecationWarning, match="use mbplanar.analysis.transmission_angles"):
        from mbplanar.check import transmission_angles  # noqa: F401
    with pytest.warns(DeprecationWarning, match=r"private now \(mbplanar.engine._tolerances.TOL\)"):
        from mbplanar.solver import TOL  # noqa: F401


def test_public_functions_are_not_shadowed_by_old_modules():
    import mbplanar.check  # noqa: F401
    import mbplanar.kinetostatics  # noqa: F401
    assert callable(mbplanar.check) and mbplanar.check.__module__ == "mbplanar.analysis._check"
    assert callable(mbplanar.kinetostatics)


def test_subpackages_named_like_old_modules_keep_their_names():
    from mbplanar.kinematics import Motion, analyse, positions_at_limits  # noqa: F401
    from mbplanar.model import Mechanism  # noqa: F401
    from mbplanar.structure import AssurGroup, Structure, decompose, roman  # noqa: F401
    with pytest.warns(DeprecationWarning, match="kinematics._motion.describe_limit"):
        from mbplanar.kinematics import describe_limit  # noqa: F401
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        import mbplanar.kinematics as k
        assert k.analyse is mbplanar.analyse


@pytest.mark.parametrize("package", ["model", "structure", "engine", "kinematics", "forces", "backends",
                                     "analysis", "io", "viz"])
def test_each_subpackage_exports_what_it_lists(package):
    module = importlib.import_module("mbplanar." + package)
    for name in module.__all__:
        assert getattr(module, name) is not None
