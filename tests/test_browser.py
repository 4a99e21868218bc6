"""The workbench (`mbplanar serve`), the report and the HTML animation in a real browser: Debian's Chromium
driven by Playwright for Python (no browser is downloaded: `executable_path` is the system's Chromium).

One browser serves the whole session and one workbench server (uvicorn in a thread) this module; each test
opens its own page. Skipped, saying why, where Playwright or Chromium is missing (`.ci/run` installs
Debian's `chromium` where apt-get exists). MBPLANAR_SCREENSHOTS=DIR writes the screenshots of
docs/workbench.md there (``MBPLANAR_SCREENSHOTS=docs python -m pytest tests/test_browser.py``).
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import shutil
import socket
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from conftest import linkage_models

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = next((p for p in ("/usr/bin/chromium", "/usr/bin/chromium-browser", shutil.which("chromium") or "",
                             shutil.which("google-chrome") or "") if p and os.path.exists(p)), None)
WHY = os.environ.get("MBPLANAR_BROWSER_NOTE", "")
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--disable-sync"]


def _why_not() -> str | None:
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        return "Playwright for Python is not installed (pip install -e '.[test]')"
    if CHROMIUM is None:
        return ("no Chromium at /usr/bin/chromium" + (f" ({WHY})" if WHY else "")
                + ": apt-get install chromium to run the browser tests")
    return None


pytestmark = pytest.mark.skipif(_why_not() is not None, reason=str(_why_not()))


@pytest.fixture(scope="session")
def browser():
    from playwright.sync_api import sync_playwright
    with sync_playwright() as p:
        chromium = p.chromium.launch(executable_path=CHROMIUM, args=FLAGS)
        yield chromium
        chromium.close()


@pytest.fixture
def page(browser):
    context = browser.new_context(viewport={"width": 1400, "height": 1000}, accept_downloads=True)
    pg = context.new_page()
    pg.errors = []
    pg.on("pageerror", lambda e: pg.errors.append(str(e)))
    yield pg
    context.close()
    assert not pg.errors, pg.errors


# -- the workbench server ---------------------------------------------------------------------------------
def forms() -> dict:
    """The panels' forms as `mbplanar serve` makes them from the command line's parsers."""
    from mbplanar.cli import build_parser
    from mbplanar.web._runs import EXPORTS, PANELS, form
    return {name: form(build_parser(name), name) for name in PANELS + EXPORTS}


class Server:
    """A workbench server on a free port of 127.0.0.1, in a thread of this process."""

    def __init__(self, folder: Path):
        import uvicorn
        from mbplanar.web import create_app
        self.folder = folder
        self.app = create_app(folder, forms=forms())
        self.token = self.app.state.token
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.port = self.sock.getsockname()[1]
        self.base = f"http://127.0.0.1:{self.port}/"
        self.url = f"{self.base}?token={self.token}"
        config = uvicorn.Config(self.app, log_level="warning", ws_per_message_deflate=False, lifespan="on")
        self.server = uvicorn.Server(config)
        self.thread = threading.Thread(target=self.server.run, kwargs={"sockets": [self.sock]}, daemon=True)
        self.thread.start()
        end = time.monotonic() + 20
        while not self.server.started and time.monotonic() < end:
            time.sleep(0.02)

    def stop(self):
        self.server.should_exit = True
        self.thread.join(10)


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    pytest.importorskip("uvicorn", reason="the workbench needs the web extra (pip install -e '.[web]')")
    folder = tmp_path_factory.mktemp("served")
    for path in ROOT.joinpath("models").glob("*.toml"):
        shutil.copy(path, folder / path.name)
    srv = Server(folder)
    yield srv
    srv.stop()


def open_model(page, server, name: str):
    """The page with `name` (a file of the served folder, or gallery/NAME) open and its picture drawn."""
    page.goto(f"{server.url}&open={name}")
    wait_model(page, name)
    return page


def wait_model(page, name: str, timeout=20_000):
    page.wait_for_function("n => { const s = window.workbench && window.workbench.state; return s && s.document &&"
                           " s.document.name === n && s.picture && s.document.errors.length === 0 &&"
                           " s.picture.source === n; }", arg=name, timeout=timeout)


def show_values(page, values):
    """Type the input values into the value boxes; wait for the numbers of that position."""
    boxes = page.locator("[data-role=value]")
    for k, v in enumerate(values):
        boxes.nth(k).fill(repr(float(v)))
    boxes.nth(len(values) - 1).press("Enter")
    try:
        _wait_values(page, values)
    except Exception:
        print(page.inner_text("[data-role=status]"), page.evaluate("() => [document.querySelector('[data-role=numbers]').dataset.values, window.workbench.state.inflight, window.workbench.state.pending]"))
        raise


def _wait_values(page, values):
    page.wait_for_function("v => { const d = document.querySelector('[data-role=numbers]').dataset.values;"
                           " return d && JSON.parse(d).length === v.length &&"
                           " JSON.parse(d).every((x, i) => Math.abs(x - v[i]) < 1e-12); }", arg=list(values))


def page_points(page) -> dict:
    return page.evaluate("""() => Object.fromEntries([...document.querySelectorAll('[data-role=points] tr[data-point]')]
        .map(tr => [tr.dataset.point, Object.fromEntries([...tr.querySelectorAll('td[data-q]')]
        .map(td => [td.dataset.q, +td.dataset.value])) ]))""")


def cli_json(*args) -> dict:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert mbplanar.cli.main(list(args)) == 0
    return json.loads(out.getvalue())


def grey(png: bytes) -> np.ndarray:
    from PIL import Image
    with Image.open(io.BytesIO(png)) as im:
        return np.asarray(im.convert("L"), float)


def screenshot_to_docs(page, name: str, **options):
    where = os.environ.get("MBPLANAR_SCREENSHOTS")
    if where:
        page.screenshot(path=str(Path(where) / name), **options)


# -- every bundled model opens, at the CLI's coordinates --------------------------------------------------
def test_every_bundled_model_opens_with_the_coordinates_of_solve(page, server):
    """Each linkage model of the gallery, at three input values typed into the page: every joint's and
    point's coordinates equal those `mbplanar solve MODEL --at ... --json` prints, to 1e-9 m."""
    page.goto(server.url)
    page.wait_for_function("() => window.workbench && window.workbench.state.session")
    worst = 0.0
    for path in linkage_models():
        name = f"gallery/{path.name}"
        page.evaluate("n => window.workbench.openPath(n)", name)
        wait_model(page, name)
        n_in = page.evaluate("() => window.workbench.state.picture.inputs.length")
        count = page.evaluate("() => window.workbench.state.frames.count")
        assert count > 1
        for fraction in (0.13, 0.5, 0.77):
            values = page.evaluate("([f, n]) => { const F = window.workbench.state.frames; const b = Math.round(f * (F.count - 1));"
                                   " return Array.from({length: n}, (_, k) => F.phi[b * n + k]); }", [fraction, n_in])
            values = [round(v, 3) for v in values]
            show_values(page, values)
            shown = page_points(page)
            solved = cli_json("solve", str(path), "--at", ",".join(repr(v) for v in values), "--json")["points"]
            assert set(shown) == set(solved), name
            for point, p in solved.items():
                for q in ("x", "y"):
                    worst = max(worst, abs(shown[point][q] - p[q]))
                    assert shown[point][q] == pytest.approx(p[q], abs=1e-9), (name, values, point, q)
    assert worst < 1e-9


