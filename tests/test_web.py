"""The workbench without a browser: the table and the text as two views of one model, the page's messages
(answered by `Workbench` with the library's own numbers), the web server's rules (token, folder, sizes,
malformed requests, two sessions) through Starlette's test client, the panels' command lines, the
`mbplanar serve` command (Ctrl-C stops it) and the Jupyter widget. The page itself is tested in a real
browser in test_browser.py."""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import signal
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from conftest import linkage_models

pytest.importorskip("tomlkit", reason="the workbench needs tomlkit (pip install -e '.[web]')")

from mbplanar.web import Workbench  # noqa: E402
from mbplanar.web._document import EditError, ModelDocument, locate, parse_cell  # noqa: E402
from mbplanar.web._wire import frame, pack  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"


def engine_of_text(text, source="t.toml"):
    return mbplanar.Engine(mbplanar.parse_model(tomllib.loads(text), source=source))


def answers(bench, message):
    return {m["type"]: m for m in bench.answers(message)}


# -- the table and the text -------------------------------------------------------------------------------
def test_a_cell_edit_changes_that_value_only_and_keeps_the_comments():
    text = (MODELS / "six_bar_press.toml").read_text(encoding="utf-8")
    doc = ModelDocument(text, "six_bar_press.toml")
    new = doc.set_cell("links", 1, "length", "1.5")
    assert new.replace("length = 1.5,", "length = 1.445,") == text          # nothing else moved
    before, after = tomllib.loads(text), tomllib.loads(new)
    after["links"][1]["length"] = 1.445
    assert after == before
    mech = mbplanar.parse_model(tomllib.loads(new))
    assert mech.links["2"].lengths[0][2] == 1.5


def test_the_table_lists_every_section_with_its_rows():
    text = (MODELS / "six_bar_press.toml").read_text(encoding="utf-8")
    sections = {s["name"]: s for s in ModelDocument(text).sections()}
    assert list(sections)[:6] == ["model", "links", "joints", "points", "input", "loads"]
    assert {"dynamics", "dynamics.flywheel"} <= set(sections)
    joints = sections["joints"]
    assert joints["columns"][:4] == ["name", "type", "links", "at"] and len(joints["rows"]) == 7
    assert joints["rows"][6][joints["columns"].index("guide")] == "0.0"
    assert sections["links"]["rows"][2][sections["links"]["columns"].index("lengths")] == \
        '[["C", "B", 0.85], ["C", "D", 1.7], ["B", "D", 0.85]]'


@pytest.mark.parametrize("was_string, typed, expected", [
    (True, "crank", "crank"), (True, "1", "1"), (True, '"1"', "1"), (False, "1", 1), (False, "0.5", 0.5),
    (False, "[0.1, 0.2]", [0.1, 0.2]), (False, "true", True), (False, "cw", "cw"), (True, "[1, 2]", [1, 2])])
def test_a_cell_reads_strings_as_strings_and_the_rest_as_toml(was_string, typed, expected):
    value = parse_cell(typed, was_string)
    assert (value.unwrap() if hasattr(value, "unwrap") else value) == expected


def test_a_cell_that_is_not_toml_is_refused_at_its_row():
    doc = ModelDocument((MODELS / "fourbar.toml").read_text(encoding="utf-8"))
    with pytest.raises(EditError, match=r"joints\[1\].*not a TOML value") as info:
        doc.set_cell("joints", 1, "at", "[0.1, ")
    assert (info.value.section, info.value.row) == ("joints", 1)
    with pytest.raises(EditError, match="no row 9"):
        doc.set_cell("joints", 9, "at", "[0, 0]")
    with pytest.raises(EditError, match="column's name"):
        doc.set_cell("joints", 1, "a b", "1")


def test_rows_are_added_and_deleted():
    text = (MODELS / "fourbar.toml").read_text(encoding="utf-8")
    rows = len(tomllib.loads(text)["points"])
    added = ModelDocument(text).add_row("points")
    assert tomllib.loads(added)["points"][rows] == {}
    named = ModelDocument(added).set_cell("points", rows, "name", "N")
    assert tomllib.loads(named)["points"][rows] == {"name": "N"}
    assert tomllib.loads(ModelDocument(named).delete_row("points", rows)) == tomllib.loads(text)
    with pytest.raises(EditError, match="one table"):
        ModelDocument(text).add_row("input")


