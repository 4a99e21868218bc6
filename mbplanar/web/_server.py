"""The workbench's web server: a Starlette application served by uvicorn.

Every request carries the server's token (in the URL's ``token``, the ``X-Mbplanar-Token`` header, or the
cookie the page gets with its first answer), as Jupyter's does; one without it gets 403. A page talks to
the server over one WebSocket, ``/ws``: each connection has a `Workbench` of its own (two tabs are two
sessions), its messages answered in order, an edit that a newer one makes out of date dropped, and
its long runs (the panels' commands, the exports) in processes of their own. Files are read from and
written to the served folder only (`Folder`); an upload or a text over 1 MB, and a message that is not
what the page sends, get an answer that says so, and the server goes on.
"""

from __future__ import annotations

import asyncio
import contextlib
import itertools
import json
import secrets
import shutil
import tempfile
from pathlib import Path, PurePosixPath
from urllib.parse import parse_qs, urlsplit

from ._files import MAX_UPLOAD, Folder, Refused
from ._runs import EXPORTS, PANELS, Run, argv
from ._session import FRAMES, Later, Workbench, slow_answer
from ._wire import dumps, frame, pack

__all__ = ["create_app", "STATIC", "COOKIE"]

STATIC = Path(__file__).resolve().parent / "static"
COOKIE = "mbplanar-token"
HEADER = "x-mbplanar-token"
EDITS = ("text", "cell", "add_row", "delete_row", "move", "undo", "redo", "load", "hello")
RUNS_AT_ONCE = 2          # commands one page may run at the same time


def create_app(folder, *, token: str | None = None, forms: dict | None = None, initial: str | None = None,
               frames: int = FRAMES):
    """The ASGI application of a workbench serving `folder`.

    Parameters
    ----------
    folder : path
        The served folder.
    token : str, optional
        The secret every request carries (default: a new random one, in ``app.state.token``).
    forms : dict, optional
        The panels' and exports' fields by command (`mbplanar.web._runs.form` of the CLI's parser); the
        command line passes them in, without them the page has no panels.
    initial : str, optional
        The model (relative to the folder) a new page opens.
    frames : int
        Positions of the cycle drawn and plotted.
    """
    from starlette.applications import Starlette
    from starlette.responses import FileResponse, HTMLResponse, JSONResponse, PlainTextResponse
    from starlette.routing import Mount, Route, WebSocketRoute
    from starlette.staticfiles import StaticFiles

    state = _State(Folder(folder), token or secrets.token_urlsafe(24), forms or {}, initial, frames)

    async def index(request):
        page = (STATIC / "index.html").read_text(encoding="utf-8")
        response = HTMLResponse(page, headers={"Cache-Control": "no-store", "Referrer-Policy": "no-referrer"})
        response.set_cookie(state.cookie, state.token, httponly=True, samesite="strict")
        return response

    async def files(request):
        return JSONResponse({"files": state.folder.files()})

    async def upload(request):
        session = state.sessions.get(request.query_params.get("session", ""))
        if session is None:
            return PlainTextResponse("400: upload to an open page's session (?session=...)", 400)
        name = Path(request.query_params.get("name") or "upload.toml").name
        if Path(name).suffix != ".toml":
            return PlainTextResponse(f"400: {name}: the workbench opens .toml models", 400)
        length = request.headers.get("content-length")
        if length is not None and (not length.isdigit() or int(length) > MAX_UPLOAD):
            return PlainTextResponse(_too_big(length), 413)
        body = b""
        async for chunk in request.stream():
            body += chunk
            if len(body) > MAX_UPLOAD:
                return PlainTextResponse(_too_big(len(body)), 413)
        try:
            text = body.decode("utf-8")
        except UnicodeDecodeError as exc:
            return PlainTextResponse(f"400: {name} is not UTF-8 text ({exc.reason} at byte {exc.start})", 400)
        await session.submit({"type": "load", "text": text, "name": name})
        session.origin = None
        return JSONResponse({"ok": True, "name": name})

    async def download(request):
        session = state.sessions.get(request.path_params["session"])
        if session is None:
            return PlainTextResponse("404: no such session", 404)
        path = session.output(request.path_params["run"], request.path_params["name"])
        if path is None:
            return PlainTextResponse("404: no such file", 404)
        inline = request.query_params.get("inline") == "1"
        return FileResponse(path, filename=path.name, content_disposition_type="inline" if inline else "attachment")

    async def socket(ws):
        await ws.accept()
        session = _Session(state, ws)
        state.sessions[session.sid] = session
        try:
            await session.serve()
        finally:
            state.sessions.pop(session.sid, None)
            await session.close()

    @contextlib.asynccontextmanager
    async def lifespan(app):
        await asyncio.to_thread(state.pool)   # start the worker process now, not at the first page's plots
        yield
        for session in list(state.sessions.values()):
            await session.close()
        state.close()

    routes = [Route("/", index), Route("/api/files", files), Route("/api/upload", upload, methods=["POST"]),
              Route("/api/download/{session}/{run}/{name}", download), WebSocketRoute("/ws", socket),
              Mount("/static", StaticFiles(directory=STATIC), name="static")]
    app = Starlette(routes=routes, lifespan=lifespan)
    app.state.workbench = state
    app.state.token = state.token
    return _TokenGate(app, state)