# -- the diagram moves with the mouse ----------------------------------------------------------------------
def _centre(box):
    return box["x"] + box["width"] / 2, box["y"] + box["height"] / 2


def test_dragging_the_crank_moves_the_picture_and_the_numbers(page, server):
    open_model(page, server, "six_bar_press.toml")
    show_values(page, [100.0])
    crank = page.locator("[data-role=diagram] [data-link='1']")
    before_points = crank.get_attribute("points")
    before = page_points(page)
    pivot = _centre(page.locator("circle[data-joint='O']").bounding_box())
    grip = _centre(page.locator("circle[data-joint='A']").bounding_box())
    start = ((pivot[0] + grip[0]) / 2, (pivot[1] + grip[1]) / 2)   # on the crank, between O and A
    radius = np.hypot(start[0] - pivot[0], start[1] - pivot[1])
    a0 = np.arctan2(start[1] - pivot[1], start[0] - pivot[0])
    page.mouse.move(*start)
    page.mouse.down()
    for step in range(1, 13):                                     # a quarter turn on the screen
        a = a0 + step * (np.pi / 2) / 12
        page.mouse.move(pivot[0] + radius * np.cos(a), pivot[1] + radius * np.sin(a))
        page.wait_for_timeout(15)
    page.mouse.up()
    page.wait_for_function("() => !window.workbench.state.inflight && !window.workbench.state.pending")
    page.wait_for_timeout(100)
    after = page_points(page)
    assert crank.get_attribute("points") != before_points
    assert np.hypot(after["A"]["x"] - before["A"]["x"], after["A"]["y"] - before["A"]["y"]) > 0.1
    value = page.evaluate("() => window.workbench.state.values[0]")
    assert abs(value - 100.0) > 45                     # the crank turned by about the quarter turn dragged
    # the numbers are the engine's at the value dragged to
    solved = cli_json("solve", str(server.folder / "six_bar_press.toml"), "--at", repr(value), "--json")["points"]
    assert after["H"]["x"] == pytest.approx(solved["H"]["x"], abs=1e-9)
    screenshot_to_docs(page, "workbench_press.png", full_page=False)


