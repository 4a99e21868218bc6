"""The workbench's speed in a real browser (`mbplanar serve` driven by Playwright in Debian's Chromium).

    python benchmarks/workbench.py [--core N] [--rounds N] [--json FILE]

The server runs in a process of its own on one core (`--core`, default 0: os.sched_setaffinity, numpy's
BLAS on one thread, the numpy backend); the browser runs beside it. Three figures, each the median of
`--rounds` rounds:

- **drag**: the six-bar press's crank grabbed with the mouse and turned round its pivot, a turn a second
  for 2 s, by 120 pointer events a second (a mouse's rate); redraws per second = the poses the page
  received from the engine and drew, over the time of the drag. Target ≥ 30 per second.
- **edit**: a dimension of the class IV model typed into its cell (the coupler pivot D's x, alternately
  two values): from the cell's change to the new picture of the 360 positions on screen (the frame after
  it was drawn). Target ≤ 150 ms.
- **first picture**: every bundled linkage model opened in a new page (`?open=MODEL`, the server's
  caches warm: the model was opened once before): from the page's navigation start to its first picture
  on screen. Target ≤ 1 s for each.

Writes benchmarks/workbench_latest.json (or `--json FILE`) and prints a table.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CHROMIUM = "/usr/bin/chromium"
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--disable-sync"]
TARGETS = {"drag": ("redraws per second while dragging the six-bar press's input", ">=", 30.0),
           "edit": ("an edited dimension of the class IV model: 360 positions re-solved and drawn, ms", "<=", 150.0),
           "first": ("first picture of the slowest bundled model after the page opens, s", "<=", 1.0)}


def linkage_models() -> list[Path]:
    import tomllib
    return sorted(p for p in (ROOT / "models").glob("*.toml")
                  if "joints" in tomllib.loads(p.read_text(encoding="utf-8")))


def start_server(folder: Path, core: int):
    """`mbplanar serve FOLDER` pinned to one core; (process, URL)."""
    env = dict(os.environ, PYTHONUNBUFFERED="1", OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    proc = subprocess.Popen([sys.executable, "-m", "mbplanar", "serve", str(folder), "--port", "0", "--no-browser"],
                            stderr=subprocess.PIPE, text=True, env=env, cwd=ROOT,
                            preexec_fn=(lambda: os.sched_setaffinity(0, {core})) if hasattr(os, "sched_setaffinity")
                            else None)
    end = time.monotonic() + 60
    while time.monotonic() < end:
        line = proc.stderr.readline()
        found = re.search(r"http://\S+", line)
        if found:
            return proc, found.group(0)
    proc.kill()
    raise RuntimeError("mbplanar serve did not print its URL")


def wait_model(page, name):
    page.wait_for_function("n => { const s = window.workbench && window.workbench.state;"
                           " return s && s.picture && s.picture.source === n && s.painted; }", arg=name, timeout=30_000)
    page.wait_for_function("() => window.workbench.state.series", timeout=30_000)


def drag(page, url) -> float:
    page.goto(f"{url}&open=six_bar_press.toml")
    wait_model(page, "six_bar_press.toml")
    page.wait_for_function("() => window.workbench.state.settled === window.workbench.state.picture.version",
                           timeout=60_000)        # the state's plots, check and dynamics are made: a steady drag
    centre = lambda box: (box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)  # noqa: E731
    pivot = centre(page.locator("circle[data-joint='O']").bounding_box())
    grip = centre(page.locator("circle[data-joint='A']").bounding_box())
    import math
    start = ((pivot[0] + grip[0]) / 2, (pivot[1] + grip[1]) / 2)
    radius = math.hypot(start[0] - pivot[0], start[1] - pivot[1])
    a0 = math.atan2(start[1] - pivot[1], start[0] - pivot[0])
    page.mouse.move(*start)
    page.mouse.down()                     # the drag starts with the real mouse, on the crank
    # then the pointer moves as a hand's does, 120 events a second, sent inside the page (Playwright's own
    # moves are round trips to the browser, slower than the events of a mouse); 2 s, a turn a second
    result = page.evaluate("""([px, py, r, a0]) => new Promise(done => {
        const svg = document.querySelector('[data-role=diagram]'), st = window.workbench.state;
        const poses0 = st.poses, t0 = performance.now();
        const timer = setInterval(() => {
            const t = performance.now() - t0, a = a0 - 2 * Math.PI * t / 1000;
            svg.dispatchEvent(new PointerEvent('pointermove', { clientX: px + r * Math.cos(a), clientY: py + r * Math.sin(a),
                                                                 pointerId: 1, bubbles: true }));
            if (t > 2000) { clearInterval(timer); done([st.poses - poses0, (performance.now() - t0) / 1000]); }
        }, 1000 / 120); })""", [pivot[0], pivot[1], radius, a0])
    page.mouse.up()
    poses, elapsed = result
    return poses / elapsed


def edit(page, url, rounds: int) -> list[float]:
    page.goto(f"{url}&open=class4_group.toml")
    wait_model(page, "class4_group.toml")
    times = []
    for k in range(rounds + 1):
        value = "[0.29, 0.351]" if k % 2 == 0 else "[0.29, 0.35]"
        before = page.evaluate("() => window.workbench.state.painted")
        page.evaluate("""v => { const cell = document.querySelector("input[data-section=joints][data-key=at][data-row='2']");
            cell.value = v; window.__t0 = performance.now(); cell.dispatchEvent(new Event('change')); }""", value)
        page.wait_for_function("b => window.workbench.state.painted > b", arg=before, timeout=30_000)
        ms = page.evaluate("() => window.workbench.state.paintedAt - window.__t0")
        if k:                                     # the first round warms the page's and the server's paths
            times.append(ms)
        page.wait_for_function("() => window.workbench.state.series", timeout=30_000)
        page.wait_for_timeout(400)                # the state's plots and check, before the next edit
    return times


def first_picture(browser, url, models) -> dict[str, float]:
    out = {}
    for path in models:
        for warm in (True, False):
            context = browser.new_context(viewport={"width": 1400, "height": 1000})
            page = context.new_page()
            page.goto(f"{url}&open={path.name}")
            wait_model(page, path.name)
            if not warm:
                out[path.stem] = page.evaluate("() => window.workbench.state.firstPaint") / 1000
            context.close()
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--core", type=int, default=0, help="the core the server runs on")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--json", default=str(ROOT / "benchmarks" / "workbench_latest.json"))
    args = parser.parse_args(argv)
    from playwright.sync_api import sync_playwright
    folder = Path(tempfile.mkdtemp(prefix="mbplanar-bench-"))
    models = linkage_models()
    for path in models:
        shutil.copy(path, folder / path.name)
    proc, url = start_server(folder, args.core)
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, args=FLAGS)
            page = browser.new_page(viewport={"width": 1400, "height": 1000})
            drags = [drag(page, url) for _ in range(args.rounds)]
            edits = edit(page, url, args.rounds)
            firsts = first_picture(browser, url, models)
            browser.close()
    finally:
        proc.send_signal(signal.SIGINT)      # Ctrl-C: the server stops its worker process too
        proc.wait(30)
        shutil.rmtree(folder, ignore_errors=True)
    figures = {"drag": statistics.median(drags), "edit": statistics.median(edits), "first": max(firsts.values())}
    result = {"date": datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC"), "load": os.getloadavg()[0],
              "server_core": args.core, "drag_per_s": drags, "edit_ms": edits, "first_s": firsts,
              "targets": [{"target": TARGETS[k][0], "value": round(v, 3), "limit": TARGETS[k][2],
                           "met": v >= TARGETS[k][2] if TARGETS[k][1] == ">=" else v <= TARGETS[k][2]}
                          for k, v in figures.items()]}
    Path(args.json).write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    print(f"workbench, server on core {args.core} (load {result['load']:.2f}), medians of {args.rounds} rounds")
    print(f"  drag, six-bar press: {figures['drag']:.0f} redraws/s  ({', '.join(f'{d:.0f}' for d in drags)})")
    print(f"  edit, class IV: {figures['edit']:.0f} ms  ({', '.join(f'{e:.0f}' for e in edits)})")
    print("  first picture: " + ", ".join(f"{k} {v:.2f} s" for k, v in firsts.items()))
    for t in result["targets"]:
        print(f"  {'met' if t['met'] else 'MISSED'}: {t['target']}: {t['value']} (limit {t['limit']})")
    return 0 if all(t["met"] for t in result["targets"]) else 1


if __name__ == "__main__":
    sys.exit(main())
