"""`mbplanar serve [MODEL | FOLDER] [--port N] [--host H] [--no-browser]`: the workbench in the browser.

Starts the web server (`mbplanar.web.create_app` under uvicorn) on 127.0.0.1, prints the page's URL
with its token and opens it in the default browser. Ctrl-C stops it. Needs the ``web`` extra
(``pip install "mbplanar[web]"``).
"""

from __future__ import annotations

import ipaddress
import socket
import sys
from pathlib import Path

from ..errors import ModelError

__all__ = ["add_arguments", "panel_forms", "run", "DEFAULT_PORT", "is_loopback"]

DEFAULT_PORT = 8760
PORTS_TRIED = 20          # the next ports tried when the default one is taken


def add_arguments(parser) -> None:
    """The `serve` command's options."""
    parser.add_argument("model", nargs="?", default=".",
                        help="a model to open, or the folder whose models the page may open and save (default: .)")
    parser.add_argument("--port", type=int, default=None,
                        help=f"the port (default {DEFAULT_PORT}, or the next free one; 0: any free port)")
    parser.add_argument("--host", default="127.0.0.1",
                        help="the address to listen on (default 127.0.0.1: this machine only)")
    parser.add_argument("--no-browser", action="store_true", help="do not open the page in a browser")


def is_loopback(host: str) -> bool:
    """True for an address (or name) that only this machine reaches."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def panel_forms(build_parser) -> dict:
    """The panels' and exports' forms: {command: fields}, each command's options read from the parser
    `build_parser(command)` makes (`mbplanar.cli.build_parser`), as `create_app(forms=...)` takes them."""
    from ._runs import EXPORTS, PANELS, form
    return {name: form(build_parser(name), name) for name in PANELS + EXPORTS}


def run(args, forms: dict | None = None) -> int:
    """Serve until Ctrl-C; `forms` are the panels' fields made from the CLI's parser (`mbplanar.cli`)."""
    try:
        import uvicorn
        from ._server import create_app
    except ImportError as exc:
        raise ModelError(f"mbplanar serve needs the web extra ({exc.name} is missing): "
                         "pip install \"mbplanar[web]\"") from None
    target = Path(args.model)
    if not target.exists():
        raise ModelError(f"{args.model}: no such model or folder")
    folder, initial = (target.parent, target.name) if target.is_file() else (target, None)
    if not is_loopback(args.host):
        print(f"mbplanar serve: warning: --host {args.host} listens beyond this machine: whoever reaches it and "
              f"has the URL (its token) can read and overwrite the models of {folder.resolve()}", file=sys.stderr)
    sock = _bind(args.host, args.port)
    port = sock.getsockname()[1]
    app = create_app(folder, forms=forms, initial=initial)
    shown = "127.0.0.1" if args.host in ("0.0.0.0", "::") else args.host
    url = f"http://{'[' + shown + ']' if ':' in shown else shown}:{port}/?token={app.state.token}"
    print(f"mbplanar serve: the workbench of {folder.resolve()} at\n    {url}\n(Ctrl-C stops it)", file=sys.stderr,
          flush=True)
    if not args.no_browser:
        import webbrowser
        try:
            webbrowser.open(url)
        except Exception:                 # no browser here: the URL is printed
            pass
    config = uvicorn.Config(app, log_level="warning", ws_max_size=4 << 20, ws_per_message_deflate=False,
                            timeout_graceful_shutdown=3, lifespan="on")
    server = uvicorn.Server(config)
    try:
        server.run(sockets=[sock])
    except KeyboardInterrupt:
        pass
    finally:
        sock.close()
    print("mbplanar serve: stopped", file=sys.stderr)
    return 0


def _bind(host: str, port: int | None) -> socket.socket:
    """A listening socket on `host`: `port`, or the default port or one of the next free ones."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    candidates = [port] if port is not None else range(DEFAULT_PORT, DEFAULT_PORT + PORTS_TRIED)
    last = None
    for candidate in candidates:
        sock = socket.socket(family, socket.SOCK_STREAM)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            sock.bind((host, candidate))
        except OSError as exc:
            sock.close()
            last = exc
            continue
        sock.listen(128)
        sock.set_inheritable(True)
        return sock
    raise ModelError(f"cannot listen on {host} port {port if port is not None else DEFAULT_PORT}"
                     f"{'' if port is not None else f' … {DEFAULT_PORT + PORTS_TRIED - 1}'}: {last}")