def test_a_screenshot_of_the_diagram_is_not_blank(page, server):
    open_model(page, server, "fourbar_loaded.toml")
    for toggle in ("velocities", "reactions"):
        page.check(f"[data-toggle={toggle}]")
    image = grey(page.locator("[data-role=diagram]").screenshot())
    assert image.std() > 10
    ink = image < 128
    assert 0.005 < ink.mean() < 0.5
    rows, cols = np.nonzero(ink)
    assert np.ptp(rows) > 0.4 * image.shape[0] and np.ptp(cols) > 0.3 * image.shape[1]
    assert page.locator("[data-vector=v]").count() > 0 and page.locator("[data-reaction]").count() > 0
    assert "balancing moment at O" in page.inner_text("[data-role=legend]")
    page.wait_for_function("() => window.workbench.state.settled === window.workbench.state.picture.version")
    screenshot_to_docs(page, "workbench.png")


# -- the table and the text ---------------------------------------------------------------------------------
def test_editing_a_length_updates_the_text_the_picture_and_the_plots(page, server):
    open_model(page, server, "fourbar_loaded.toml")
    plot = page.locator("[data-role=plot] path[data-series]").first
    plot.wait_for()
    before = {"path": plot.get_attribute("d"), "bar": page.locator("[data-role=diagram] [data-link='3']").get_attribute("points"),
              "text": page.input_value("[data-role=text]")}
    cell = page.locator("input[data-section=links][data-row='2'][data-key=length]")
    assert cell.input_value() == "0.25"
    cell.fill("0.27")
    cell.press("Enter")
    page.wait_for_function("() => document.querySelector('[data-role=text]').value.includes('length = 0.27')")
    page.wait_for_function("b => document.querySelector(\"[data-role=diagram] [data-link='3']\").getAttribute('points') !== b",
                           arg=before["bar"])
    page.wait_for_function("d => { const p = document.querySelector('[data-role=plot] path[data-series]');"
                           " return p && p.getAttribute('d') !== d; }", arg=before["path"])
    text = page.input_value("[data-role=text]")
    assert "# rocker CB" in text                          # the author's comments stay
    assert text.replace("length = 0.27", "length = 0.25") == before["text"]
    page.click("[data-role=undo]")
    page.wait_for_function("t => document.querySelector('[data-role=text]').value === t", arg=before["text"])
    page.click("[data-role=redo]")
    page.wait_for_function("() => document.querySelector('[data-role=text]').value.includes('length = 0.27')")


