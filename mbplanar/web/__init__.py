"""The workbench: `mbplanar serve` (a page in the browser) and `mbplanar.widget` (the same page in Jupyter).

`Workbench` holds one page's model (text, table, history, engine) and answers its messages;
`create_app(folder)` is the web server's ASGI application (Starlette, the ``web`` extra); `widget(model)`
is the Jupyter widget (anywidget, the ``widget`` extra). The page's own code (HTML, CSS, JavaScript)
lives in ``static/`` and works with no network; the server solves, the page draws what it receives.
"""

from ._session import FRAMES, Workbench
from ._widget import widget

__all__ = ["Workbench", "FRAMES", "create_app", "widget"]


def create_app(folder, **options):
    """The workbench's ASGI application serving `folder` (see `mbplanar.web._server.create_app`)."""
    from ._server import create_app as make
    return make(folder, **options)