def _ignore_interrupts():
    import signal
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _too_big(size) -> str:
    return f"413: an upload is at most {MAX_UPLOAD // 1024} kB (1 MB); this one is {size} bytes"


class _State:
    def __init__(self, folder: Folder, token: str, forms: dict, initial, frames: int):
        self.folder, self.token, self.forms, self.initial, self.frames = folder, token, forms, initial, frames
        self.cookie = COOKIE
        self.sessions: dict[str, _Session] = {}
        self._pool, self._no_pool = None, False

    def pool(self):
        """The worker process that makes the states' slow answers (plots, check, machine dynamics) beside
        the poses: one for the server, started on first use, ignoring Ctrl-C (the server stops it). None
        where it cannot start (a script that starts a server without the ``if __name__ == "__main__":``
        guard multiprocessing needs): the answers are then made in a thread of the server."""
        if self._pool is None and not self._no_pool:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor
            try:
                self._pool = ProcessPoolExecutor(max_workers=1, mp_context=multiprocessing.get_context("spawn"),
                                                 initializer=_ignore_interrupts)
                self._pool.submit(int).result(timeout=60)
            except Exception as exc:
                self.pool_failed(exc)
        return self._pool

    def pool_failed(self, exc):
        if self._pool is not None:
            self._pool.shutdown(wait=False, cancel_futures=True)
        self._pool, self._no_pool = None, True

    def close(self):
        """Stop the worker process: it ends after the answer it is making (waited for 3 s), or is ended."""
        pool, self._pool = self._pool, None
        if pool is None:
            return
        import multiprocessing
        pool.shutdown(wait=False, cancel_futures=True)
        for child in multiprocessing.active_children():
            child.join(3)
            if child.is_alive():
                child.terminate()
                child.join(3)

    def first_model(self) -> str | None:
        """The model a new page opens: the one given, else the folder's first linkage model."""
        if self.initial:
            return self.initial
        for entry in self.folder.files():
            if entry["where"] == "folder" and entry["path"].endswith(".toml"):
                try:
                    text = self.folder.resolve(entry["path"]).read_text(encoding="utf-8")
                except (OSError, UnicodeDecodeError, Refused):
                    continue
                if "joints" in text:
                    return entry["path"]
        return None


class _TokenGate:
    """ASGI middleware: a request without the token gets 403, a WebSocket from another origin too."""

    def __init__(self, app, state: _State):
        self.app, self.state = app, state

    def __getattr__(self, name):
        return getattr(self.app, name)

    async def __call__(self, scope, receive, send):
        if scope["type"] not in ("http", "websocket"):
            return await self.app(scope, receive, send)
        headers = {k.decode("latin-1").lower(): v.decode("latin-1") for k, v in scope.get("headers", [])}
        given = parse_qs(scope.get("query_string", b"").decode("latin-1")).get("token", [""])[0] \
            or headers.get(HEADER, "") or _cookie(headers.get("cookie", ""), self.state.cookie)
        allowed = secrets.compare_digest(given.encode(), self.state.token.encode())
        reason = None if allowed else "this workbench needs the token of its URL (mbplanar serve prints it)"
        if allowed and scope["type"] == "websocket" and not _same_origin(headers):
            reason = "a WebSocket from another origin"
        if reason is None:
            return await self.app(scope, receive, send)
        if scope["type"] == "websocket":
            await send({"type": "websocket.close", "code": 1008, "reason": reason[:120]})
            return
        body = f"403 Forbidden: {reason}\n".encode()
        await send({"type": "http.response.start", "status": 403,
                    "headers": [(b"content-type", b"text/plain; charset=utf-8"),
                                (b"content-length", str(len(body)).encode())]})
        await send({"type": "http.response.body", "body": body})