def test_a_broken_row_shows_the_error_at_its_row_and_the_page_stays_usable(page, server):
    open_model(page, server, "fourbar_loaded.toml")
    good = page.locator("[data-role=diagram] [data-link='2']").get_attribute("points")
    cell = page.locator("input[data-section=joints][data-row='2'][data-key=links]")
    page.evaluate("""() => { window.__edited = null; window.__shown = null;
        new MutationObserver(() => { if (!window.__shown && document.querySelector('[data-role=row-error]'))
            window.__shown = performance.now(); }).observe(document.querySelector('[data-role=table]'),
            {childList: true, subtree: true});
        document.querySelector("input[data-section=joints][data-row='2'][data-key=links]")
            .addEventListener('change', () => { window.__edited = performance.now(); }, {capture: true}); }""")
    cell.fill('["2", "9"]')
    cell.press("Enter")
    error = page.locator("tr.bad[data-section=joints][data-row='2'] + tr[data-role=row-error]")
    error.wait_for()
    delay = page.evaluate("() => window.__shown - window.__edited")
    assert delay < 200, f"the error showed {delay:.0f} ms after the edit"
    message = error.inner_text()
    error.scroll_into_view_if_needed()
    screenshot_to_docs(page, "workbench_error.png")
    cli = io.StringIO()
    broken = server.folder / "broken.toml"
    broken.write_text(page.input_value("[data-role=text]"), encoding="utf-8")
    with contextlib.redirect_stderr(cli):
        assert mbplanar.cli.main(["info", str(broken)]) == 2
    cli_message = cli.getvalue().strip().removeprefix("mbplanar: ")
    assert message.split(": ", 1)[1] == cli_message.split(": ", 1)[1]   # the CLI's message (file names differ)
    assert page.locator("[data-role=diagram] [data-link='2']").get_attribute("points") == good    # the last good picture stays
    # still usable: the slider moves the last good picture, then the row is mended
    page.locator("[data-role=slider]").fill("90")
    page.wait_for_function("g => document.querySelector(\"[data-role=diagram] [data-link='2']\").getAttribute('points') !== g", arg=good)
    cell = page.locator("input[data-section=joints][data-row='2'][data-key=links]")
    cell.fill('["2", "3"]')
    cell.press("Enter")
    page.wait_for_function("() => !document.querySelector('[data-role=row-error]') &&"
                           " window.workbench.state.document.errors.length === 0")
    # a syntax error in the text names its line, and the table keeps the last good state
    page.fill("[data-role=text]", page.input_value("[data-role=text]").replace('ground = "0"', 'ground = "0'))
    page.locator("[data-role=problem]").wait_for()
    assert "line" in page.inner_text("[data-role=problem]")


def test_edit_mode_drags_a_joint_and_the_table_follows(page, server):
    open_model(page, server, "fourbar.toml")
    page.click("[data-role=edit]")
    cell = page.locator("input[data-section=joints][data-key=at]").nth(3)      # C, a ground pivot
    before = cell.input_value()
    pin = page.locator("circle[data-joint='C']").bounding_box()
    x, y = _centre(pin)
    page.mouse.move(x, y)
    page.mouse.down()
    for k in range(1, 6):
        page.mouse.move(x + 8 * k, y)
        page.wait_for_timeout(30)
    page.mouse.up()
    page.wait_for_function("b => { const c = document.querySelectorAll('input[data-section=joints][data-key=at]')[3];"
                           " return c && JSON.parse(c.value)[0] > JSON.parse(b)[0] + 0.01; }", arg=before)
    page.wait_for_timeout(300)                        # the drag's last state
    cell, text = page.evaluate("() => [document.querySelectorAll('input[data-section=joints][data-key=at]')[3].value,"
                               " document.querySelector('[data-role=text]').value]")
    new = json.loads(cell)
    assert new[0] > json.loads(before)[0] and new[1] == pytest.approx(json.loads(before)[1], abs=0.02)
    assert f"at = {cell}" in text                     # the table and the text: one state


