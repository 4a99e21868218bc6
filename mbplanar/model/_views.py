"""Views of a result that live in higher layers: its pandas DataFrame (`mbplanar.io`) and what Jupyter shows
for it (`mbplanar.viz`). A result type offers ``to_frame()`` and ``_repr_html_()`` by calling `view`, which
loads the presenting module by name when first asked, so that imports still run one way (model → ... → io,
viz) and neither pandas nor the presentation code is imported by an analysis that does not ask for them.
"""

from __future__ import annotations

import importlib

__all__ = ["view", "PRESENTERS"]

#: kind of view → the module presenting it; each has ``VIEWS``: a result type's name → function(result)
PRESENTERS = {"frame": "mbplanar.io._frames", "html": "mbplanar.viz._notebook"}


def view(kind: str, result):
    """A view of a result that a higher layer presents: its DataFrame or its HTML for Jupyter.

    Parameters
    ----------
    kind : {"frame", "html"}
        The view: a pandas DataFrame (`mbplanar.io`) or the HTML Jupyter shows (`mbplanar.viz`).
    result : object
        A result whose type the presenting module knows (`Motion`, `Kinetostatics`, `Engine`, ...).

    Returns
    -------
    object
        The DataFrame, or the HTML text.

    Raises
    ------
    KeyError
        Another `kind`, or a type the presenter has no view of.
    ImportError
        The view needs an extra that is not installed (pandas for "frame").

    Examples
    --------
    >>> from mbplanar import Engine, read_model
    >>> from mbplanar.model import view
    >>> html = view("html", Engine(read_model("models/fourbar.toml")))
    >>> html.startswith("<"), "fourbar" in html
    (True, True)
    """
    presenter = importlib.import_module(PRESENTERS[kind])
    return presenter.VIEWS[type(result).__name__](result)