@pytest.mark.parametrize("section, row, key, value, where", [
    ("joints", 2, "links", '["2", "9"]', ("joints", 2)),
    ("links", 1, "length", "-0.3", ("links", 1)),
    ("points", 0, "along", '["A", "Q"]', ("points", 0)),
    ("input", None, "joint", "Q", ("input", 0)),
    ("loads", 0, "link", "7", ("loads", 0)),
    ("model", None, "ground", "9", None),
])
def test_an_error_of_the_model_is_located_at_its_row(section, row, key, value, where):
    """The library's own error (as the CLI prints it) for a broken cell names a row that the table finds."""
    text = ModelDocument((MODELS / "fourbar_loaded.toml").read_text(encoding="utf-8")).set_cell(section, row, key, value)
    with pytest.raises(mbplanar.MbplanarError) as info:
        engine_of_text(text)
    found = locate(info.value.where, str(info.value), tomllib.loads(text))
    if where is None:
        assert "line" not in found
    else:
        assert (found["section"], found["row"]) == where, str(info.value)


def test_a_syntax_error_is_located_at_its_line():
    bench = Workbench('name = "x"\nground = "0\n', "x.toml")
    doc = answers(bench, {"type": "hello"})["document"]
    assert doc["errors"][0]["line"] == 2 and "TOML syntax error" in doc["errors"][0]["message"]


def test_dragging_a_joint_rewrites_coordinates_lengths_and_drawn_at_so_the_model_is_drawn_there():
    """Moving A of the loaded four-bar (lengths and drawn_at given) in edit mode: the crank's and the
    coupler's lengths and the input's drawn_at are rewritten, and the model read back is drawn with A where
    it was dropped (to the rounding of the table, 1e-4 of the drawing)."""
    text = (MODELS / "fourbar_loaded.toml").read_text(encoding="utf-8")
    bench = Workbench(text, "fourbar_loaded.toml")
    list(bench.answers({"type": "hello"}))
    target = [0.03, 0.12]
    out = answers(bench, {"type": "move", "name": "A", "xy": target})
    data = tomllib.loads(bench.text)
    assert data["joints"][1]["at"] == target
    assert data["links"][0]["length"] == pytest.approx(math.hypot(*target), abs=1e-5)
    assert data["input"]["drawn_at"] == pytest.approx(math.degrees(math.atan2(target[1], target[0])), abs=1e-4)
    engine = engine_of_text(bench.text)
    assert engine.mech.joints["A"].at == pytest.approx(target, abs=1e-4)
    assert engine.mech.joints["B"].at == pytest.approx(bench_engine_b(text), abs=2e-4)
    assert "picture" in out and not out["document"]["errors"]
    assert "# crank OA" in bench.text                    # comments stay
    list(bench.answers({"type": "undo"}))
    assert bench.text == text


def bench_engine_b(text):
    return engine_of_text(text).mech.joints["B"].at


def test_undo_and_redo_walk_the_history_and_typing_is_one_step():
    text = (MODELS / "fourbar.toml").read_text(encoding="utf-8")
    bench = Workbench(text, "fourbar.toml")
    list(bench.answers({"type": "hello"}))
    for k in range(1, 4):                                        # three keystrokes in a burst
        list(bench.answers({"type": "text", "text": text + "#" * k}))
    list(bench.answers({"type": "cell", "section": "links", "row": 0, "key": "length", "value": "0.12"}))
    assert bench.at == 2 and "length = 0.12" in bench.text
    undo = answers(bench, {"type": "undo"})
    assert bench.text == text + "###" and undo["document"]["redo"]
    list(bench.answers({"type": "undo"}))
    assert bench.text == text and not answers(bench, {"type": "undo"}).get("document")
    list(bench.answers({"type": "redo"}))
    assert bench.text == text + "###"


