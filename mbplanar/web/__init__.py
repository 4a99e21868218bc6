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
    """The workbench's ASGI application serving a folder (what ``mbplanar serve`` runs under uvicorn).

    Every request must carry the token (the URL's ``token``, the ``X-Mbplanar-Token`` header or the
    page's cookie); only files inside `folder` are read or written.

    Parameters
    ----------
    folder : str or Path
        The served folder.
    **options
        ``token`` (default: a new random one, in ``app.state.token``), ``forms`` (the panels' fields,
        `mbplanar.web.command.panel_forms`), ``initial`` (the model a new page opens), ``frames``
        (positions of the cycle); see `mbplanar.web._server.create_app`.

    Returns
    -------
    starlette.applications.Starlette
        The application.

    Raises
    ------
    ModuleNotFoundError
        Starlette is not installed (``pip install "mbplanar[web]"``).

    Examples
    --------
    >>> from starlette.testclient import TestClient
    >>> from mbplanar.web import create_app
    >>> client = TestClient(create_app("models", token="secret"))
    >>> client.get("/").status_code, client.get("/?token=secret").status_code
    (403, 200)
    """
    from ._server import create_app as make
    return make(folder, **options)