def _cookie(header: str, name: str) -> str:
    for part in header.split(";"):
        key, _, value = part.strip().partition("=")
        if key == name:
            return value
    return ""


def _same_origin(headers: dict) -> bool:
    origin = headers.get("origin")
    if not origin:
        return True                       # not a browser's cross-site request
    return urlsplit(origin).netloc == headers.get("host", "")


class _Session:
    """One page: its `Workbench`, its queue of edits, its runs and their files."""

    _runs = itertools.count(1)

    def __init__(self, state: _State, ws):
        self.state, self.ws = state, ws
        self.sid = secrets.token_urlsafe(12)
        self.bench = Workbench(frames=state.frames, folder=str(state.folder.root))
        self.queue: asyncio.Queue = asyncio.Queue()
        self.runs: dict[str, Run] = {}
        self.tasks: set = set()
        self.origin = None                # the folder's file the model was opened from (None: not saved there)
        self.tmp = Path(tempfile.mkdtemp(prefix="mbplanar-serve-"))
        self.send_lock = asyncio.Lock()
        self.busy = False
        self.background = None

    # -- the connection --------------------------------------------------------------------------------
    async def serve(self):
        from starlette.websockets import WebSocketDisconnect
        worker = asyncio.ensure_future(self.work())
        await self.send({"type": "welcome", "session": self.sid, "files": self.state.folder.files(),
                         "forms": self.state.forms, "panels": [p for p in PANELS if p in self.state.forms],
                         "exports": [e for e in EXPORTS if e in self.state.forms],
                         "initial": self.state.first_model(), "folder": str(self.state.folder.root),
                         "max_upload": MAX_UPLOAD})
        try:
            while True:
                message = await self.ws.receive()
                if message["type"] == "websocket.disconnect":
                    break
                data = message.get("text")
                if data is None and message.get("bytes") is not None:
                    data = message["bytes"].decode("utf-8", "replace")
                await self.dispatch(data or "")
        except WebSocketDisconnect:
            pass
        finally:
            worker.cancel()

    async def dispatch(self, data: str):
        if len(data) > MAX_UPLOAD + 4096:
            return await self.send({"type": "error", "message": f"a message is at most 1 MB; this one is "
                                                                f"{len(data)} characters: not read"})
        try:
            message = json.loads(data)
            if not isinstance(message, dict) or not isinstance(message.get("type"), str):
                raise ValueError("not an object with a 'type'")
        except ValueError as exc:
            return await self.send({"type": "error", "message": f"a message that is not the page's JSON ({exc})"})
        kind = message["type"]
        try:
            if kind == "open" and message.get("run") is not None:
                path = self.output(str(message["run"]), str(message.get("name", "")))
                if path is None or path.suffix != ".toml":
                    raise Refused("no such model among the run's files", 404)
                await self.settled()
                self.origin = None
                await self.submit({"type": "load", "text": path.read_text(encoding="utf-8", errors="replace"),
                                   "name": path.name})
            elif kind == "open":
                text, origin = self.state.folder.read(message.get("path"))
                await self.settled()
                self.origin = origin
                await self.submit({"type": "load", "text": text, "name": message.get("path")})
            elif kind in ("save", "save_as"):
                await self.save(message)
            elif kind == "files":
                await self.send({"type": "files", "files": self.state.folder.files()})
            elif kind == "run":
                self.start(self.run(message))
            elif kind == "cancel":
                run = self.runs.get(str(message.get("id")))
                if run is not None:
                    self.start(run.cancel())
            elif kind == "text" and len(str(message.get("text", ""))) > MAX_UPLOAD:
                await self.send({"type": "error", "message": "a model's text is at most 1 MB"})
            else:
                await self.submit(message)
        except Refused as exc:
            await self.send({"type": "refused", "request": kind, "message": str(exc), "status": exc.status})

    async def submit(self, message):
        await self.queue.put(message)

    def start(self, coroutine):
        task = asyncio.ensure_future(coroutine)
        self.tasks.add(task)
        task.add_done_callback(self.tasks.discard)

    async def work(self):
        """Answer the queued messages in order; an edit or a solve that a newer one of its kind follows is
        dropped, and a state's later answers are skipped once another edit waits."""
        import anyio
        while True:
            message = await self.queue.get()
            if self._superseded(message):
                continue
            self.busy = True
            answers = self.bench.handle(message, self._stale)

            def step():
                answer = next(answers, None)
                return answer if answer is None or isinstance(answer, Later) else pack(answer)
            try:
                while True:
                    packed = await anyio.to_thread.run_sync(step)
                    if packed is None:
                        break
                    if isinstance(packed, Later):
                        self.later(packed)
                        continue
                    await self.send_packed(*packed)
                    await self._solves_first()
            except Exception as exc:       # a bug must not end the page's session: say it, go on
                if isinstance(exc, (asyncio.CancelledError, RuntimeError)) and self.ws.client_state.name != "CONNECTED":
                    raise
                await self.send({"type": "error", "message": f"internal error while answering "
                                 f"{message.get('type')!r}: {type(exc).__name__}: {exc}"})
            finally:
                self.busy = False

    async def settled(self):
        """Wait until every queued edit is made (a save writes the text they lead to)."""
        while self.busy or not self.queue.empty():
            await asyncio.sleep(0.005)

    def later(self, later: Later):
        """Make a state's slow answers in the server's worker process (the poses asked for meanwhile are
        answered here); a newer state's make the older's stop at their next answer."""
        if self.background is not None:
            self.background.cancel()

        async def run():
            loop = asyncio.get_running_loop()
            for kind in Later.KINDS:
                if self.bench.version != later.version:
                    return
                job = (slow_answer, kind, later.text, later.name, later.frames, later.version, later.folder)
                try:
                    pool = self.state.pool()
                    answer = await (loop.run_in_executor(pool, *job) if pool is not None else
                                    asyncio.to_thread(*job))
                except Exception as exc:        # a worker that died: say so, the page goes on
                    self.state.pool_failed(exc)
                    answer = {"type": "error", "message": f"the plots and the check could not be made: "
                                                          f"{type(exc).__name__}: {exc}"}
                if self.bench.version != later.version:
                    return
                await self.send(answer)
        self.background = asyncio.ensure_future(run())
        self.tasks.add(self.background)
        self.background.add_done_callback(self.tasks.discard)

    async def _solves_first(self):
        """Answer a waiting `solve` (the latest) between the stages of a state: a pose the page asks for does
        not wait for the plots and the check of the state before it."""
        import anyio
        waiting = [m for m in self.queue._queue if m.get("type") == "solve"]
        if not waiting or self._stale():
            return
        for m in waiting:
            self.queue._queue.remove(m)
        answer = await anyio.to_thread.run_sync(lambda: pack(self.bench.pose(waiting[-1])))
        await self.send_packed(*answer)

    def _superseded(self, message) -> bool:
        kind = message.get("type")
        if kind not in ("text", "solve", "move"):
            return False
        return any(m.get("type") == kind and m.get("name") == message.get("name") for m in list(self.queue._queue))

    def _stale(self) -> bool:
        return any(m.get("type") in EDITS for m in list(self.queue._queue))

    async def send(self, message):
        await self.send_packed(*pack(message))

    async def send_packed(self, header, buffer):
        async with self.send_lock:
            if buffer:
                await self.ws.send_bytes(frame(header, buffer))
            else:
                await self.ws.send_text(dumps(header))

    # -- files ---------------------------------------------------------------------------------------
    async def save(self, message):
        await self.settled()
        target = message.get("path") if message["type"] == "save_as" else (self.origin or None)
        if not target:
            return await self.send({"type": "save_as_needed", "message": "this model has no file in the served "
                                    "folder yet: save it as a new file"})
        path = self.state.folder.resolve(target, write=True)
        if path.exists() and message["type"] == "save_as" and not message.get("overwrite"):
            return await self.send({"type": "confirm_overwrite", "path": target})
        text = self.bench.text
        await asyncio.to_thread(path.write_text, text, encoding="utf-8")
        self.origin = self.state.folder.relative(path)
        self.bench.saved(self.origin)
        await self.send({"type": "saved", "path": self.origin, "files": self.state.folder.files()})

    def output(self, run: str, name: str) -> Path | None:
        if not run.isdigit() or Path(name).name != name or name.startswith("."):
            return None
        path = self.tmp / f"run{run}" / name
        return path if path.is_file() else None

    # -- runs ----------------------------------------------------------------------------------------
    async def run(self, message):
        request = str(message.get("id", ""))
        command = message.get("command")
        fields = self.state.forms.get(command)
        if fields is None:
            return await self.send({"type": "run_done", "id": request, "code": 2,
                                    "stderr": f"no command {command!r} here", "stdout": "", "files": []})
        if sum(run.process is not None and run.process.returncode is None for run in self.runs.values()) \
                >= RUNS_AT_ONCE:
            return await self.send({"type": "run_done", "id": request, "code": 2, "stdout": "", "files": [],
                                    "stderr": f"at most {RUNS_AT_ONCE} runs at once: wait for one to end or "
                                              "cancel it"})
        number = str(next(self._runs))
        folder = self.tmp / f"run{number}"
        folder.mkdir()
        files = _RunFiles(self, folder)
        try:
            args = [command] + argv(fields, message.get("values") or {}, files)
        except Refused as exc:
            shutil.rmtree(folder, ignore_errors=True)
            return await self.send({"type": "run_done", "id": request, "code": 2, "stdout": "", "files": [],
                                    "stderr": str(exc)})

        async def progress(line):
            await self.send({"type": "run_progress", "id": request, "line": line})
        run = Run(args, folder, progress)
        self.runs[request] = run
        shown = ["mbplanar"] + [files.shown(a) for a in args]
        await self.send({"type": "run_started", "id": request, "argv": shown})
        try:
            result = await run.run()
        finally:
            self.runs.pop(request, None)
        made = [{"name": p.name, "url": f"api/download/{self.sid}/{number}/{p.name}", "kind": _kind(p.suffix),
                 "run": number} for p in result["files"] if p != files.model_path]
        await self.send({"type": "run_done", "id": request, "command": command, "argv": shown,
                         "code": result["code"], "stdout": result["stdout"], "stderr": result["stderr"],
                         "cancelled": result["cancelled"], "files": made})

    async def close(self):
        for run in list(self.runs.values()):
            run.kill()
        for task in list(self.tasks):
            task.cancel()
        shutil.rmtree(self.tmp, ignore_errors=True)