def test_save_then_solve_gives_the_same_answer(page, server):
    open_model(page, server, "slider_crank.toml")
    cell = page.locator("input[data-section=links][data-row='1'][data-key=length]")
    old = cell.input_value()
    cell.fill(repr(round(float(old) * 1.1, 6)))
    cell.press("Enter")
    page.wait_for_function("() => window.workbench.state.document.dirty && window.workbench.state.document.errors.length === 0")
    page.fill("[data-role=save-name]", "saved/slider_crank_longer.toml")
    page.click("[data-role=save-as]")
    assert "no such folder" in _status_after(page)
    page.fill("[data-role=save-name]", "slider_crank_longer.toml")
    page.click("[data-role=save-as]")
    page.wait_for_function("() => document.querySelector('[data-role=status]').textContent.startsWith('saved')")
    saved = server.folder / "slider_crank_longer.toml"
    assert saved.read_text(encoding="utf-8") == page.input_value("[data-role=text]")
    assert not page.evaluate("() => window.workbench.state.document.dirty")
    show_values(page, [40.0])
    shown = page_points(page)
    solved = cli_json("solve", str(saved), "--at", "40", "--json")["points"]
    for point, p in solved.items():
        assert shown[point]["x"] == pytest.approx(p["x"], abs=1e-12) and shown[point]["y"] == pytest.approx(p["y"], abs=1e-12)


def _status_after(page) -> str:
    page.wait_for_function("() => document.querySelector('[data-role=status]').classList.contains('bad')")
    return page.inner_text("[data-role=status]")


def test_two_tabs_are_independent(page, server):
    open_model(page, server, "fourbar.toml")
    other = page.context.new_page()
    open_model(other, server, "fourbar.toml")
    cell = page.locator("input[data-section=links][data-row='1'][data-key=length]")
    cell.fill("0.31")
    cell.press("Enter")
    page.wait_for_function("() => document.querySelector('[data-role=text]').value.includes('0.31')")
    other.wait_for_timeout(200)
    assert "0.31" not in other.input_value("[data-role=text]")
    assert not other.evaluate("() => window.workbench.state.document.dirty")


# -- the security rules ------------------------------------------------------------------------------------
def test_requests_without_the_token_outside_the_folder_or_too_big_are_refused(page, server):
    answer = page.request.get(server.base)
    assert answer.status == 403 and "token" in answer.text()
    assert page.request.get(f"{server.base}static/workbench.js").status == 403
    assert page.request.get(f"{server.base}api/files?token=wrong").status == 403
    assert page.request.get(f"{server.base}api/files?token={server.token}").status == 200
    open_model(page, server, "fourbar.toml")
    outside = server.folder.parent / "outside.toml"
    outside.write_text((ROOT / "models" / "fourbar.toml").read_text(), encoding="utf-8")
    page.evaluate("() => window.workbench.openPath('../outside.toml')")
    assert "outside the served folder" in _status_after(page)
    page.evaluate("() => window.workbench.send({type: 'save_as', path: '/tmp/x.toml'})")
    page.wait_for_function("() => document.querySelector('[data-role=status]').textContent.includes('absolute path')")
    session = page.evaluate("() => window.workbench.state.session")
    big = page.request.post(f"{server.base}api/upload?session={session}&name=big.toml&token={server.token}",
                            data=b"#" * (1_100_000))
    assert big.status == 413 and "at most" in big.text()
    page.evaluate("() => window.workbench.send('not a message')")
    page.evaluate("() => window.workbench.send({type: 'cell', section: 'links', row: 99, key: 'length', value: '1'})")
    page.wait_for_function("() => document.querySelector('[data-role=status]').textContent.includes('no row 99')")
    show_values(page, [30.0])                                  # the page goes on
    assert page.request.get(f"{server.base}api/files?token={server.token}").status == 200
    assert not outside.with_name("x.toml").exists()


# -- panels and exports -------------------------------------------------------------------------------------
def test_a_panel_runs_the_cli_command_and_shows_its_output(page, server):
    open_model(page, server, "fourbar_loaded.toml")
    page.click("[data-panel=check]")
    page.click("[data-panel-body=check] [data-role=run]")
    page.wait_for_function("() => document.querySelector('[data-panel-body=check] [data-role=output]').dataset.code === '0'",
                           timeout=60_000)
    shown = page.inner_text("[data-panel-body=check] [data-role=stdout]")
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        mbplanar.cli.main(["check", str(server.folder / "fourbar_loaded.toml")])
    assert shown.split("\n", 1)[1].strip() == out.getvalue().split("\n", 1)[1].strip()
    where = os.environ.get("MBPLANAR_SCREENSHOTS")
    if where:
        page.locator("[data-panel-body=check]").locator("xpath=../..").screenshot(path=str(Path(where) / "workbench_panel.png"))
    page.click("[data-panel=forces]")
    page.click("[data-panel-body=forces] [data-role=run]")
    page.wait_for_function("() => document.querySelector('[data-panel-body=forces] [data-role=output]').dataset.code === '0'",
                           timeout=60_000)
    assert "balancing moment at O" in page.inner_text("[data-panel-body=forces] [data-role=stdout]")


