"""Public names imported on first use (PEP 562): a package lists where each lives, and the module is
imported only when the name is read, so that importing the package stays cheap. A misspelt name is an
AttributeError, as for any module."""

from __future__ import annotations

import importlib
import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Callable

__all__ = ["lazy_attributes"]


def lazy_attributes(package: str, homes: dict) -> tuple[Callable, Callable]:
    """The module-level ``__getattr__`` and ``__dir__`` of a package whose names load on first use.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    homes : dict
        {public name: the submodule (relative to the package) that defines it}, or
        ``"submodule:attribute"`` where the name there differs.

    Returns
    -------
    getattr_, dir_ : callable
        To assign to the package's ``__getattr__`` and ``__dir__``; a name read once is then a plain
        attribute of the package.

    Raises
    ------
    AttributeError
        From ``getattr_``, for a name `homes` does not list.

    Examples
    --------
    >>> import mbplanar.formats as formats
    >>> "model_schema" in dir(formats), callable(formats.model_schema)
    (True, True)
    >>> formats.model_shema
    Traceback (most recent call last):
    ...
    AttributeError: module 'mbplanar.formats' has no attribute 'model_shema'
    """

    def getattr_(name: str):
        if name not in homes:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module, _, attribute = homes[name].partition(":")
        value = getattr(importlib.import_module(f"{package}.{module}"), attribute or name)
        setattr(sys.modules[package], name, value)
        return value

    def dir_():
        module = sys.modules[package]
        return sorted(set(vars(module)) | set(getattr(module, "__all__", ())))

    return getattr_, dir_