# -- what the page draws is what the engine solved ---------------------------------------------------------
@pytest.mark.parametrize("path", linkage_models(), ids=lambda p: p.stem)
def test_the_picture_and_a_pose_are_the_engines(path, capsys):
    """The picture's frames are the CLI's cycle (`cycle_motion`), a pose is `mbplanar solve`'s document (the
    engine of a state that has walked its cycle may close a position a few 1e-13 m apart from a new one's)."""
    from mbplanar.viz import cycle_motion
    bench = Workbench(path.read_text(encoding="utf-8"), str(path))
    out = answers(bench, {"type": "hello"})
    assert not out["document"]["errors"]
    pic = out["picture"]
    cycle = cycle_motion(mbplanar.Engine(mbplanar.read_model(path)), 360)
    xy = np.stack([cycle.xy[:, cycle.point(n)] for n in pic["joints"]], axis=1)
    assert np.allclose(pic["frames"]["joint_xy"], xy, rtol=0, atol=1e-12)   # (an engine met before may have
    # walked further on its branch: the same positions to its closure tolerance)
    values = list(pic["frames"]["phi"][len(cycle.phi) // 3])
    pose = next(bench.answers({"type": "solve", "values": values, "id": 7}))
    assert pose["id"] == 7 and "error" not in pose
    assert mbplanar.cli.main(["solve", str(path), "--at", ",".join(repr(float(v)) for v in values), "--json"]) == 0
    solved = json.loads(capsys.readouterr().out)
    assert pose["numbers"].keys() == solved.keys() - {"partials"} and pose["numbers"]["points"].keys() == solved["points"].keys()
    for name, point in solved["points"].items():        # the same document, to the closure tolerance
        for q in ("x", "y"):
            assert pose["numbers"]["points"][name][q] == pytest.approx(point[q], abs=1e-9)
    for name, link in solved["links"].items():
        assert pose["numbers"]["links"][name]["omega"] == pytest.approx(link["omega"], rel=1e-8, abs=1e-9)


def test_a_pose_past_a_motion_limit_is_refused_with_the_engines_message():
    path = MODELS / "crank_slider_rocker_locking.toml"
    bench = Workbench(path.read_text(encoding="utf-8"), str(path))
    list(bench.answers({"type": "hello"}))
    pose = next(bench.answers({"type": "solve", "values": [3.0], "id": 1}))
    assert "motion limit" in pose["error"] and "frame" not in pose


def test_marks_are_the_checks_limits_and_dead_centres():
    path = MODELS / "crank_slider_rocker_locking.toml"
    bench = Workbench(path.read_text(encoding="utf-8"), str(path))
    marks = answers(bench, {"type": "hello"})["marks"]["marks"]
    report = mbplanar.check(mbplanar.Engine(mbplanar.read_model(path)))
    assert sorted(m["at"] for m in marks if m["kind"] == "limit") == sorted(lim.phi for lim in report.limits)
    assert any(m["kind"] == "dead" for m in marks)


def test_the_series_are_the_columns_of_sweep(capsys, tmp_path):
    path = MODELS / "fourbar_loaded.toml"
    bench = Workbench(path.read_text(encoding="utf-8"), str(path))
    series = next(m for m in bench.answers({"type": "hello"}) if m["type"] == "series")
    columns = {c["name"]: c["values"] for c in series["groups"][0]["columns"]}
    csv = tmp_path / "sweep.csv"
    assert mbplanar.cli.main(["sweep", str(path), "--steps", "359", "--to", "359", "--omega", "10",
                              "-o", str(csv)]) == 0
    header = csv.read_text().splitlines()[0].split(",")
    table = np.genfromtxt(csv, delimiter=",", skip_header=1)
    for name in ("B.x[m]", "3.omega[rad/s]", "transmission.A-B-C[deg]", "O.balancing[N*m]"):
        assert np.allclose(columns[name], table[:, header.index(name)], rtol=1e-10, atol=1e-10), name


def test_a_message_travels_as_json_and_one_buffer_of_float64():
    header, buffer = pack({"type": "t", "a": np.array([[1.0, np.nan], [3.0, 4.0]]), "b": [np.float64(2.5), 1]})
    assert header == {"type": "t", "a": {"$": 0, "shape": [2, 2]}, "b": [2.5, 1]}
    values = np.frombuffer(buffer, "<f8")
    assert values[0] == 1.0 and math.isnan(values[1])
    blob = frame(header, buffer)
    assert blob[:4] == b"MBP1" and (8 + int.from_bytes(blob[4:8], "little")) % 8 == 0


# -- the server's rules --------------------------------------------------------------------------------------
@pytest.fixture
def client(tmp_path):
    pytest.importorskip("starlette", reason="the server needs the web extra")
    pytest.importorskip("httpx", reason="Starlette's test client needs httpx")
    import warnings
    with warnings.catch_warnings():       # Starlette >= 1.0 would rather have httpx2 drive its test client
        warnings.simplefilter("ignore")
        from starlette.testclient import TestClient

    from mbplanar.cli import build_parser
    from mbplanar.web import create_app
    from mbplanar.web._runs import EXPORTS, PANELS, form
    folder = tmp_path / "served"
    folder.mkdir()
    for name in ("fourbar.toml", "fourbar_loaded.toml"):
        (folder / name).write_text((MODELS / name).read_text(encoding="utf-8"), encoding="utf-8")
    (tmp_path / "secret.toml").write_text((MODELS / "fourbar.toml").read_text(encoding="utf-8"), encoding="utf-8")
    (folder / "link.toml").symlink_to(tmp_path / "secret.toml")
    app = create_app(folder, forms={n: form(build_parser(n), n) for n in PANELS + EXPORTS})
    with TestClient(app) as c:
        c.token, c.folder = app.state.token, folder
        yield c


def receive_until(ws, kind, limit=40):
    seen = []
    for _ in range(limit):
        message = ws.receive()
        if message.get("bytes") is not None:
            data = message["bytes"]
            length = int.from_bytes(data[4:8], "little")
            msg = json.loads(data[8:8 + length])
        else:
            msg = json.loads(message["text"])
        seen.append(msg["type"])
        if msg["type"] in ((kind,) if isinstance(kind, str) else kind):
            return msg
    raise AssertionError(f"no {kind!r} among {seen}")


def test_every_request_needs_the_token(client):
    from starlette.websockets import WebSocketDisconnect
    for url in ("/", "/static/workbench.js", "/api/files", "/api/files?token=wrong"):
        answer = client.get(url)
        assert answer.status_code == 403 and "token" in answer.text, url
    assert client.get(f"/?token={client.token}").status_code == 200
    assert client.get("/static/workbench.js").status_code == 200          # the page's cookie carries it now
    client.cookies.clear()
    assert client.get("/static/workbench.js", headers={"X-Mbplanar-Token": client.token}).status_code == 200
    with pytest.raises(WebSocketDisconnect):
        with client.websocket_connect("/ws") as ws:
            ws.receive_text()
    with pytest.raises(WebSocketDisconnect):
        with client.websocket_connect(f"/ws?token={client.token}", headers={"Origin": "http://evil.example"}) as ws:
            ws.receive_text()


def test_only_the_folders_models_are_served(client):
    with client.websocket_connect(f"/ws?token={client.token}") as ws:
        welcome = receive_until(ws, "welcome")
        paths = [f["path"] for f in welcome["files"] if f["where"] == "folder"]
        assert "fourbar.toml" in paths and "link.toml" not in paths
        for bad, why in (("../secret.toml", "outside the served folder"), ("/etc/passwd.toml", "absolute path"),
                         ("link.toml", "outside the served folder"), ("fourbar.py", "only .toml and .csv"),
                         ("gallery/nothing.toml", "no such model")):
            ws.send_text(json.dumps({"type": "open", "path": bad}))
            refused = receive_until(ws, "refused")
            assert why in refused["message"], bad
        ws.send_text(json.dumps({"type": "open", "path": "fourbar.toml"}))
        assert receive_until(ws, "picture")["model"] == "fourbar"
        ws.send_text(json.dumps({"type": "save_as", "path": "../escaped.toml"}))
        assert "outside" in receive_until(ws, "refused")["message"]
        ws.send_text(json.dumps({"type": "save_as", "path": "gallery/fourbar.toml"}))
        assert "read-only" in receive_until(ws, "refused")["message"]
    assert not (client.folder.parent / "escaped.toml").exists()


def test_oversized_and_malformed_requests_get_a_4xx_and_the_server_goes_on(client):
    with client.websocket_connect(f"/ws?token={client.token}") as ws:
        session = receive_until(ws, "welcome")["session"]
        big = client.post(f"/api/upload?session={session}&name=big.toml&token={client.token}", content=b"#" * 1_100_000)
        assert big.status_code == 413 and "at most" in big.text
        bad = client.post(f"/api/upload?session={session}&name=bad.toml&token={client.token}", content=b"\xff\xfe")
        assert bad.status_code == 400 and "UTF-8" in bad.text
        assert client.post(f"/api/upload?session=nobody&token={client.token}", content=b"x").status_code == 400
        for text in ("{not json", json.dumps([1, 2]), json.dumps({"type": 5}), json.dumps({"type": "cell"})):
            ws.send_text(text)
            assert receive_until(ws, ("error", "edit_error"))["message"]
        ws.send_text(json.dumps({"type": "text", "text": "#" * 1_100_000}))
        assert "at most 1 MB" in receive_until(ws, "error")["message"]
        good = client.post(f"/api/upload?session={session}&name=up.toml&token={client.token}",
                           content=(MODELS / "slider_crank.toml").read_bytes())
        assert good.status_code == 200
        assert receive_until(ws, "picture")["model"] == "slider_crank"
        ws.send_text(json.dumps({"type": "save"}))
        assert receive_until(ws, "save_as_needed")
        ws.send_text(json.dumps({"type": "save_as", "path": "up.toml"}))
        assert receive_until(ws, "saved")["path"] == "up.toml"
    assert (client.folder / "up.toml").read_bytes() == (MODELS / "slider_crank.toml").read_bytes()
    assert client.get(f"/api/files?token={client.token}").status_code == 200


def test_two_sessions_are_independent(client):
    with client.websocket_connect(f"/ws?token={client.token}") as one, \
            client.websocket_connect(f"/ws?token={client.token}") as two:
        for ws in (one, two):
            receive_until(ws, "welcome")
            ws.send_text(json.dumps({"type": "open", "path": "fourbar.toml"}))
            receive_until(ws, "picture")
        one.send_text(json.dumps({"type": "cell", "section": "links", "row": 0, "key": "length", "value": "0.12"}))
        assert "0.12" in receive_until(one, "document")["text"]
        two.send_text(json.dumps({"type": "undo"}))
        two.send_text(json.dumps({"type": "solve", "id": 1, "values": [30]}))
        pose = receive_until(two, "pose")
        assert pose["numbers"]["points"]["A"]["x"] == pytest.approx(0.1 * math.cos(math.radians(30)), abs=1e-15)


def test_a_panel_runs_the_cli_and_its_files_are_downloaded(client):
    with client.websocket_connect(f"/ws?token={client.token}") as ws:
        session = receive_until(ws, "welcome")["session"]
        ws.send_text(json.dumps({"type": "open", "path": "fourbar_loaded.toml"}))
        receive_until(ws, "picture")
        ws.send_text(json.dumps({"type": "run", "id": "a", "command": "forces", "values": {"at": "60"}}))
        done = receive_until(ws, "run_done", limit=200)
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            mbplanar.cli.main(["forces", str(client.folder / "fourbar_loaded.toml"), "--at", "60"])
        assert done["code"] == 0 and done["stdout"] == out.getvalue()
        assert done["argv"] == ["mbplanar", "forces", "fourbar_loaded.toml", "--at", "60"]
        ws.send_text(json.dumps({"type": "run", "id": "b", "command": "sweep",
                                 "values": {"output": "cycle.csv", "steps": "12"}}))
        done = receive_until(ws, "run_done", limit=200)
        assert done["code"] == 0 and [f["name"] for f in done["files"]] == ["cycle.csv"]
        csv = client.get(f"/{done['files'][0]['url']}?token={client.token}")
        assert csv.status_code == 200 and csv.text.startswith("phi[deg],")
        assert client.get(f"/api/download/{session}/1/..%2Fsecret.toml?token={client.token}").status_code == 404
        for values, why in (({"output": "../x.csv"}, "file name"), ({"variants": "../secret.toml"}, "outside")):
            ws.send_text(json.dumps({"type": "run", "id": "c", "command": "study" if "variants" in values else "sweep",
                                     "values": values}))
            assert why in receive_until(ws, "run_done", limit=200)["stderr"]


def test_the_accuracy_panel_runs_the_command_and_offers_its_csv(client):
    """The accuracy panel on a model with [tolerances]: the command's summary and its CSV; on a model
    with a gear pair, its pitch radius among the ranked dimensions."""
    section = ('\n[tolerances]\noutputs = ["P"]\ndimensions = [{ name = "joints.G.radius_a", band = 0.00001 },'
               ' { name = "joints.E.x", band = 0.00002 }]\n')
    (client.folder / "geared_five_bar.toml").write_text((MODELS / "geared_five_bar.toml").read_text(encoding="utf-8")
                                                        + section, encoding="utf-8")
    with client.websocket_connect(f"/ws?token={client.token}") as ws:
        receive_until(ws, "welcome")
        ws.send_text(json.dumps({"type": "open", "path": "fourbar.toml"}))
        receive_until(ws, "picture")
        ws.send_text(json.dumps({"type": "run", "id": "a", "command": "accuracy",
                                 "values": {"samples": "200", "positions": "12", "output": "acc.csv"}}))
        done = receive_until(ws, "run_done", limit=400)
        assert done["code"] == 0 and [f["name"] for f in done["files"]] == ["acc.csv"]
        csv = client.get(f"/{done['files'][0]['url']}?token={client.token}")
        assert csv.status_code == 200 and "M.x" in csv.text.splitlines()[0]
        assert len(csv.text.splitlines()) == 13
        ws.send_text(json.dumps({"type": "open", "path": "geared_five_bar.toml"}))
        receive_until(ws, "picture")
        ws.send_text(json.dumps({"type": "run", "id": "b", "command": "accuracy",
                                 "values": {"samples": "10", "positions": "12"}}))
        done = receive_until(ws, "run_done", limit=400)
        assert done["code"] == 0 and "joints.G.radius_a" in done["stdout"], done["stderr"]


def test_the_panels_forms_follow_the_cli_parser():
    from mbplanar.cli import build_parser
    from mbplanar.web._runs import argv, form
    fields = form(build_parser("synth"), "synth")
    assert fields[0]["kind"] == "sub" and set(fields[0]["choices"]) == {"seed001", "function", "motion", "path"}
    path = {f["dest"]: f for f in fields[0]["choices"]["path"]["fields"]}
    assert path["input"]["kind"] == "read" and path["output"]["kind"] == "write" and path["progress"]["kind"] == "flag"
    assert path["vary"]["append"]

    class Files:
        def model(self):
            return "/run/m.toml"

        def read(self, name):
            return f"/folder/{name}"

        def write(self, name):
            return f"/run/{name}"
    args = argv(fields, {"problem": "path", "input": "targets.csv", "vary": "a=1:2\nb=3:4", "--progress": True,
                         "seed": "3", "output": "best.toml"}, Files())
    assert args[:2] == ["path", "/folder/targets.csv"]
    assert build_parser("synth").parse_args(["synth"] + args).vary == ["a=1:2", "b=3:4"]
    check = form(build_parser("check"), "check")
    assert argv(check, {"--json": True}, Files()) == ["/run/m.toml", "--json"]
    study = form(build_parser("study"), "study")
    assert "--no-progress" in argv(study, {"--no-progress": True, "variants": "v.csv"}, Files())


# -- the command -----------------------------------------------------------------------------------------
def test_serve_prints_its_url_refuses_without_the_token_and_stops_on_ctrl_c(tmp_path):
    pytest.importorskip("uvicorn", reason="mbplanar serve needs the web extra")
    import urllib.error
    import urllib.request
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    proc = subprocess.Popen([sys.executable, "-m", "mbplanar", "serve", str(MODELS / "fourbar.toml"), "--port", "0",
                             "--no-browser"], stderr=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=env)
    try:
        line = ""
        end = time.monotonic() + 30
        while "http://" not in line and time.monotonic() < end:
            line = proc.stderr.readline()
        url = line.strip()
        assert url.startswith("http://127.0.0.1:") and "?token=" in url
        assert urllib.request.urlopen(url, timeout=10).status == 200
        with pytest.raises(urllib.error.HTTPError) as refused:
            urllib.request.urlopen(url.split("?")[0], timeout=10)
        assert refused.value.code == 403
        children = _children(proc.pid)            # the worker process of the plots and the check
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=15)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0 and "stopped" in err and "Traceback" not in err
    end = time.monotonic() + 10
    while any(os.path.exists(f"/proc/{pid}") for pid in children) and time.monotonic() < end:
        time.sleep(0.1)
    assert not [pid for pid in children if os.path.exists(f"/proc/{pid}")], "a process outlived the server"


def _children(pid: int) -> list[int]:
    """The processes `pid` started (Linux), waited for up to 10 s: the server starts its worker at once."""
    path = Path(f"/proc/{pid}/task/{pid}/children")
    end = time.monotonic() + 10
    while path.exists() and not path.read_text().split() and time.monotonic() < end:
        time.sleep(0.1)
    return [int(p) for p in path.read_text().split()] if path.exists() else []


def test_serve_warns_beyond_loopback_and_refuses_a_missing_folder(capsys):
    from mbplanar.web.command import is_loopback
    assert is_loopback("127.0.0.1") and is_loopback("::1") and is_loopback("localhost") and is_loopback("127.0.0.2")
    assert not is_loopback("0.0.0.0") and not is_loopback("192.168.1.4") and not is_loopback("example.org")
    assert mbplanar.cli.main(["serve", "no/such/folder", "--no-browser"]) == 2
    assert "no such model or folder" in capsys.readouterr().err


def test_serve_beyond_loopback_prints_a_warning(tmp_path):
    pytest.importorskip("uvicorn", reason="mbplanar serve needs the web extra")
    proc = subprocess.Popen([sys.executable, "-m", "mbplanar", "serve", str(tmp_path), "--host", "0.0.0.0",
                             "--port", "0", "--no-browser"], stderr=subprocess.PIPE, text=True,
                            env=dict(os.environ, PYTHONUNBUFFERED="1"))
    try:
        first = proc.stderr.readline()
        proc.send_signal(signal.SIGINT)
        proc.communicate(timeout=15)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert "warning: --host 0.0.0.0 listens beyond this machine" in first


# -- Jupyter -----------------------------------------------------------------------------------------------
def test_the_widget_uses_the_pages_javascript_and_answers_as_the_server_does():
    pytest.importorskip("anywidget", reason="mbplanar.widget needs anywidget (the widget extra)")
    from mbplanar.web._server import STATIC
    w = mbplanar.widget(MODELS / "fourbar_loaded.toml")
    assert w._esm == (STATIC / "workbench.js").read_text(encoding="utf-8")    # the page's own file
    sent = []
    w.send = lambda content, buffers=None: sent.append((content, buffers))
    w._answer(w, {"type": "hello"})
    w._answer(w, {"type": "solve", "id": 3, "values": [60.0]})
    kinds = [c["type"] for c, _ in sent]
    assert kinds[:2] == ["document", "picture"] and kinds[-1] == "pose"
    header, buffers = sent[-1]
    xy = np.frombuffer(buffers[0], "<f8")
    ref = header["frame"]["joint_xy"]
    b = mbplanar.position(mbplanar.Engine(mbplanar.read_model(MODELS / "fourbar_loaded.toml")), math.radians(60.0))
    assert xy[ref["$"]:ref["$"] + 8].reshape(4, 2)[2] == pytest.approx(b.xy[b.point("B")], abs=1e-12)
    engine = mbplanar.Engine(mbplanar.read_model(MODELS / "slider_crank.toml"))
    fixed = mbplanar.widget(engine)
    assert fixed.bench.engine is engine and fixed.bench.fixed
