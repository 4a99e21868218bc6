"""Names a package exports but imports on first access (PEP 562), so that importing the package costs
only what its other names need; a name it does not export stays an `AttributeError`.

    >>> import sys
    >>> from mbplanar._lazy import lazy_exports
    >>> getattr_, dir_ = lazy_exports("mbplanar.engine", {"load_engine": "_cache"})
    >>> getattr_("load_engine").__module__
    'mbplanar.engine._cache'
    >>> getattr_("load_engin")
    Traceback (most recent call last):
    AttributeError: module 'mbplanar.engine' has no attribute 'load_engin'
"""

from __future__ import annotations

import importlib
import sys

__all__ = ["lazy_exports"]


def lazy_exports(package: str, homes: dict[str, str]):
    """The module-level ``__getattr__`` and ``__dir__`` of `package`: each name of `homes` imported from
    the module it maps to (a module of the package, "_cache"; "_numba:BACKEND" for another attribute)
    on first access and kept in the package's namespace; ``dir()`` lists the package's names and its
    ``__all__``."""

    def __getattr__(name: str):
        if name not in homes:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module, _, attribute = homes[name].partition(":")
        value = getattr(importlib.import_module(f"{package}.{module}"), attribute or name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__():
        found = sys.modules[package]
        return sorted(set(vars(found)) | set(getattr(found, "__all__", ())))

    return __getattr__, __dir__
