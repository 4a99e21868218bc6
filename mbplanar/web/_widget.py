"""`mbplanar.widget(model)`: the workbench's diagram, slider, vectors and plots inline in Jupyter.

An anywidget whose JavaScript is the page's own file (``static/workbench.js``, its default export), not a
copy: the kernel answers its messages with a `Workbench`, as the server does for a browser tab.
"""

from __future__ import annotations

from pathlib import Path

from ._session import Workbench
from ._wire import pack

__all__ = ["widget", "STATIC"]

STATIC = Path(__file__).resolve().parent / "static"


def _widget_class():
    try:
        import anywidget
    except ImportError as exc:
        from ..errors import ModelError
        raise ModelError(f"mbplanar.widget needs anywidget ({exc.name} is missing): "
                         "pip install \"mbplanar[widget]\"") from None

    class MechanismWidget(anywidget.AnyWidget):
        """The workbench's view of one model in a notebook (see `mbplanar.widget`)."""

        _esm = STATIC / "workbench.js"
        _css = STATIC / "workbench.css"

        def __init__(self, bench: Workbench, **kwargs):
            super().__init__(**kwargs)
            self.bench = bench
            self.on_msg(self._answer)

        def _answer(self, _widget, content, buffers=None):
            if not isinstance(content, dict):
                return
            for answer in self.bench.answers(content):
                header, buffer = pack(answer)
                self.send(header, [buffer] if buffer else None)

    return MechanismWidget


def widget(model, *, frames: int | None = None):
    """The workbench's diagram of `model` with its slider, play/pause, dragging, vectors, numbers and plots,
    inline in Jupyter (anywidget: ``pip install "mbplanar[widget]"``). Its JavaScript is the page's own file
    (``mbplanar/web/static/workbench.js``); the kernel answers its messages as `mbplanar serve` does.

    Parameters
    ----------
    model : str, Path, Mechanism or Engine
        A model file, or a mechanism or engine made in Python (drawn from it, not edited).
    frames : int, optional
        Positions of the cycle (default `mbplanar.web.FRAMES`, 360).

    Returns
    -------
    anywidget.AnyWidget
        The widget: shown inline as the last expression of a notebook's cell.

    Raises
    ------
    ModelError
        Without anywidget installed (naming the extra), or for a model file that cannot be read.

    Examples
    --------
    >>> import mbplanar
    >>> w = mbplanar.widget("models/fourbar.toml", frames=72)
    >>> w.bench.name, w.bench.frames
    ('models/fourbar.toml', 72)
    """
    from ..engine import Engine
    from ..model import Mechanism
    from ._session import FRAMES
    count = FRAMES if frames is None else int(frames)
    if isinstance(model, Engine):
        bench = Workbench(engine=model, name=model.mech.source or model.mech.name, frames=count)
    elif isinstance(model, Mechanism):
        bench = Workbench(engine=Engine(model), name=model.source or model.name, frames=count)
    else:
        path = Path(model)
        try:
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            from ..errors import ModelError
            raise ModelError(f"cannot read the model file ({exc})", source=str(path)) from None
        bench = Workbench(text, str(path), frames=count)
    return _widget_class()(bench)