def test_a_long_run_shows_progress_and_can_be_cancelled(page, server):
    open_model(page, server, "fourbar.toml")
    page.click("[data-panel=synth]")
    body = page.locator("[data-panel-body=synth]")
    body.locator("select[data-dest=problem]").select_option("path")
    body.locator("select[data-dest=input]").select_option("gallery/synthesis/path_bulatovic18.csv")
    body.locator("input[data-flag='--progress']").check()
    body.locator("[data-role=run]").click()
    page.wait_for_function("() => document.querySelector('[data-panel-body=synth] [data-role=progress]').textContent"
                           ".includes('mbplanar synth path')")
    page.wait_for_timeout(1500)
    body.locator("[data-role=cancel]").click()
    page.wait_for_function("() => document.querySelector('[data-panel-body=synth] [data-role=progress]').textContent"
                           ".includes('cancelled')", timeout=20_000)


def test_an_export_downloads_the_cli_picture(page, server):
    open_model(page, server, "fourbar.toml")
    with page.expect_download(timeout=60_000) as download:
        page.click("[data-export=PNG]")
    path = download.value.path()
    assert Path(path).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# -- the report and the animation, as files --------------------------------------------------------------
def _offline(page, opened: str) -> list[str]:
    return [u for u in page.requested if u != opened and not u.startswith(("data:", "about:"))]


def _recording(page):
    page.requested = []
    page.on("request", lambda r: page.requested.append(r.url))


def test_the_report_renders_with_its_diagram_offline(page, tmp_path):
    pytest.importorskip("matplotlib", reason="the report's figures need matplotlib (the [plot] extra)")
    from mbplanar.viz import report_html
    engine = mbplanar.Engine(mbplanar.read_model(ROOT / "models" / "fourbar_loaded.toml"))
    path = tmp_path / "report.html"
    path.write_text(report_html(engine, positions=6, frames=8, dpi=50), encoding="utf-8")
    _recording(page)
    page.goto(path.as_uri())
    whole = grey(page.screenshot(full_page=True))
    assert whole.std() > 10 and (whole < 100).mean() > 0.002
    images = page.evaluate("Array.from(document.images).map(i => [i.complete, i.naturalWidth])")
    assert images and all(done and width > 0 for done, width in images)
    diagram = grey(page.locator("#diagram img").first.screenshot())
    assert diagram.shape[0] > 100 and diagram.shape[1] > 150
    ink = diagram < 128
    assert 0.005 < ink.mean() < 0.5
    rows, cols = np.nonzero(ink)
    assert np.ptp(rows) > 0.4 * diagram.shape[0] and np.ptp(cols) > 0.4 * diagram.shape[1]
    assert _offline(page, path.as_uri()) == []


def test_the_animation_plays_offline(page, tmp_path):
    from mbplanar.viz import html_animation
    engine = mbplanar.Engine(mbplanar.read_model(ROOT / "models" / "six_bar_press.toml"))
    path = tmp_path / "animation.html"
    path.write_text(html_animation(engine, frames=36, fps=12), encoding="utf-8")
    _recording(page)
    page.goto(path.as_uri())
    state = "[document.querySelector('output').textContent, +document.querySelector('input[type=range]').value]"
    first_text, first_frame = page.evaluate(state)
    first = grey(page.locator("svg").first.screenshot())
    assert first.std() > 5
    page.wait_for_timeout(1000)
    later_text, later_frame = page.evaluate(state)
    later = grey(page.locator("svg").first.screenshot())
    assert later_frame != first_frame and later_text != first_text
    assert first_text.startswith("f = ") and later_text.startswith("f = ")
    assert np.abs(later - first).mean() > 0.2 and (np.abs(later - first) > 64).sum() > 50
    page.click("button")
    paused = page.evaluate(state)
    page.wait_for_timeout(500)
    assert page.evaluate(state) == paused
    assert _offline(page, path.as_uri()) == []


