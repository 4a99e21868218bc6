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
    """The `kind` view ("frame" or "html") of `result`, by the presenting module's function for its type."""
    presenter = importlib.import_module(PRESENTERS[kind])
    return presenter.VIEWS[type(result).__name__](result)