class _RunFiles:
    """The paths of a run's files: the editor's model copied into the run's folder, files read from the
    served folder, files written into the run's folder (a bare name)."""

    def __init__(self, session: _Session, folder: Path):
        self.session, self.folder = session, folder
        self.model_path = None
        self.names = {}

    def model(self) -> str:
        """The editor's model as a file of the run's folder, with the model a cam file names beside it."""
        if self.model_path is None:
            name = Path(self.session.bench.name or "model.toml").name
            self.model_path = self.folder / (name if name.endswith(".toml") else "model.toml")
            self.model_path.write_text(self.session.bench.text, encoding="utf-8")
            self.names[str(self.model_path)] = name
            self._companion()
        return str(self.model_path)

    def _companion(self):
        """A cam file names its linkage model relative to itself: copy it from the folder or the gallery."""
        import tomllib
        try:
            other = tomllib.loads(self.session.bench.text).get("cam", {}).get("model")
        except (tomllib.TOMLDecodeError, AttributeError):
            return
        if not isinstance(other, str) or Path(other).name != other:
            return
        here = str(PurePosixPath(self.session.bench.name or "").parent)
        for name in ([f"{here}/{other}"] if here not in ("", ".") else []) + [other]:
            try:
                found = self.session.state.folder.copy_into(name, self.folder)
            except Refused:
                continue
            if found.parent != self.folder:
                found.replace(self.folder / other)
            return

    def read(self, name: str) -> str:
        if name in ("", "(editor)"):
            return self.model()
        path = self.session.state.folder.copy_into(name, self.folder)
        self.names[str(path)] = name
        return str(path)

    def write(self, name: str) -> str:
        name = name.replace("{model}", Path(self.session.bench.name or "model").stem)
        if Path(name).name != name or name.startswith(".") or not name.strip():
            raise Refused(f"{name}: an output is a file name (it is written beside the run and downloaded)", 400)
        self.names[str(self.folder / name)] = name
        return str(self.folder / name)

    def shown(self, arg: str) -> str:
        return self.names.get(arg, arg)


def _kind(suffix: str) -> str:
    return {".png": "image", ".svg": "image", ".gif": "image", ".toml": "model", ".html": "page"}.get(suffix, "file")