# -- the Jupyter widget runs the page's own script ------------------------------------------------------
def test_the_widget_draws_and_solves_through_its_comm(page, server):
    """`mbplanar.widget`'s JavaScript is the page's file, run as anywidget runs it: its default export
    renders into an element, talking to a model object; here the model's messages go to the Python
    widget's own handler (the kernel's side) and its answers, buffers and all, come back."""
    pytest.importorskip("anywidget", reason="mbplanar.widget needs anywidget (the widget extra)")
    import base64
    w = mbplanar.widget(ROOT / "models" / "six_bar_press.toml")
    outbox = []
    w.send = lambda content, buffers=None: outbox.append(
        [content, base64.b64encode(bytes(buffers[0])).decode() if buffers else None])

    def kernel(content):
        outbox.clear()
        w._answer(w, content)
        return list(outbox)
    page.expose_function("kernel", kernel)
    page.goto(server.url)                  # (the page's cookie lets the module be imported)
    page.evaluate("""async () => {
        const module = await import('./static/workbench.js');
        const listeners = [];
        const model = { on(event, f) { listeners.push(f); },
                        async send(content) { for (const [c, b] of await window.kernel(content)) {
                            const buffers = b ? [new DataView(Uint8Array.from(atob(b), x => x.charCodeAt(0)).buffer)] : [];
                            listeners.forEach(f => f(c, buffers)); } } };
        const el = document.createElement('div'); el.id = 'widget'; document.body.prepend(el);
        module.default.render({ model, el }); }""")
    page.wait_for_function("() => document.querySelectorAll('#widget [data-role=diagram] [data-link]').length > 0")
    assert page.locator("#widget [data-role=text]").count() == 0          # the widget has no editor
    box = page.locator("#widget [data-role=value]").first
    box.fill("120")
    box.press("Enter")
    page.wait_for_function("() => (document.querySelector('#widget [data-role=numbers]').dataset.values || '') === '[120]'")
    solved = cli_json("solve", str(ROOT / "models" / "six_bar_press.toml"), "--at", "120", "--json")["points"]
    x = float(page.get_attribute("#widget [data-role=points] tr[data-point=H] td[data-q=x]", "data-value"))
    assert x == pytest.approx(solved["H"]["x"], abs=1e-9)
    page.locator("#widget [data-role=plot]").first.wait_for()


def test_a_two_input_model_is_plotted_over_a_grid_in_input_space(page, server):
    """The five-bar's two inputs: `mbplanar sweep --from --to --steps --grid` run from the plots, one line per
    value of the first input; the plotted values are the sweep's own CSV."""
    open_model(page, server, "five_bar.toml")
    page.fill("[data-role=sweep-from]", "40,90")
    page.fill("[data-role=sweep-to]", "100,150")
    page.fill("[data-role=sweep-steps]", "6")
    page.check("[data-role=sweep-grid]")
    page.click("[data-role=sweep-run]")
    page.wait_for_function("() => (window.workbench.state.extraGroups || []).some(g => g.name.startsWith('sweep grid'))",
                           timeout=60_000)
    path = page.locator("[data-role=plot]").last.locator("path[data-series]")
    path.wait_for()
    assert path.get_attribute("d").count("M") == 7                      # phi1 = 40, 50, ..., 100
    name = path.get_attribute("data-series")
    shown = page.evaluate("n => Array.from(window.workbench.state.extraGroups.find(g => g.name.startsWith('sweep grid'))"
                          ".columns.find(c => c.name === n).values)", name)
    csv = server.folder / "grid.csv"
    assert mbplanar.cli.main(["sweep", str(server.folder / "five_bar.toml"), "--from", "40,90", "--to", "100,150",
                              "--steps", "6", "--grid", "-o", str(csv)]) == 0
    header = csv.read_text().splitlines()[0].split(",")
    table = np.genfromtxt(csv, delimiter=",", skip_header=1)
    assert np.allclose(shown, table[:, header.index(name)], rtol=0, atol=1e-9)
