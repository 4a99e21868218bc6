// mbplanar workbench: the page of `mbplanar serve` and the Jupyter widget `mbplanar.widget` (one file).
//
// The page draws and edits; Python solves. Every pose drawn is one the engine solved and sent
// (a frame of the cycle, or a position asked for with a `solve` message), every number shown comes
// from mbplanar's own documents and tables, every panel runs the CLI's own command.
//
// Messages are JSON objects; their numbers come as views of one Float64Array (see _wire.py).

const SVGNS = "http://www.w3.org/2000/svg";
const COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2",
                "#7f7f7f", "#bcbd22"];
const INK = "#1a1a1a", LINK_FILL = "#cfe0f3", BLOCK_FILL = "#f3e3c3";
const VEL = "#c0392b", ACC = "#2e86c1", REACTION = "#1e8449", IC = "#8e44ad";
// a higher pair's lines as the CLI's diagram draws them (viz/_plotting.PAIR_STYLES): width × the bar's, dashed, fill
const PAIR_STYLES = { pitch: [0.35, true, null], rack: [0.35, true, null], profile: [0.55, false, "#e8eef5"],
                      roller: [0.45, false, "white"], knife: [0.6, false, null], face: [0.7, false, null],
                      slot: [0.35, false, null], "slot-centre": [0.2, true, null] };
const CYCLE_SECONDS = 6;          // one cycle at speed 1×
let instances = 0;

// -- wire --------------------------------------------------------------------------------------------
function revive(value, data) {
  if (Array.isArray(value)) return value.map(v => revive(v, data));
  if (value && typeof value === "object") {
    if ("$" in value && "shape" in value) {
      const size = value.shape.reduce((a, b) => a * b, 1);
      const arr = data.subarray(value["$"], value["$"] + size);
      arr.shape = value.shape;
      return arr;
    }
    const out = {};
    for (const k of Object.keys(value)) out[k] = revive(value[k], data);
    return out;
  }
  return value;
}

function floats(buffer, byteOffset, byteLength) {
  if (byteOffset % 8 === 0) return new Float64Array(buffer, byteOffset, byteLength / 8);
  return new Float64Array(buffer.slice(byteOffset, byteOffset + byteLength));
}

export function decodeFrame(arrayBuffer) {
  const view = new DataView(arrayBuffer);
  const magic = String.fromCharCode(view.getUint8(0), view.getUint8(1), view.getUint8(2), view.getUint8(3));
  if (magic !== "MBP1") throw new Error("not a workbench message");
  const length = view.getUint32(4, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(arrayBuffer, 8, length)));
  const start = 8 + length;
  return revive(header, floats(arrayBuffer, start, arrayBuffer.byteLength - start));
}

export function websocketTransport(url) {
  const listeners = [], openers = [], closers = [];
  let ws = null, queue = [];
  function connect() {
    ws = new WebSocket(url);
    ws.binaryType = "arraybuffer";
    ws.onopen = () => { for (const m of queue) ws.send(m); queue = []; openers.forEach(f => f()); };
    ws.onmessage = ev => {
      let msg;
      try { msg = typeof ev.data === "string" ? JSON.parse(ev.data) : decodeFrame(ev.data); }
      catch (e) { msg = { type: "error", message: "a message the page cannot read: " + e }; }
      listeners.forEach(f => f(msg));
    };
    ws.onclose = ev => closers.forEach(f => f(ev));
  }
  connect();
  return {
    send(obj) { const text = JSON.stringify(obj); if (ws.readyState === 1) ws.send(text); else queue.push(text); },
    onmessage(f) { listeners.push(f); },
    onopen(f) { openers.push(f); },
    onclose(f) { closers.push(f); },
    sendRaw(text) { ws.send(text); },
  };
}

function widgetTransport(model) {
  const listeners = [];
  model.on("msg:custom", (content, buffers) => {
    let data = new Float64Array(0);
    if (buffers && buffers.length) {
      const b = buffers[0];
      data = floats(b.buffer, b.byteOffset, b.byteLength);
    }
    const msg = revive(content, data);
    listeners.forEach(f => f(msg));
  });
  return { send(obj) { model.send(obj); }, onmessage(f) { listeners.push(f); }, onopen(f) { f(); },
           onclose() {} };
}

// -- small helpers -------------------------------------------------------------------------------------
function h(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (v === undefined || v === null || v === false) continue;
    if (k.startsWith("on")) e.addEventListener(k.slice(2), v);
    else if (k === "class") e.className = v;
    else if (k === "text") e.textContent = v;
    else if (k in e && typeof v !== "string") e[k] = v;
    else e.setAttribute(k, v === true ? "" : v);
  }
  for (const c of children.flat()) if (c !== null && c !== undefined) e.append(c.nodeType ? c : String(c));
  return e;
}

function s(tag, attrs = {}, parent = null) {
  const e = document.createElementNS(SVGNS, tag);
  for (const [k, v] of Object.entries(attrs)) if (v !== undefined && v !== null) e.setAttribute(k, v);
  if (parent) parent.appendChild(e);
  return e;
}

function g6(v) {
  if (v === null || v === undefined || Number.isNaN(v)) return "—";
  if (v === 0) return "0";
  const t = Number(v).toPrecision(6);
  return String(Number(t));
}

function pts(arr, offset, n) {
  let out = "";
  for (let k = 0; k < n; k++) out += (k ? " " : "") + arr[offset + 2 * k] + "," + arr[offset + 2 * k + 1];
  return out;
}

function finite(...xs) { return xs.every(x => x !== null && x !== undefined && Number.isFinite(x)); }

function niceStep(span, count) {
  const raw = span / Math.max(count, 1);
  const p = Math.pow(10, Math.floor(Math.log10(raw)));
  for (const m of [1, 2, 2.5, 5, 10]) if (m * p >= raw) return m * p;
  return 10 * p;
}

// -- the workbench -------------------------------------------------------------------------------------
export function mount(root, transport, options = {}) {
  const id = `mbw${++instances}`;
  const widget = !!options.widget;
  const token = options.token || "";
  const st = {
    picture: null, frames: null, cycleForces: null, drawn: null, series: null, marks: [],
    shown: null, frame: 0, values: [], playing: false, speed: 1, pos: 0, editing: false,
    show: { paths: true, velocities: false, accelerations: false, centres: false, reactions: false, labels: true },
    speedMode: "analogues", document: null, sentText: null, files: [], forms: {}, panels: [], exports: [],
    session: null, plots: [], numbers: null, pending: null, inflight: false, requestId: 0, runs: {},
    lastError: null, redraws: 0, poses: 0,
  };
  root.innerHTML = "";
  const top = h("div", { class: "mbw" + (widget ? " mbw-widget" : "") });
  root.append(top);

  // toolbar ------------------------------------------------------------------------------------------
  const el = {};
  el.status = h("div", { class: "mbw-status", "data-role": "status" }, "connecting …");
  if (!widget) {
    el.gallery = h("select", { "data-role": "gallery", title: "the bundled models", onchange: e => {
      if (e.target.value) openPath(e.target.value); e.target.value = ""; } });
    el.folder = h("select", { "data-role": "folder", title: "the models of the served folder", onchange: e => {
      if (e.target.value) openPath(e.target.value); e.target.value = ""; } });
    el.upload = h("input", { type: "file", accept: ".toml", class: "mbw-hidden", onchange: e => upload(e.target.files[0]) });
    el.save = h("button", { "data-role": "save", onclick: () => send({ type: "save" }) }, "Save");
    el.saveName = h("input", { type: "text", "data-role": "save-name", placeholder: "name.toml" });
    el.saveAs = h("button", { "data-role": "save-as", onclick: () => saveAs(false) }, "Save as");
    el.undo = h("button", { "data-role": "undo", disabled: true, onclick: () => send({ type: "undo" }) }, "Undo");
    el.redo = h("button", { "data-role": "redo", disabled: true, onclick: () => send({ type: "redo" }) }, "Redo");
    el.exports = h("span", { class: "mbw-exports" });
    el.title = h("span", { class: "mbw-title", "data-role": "title" }, "mbplanar");
    top.append(h("div", { class: "mbw-bar" }, el.title, el.gallery, el.folder,
      h("button", { onclick: () => el.upload.click(), title: "open a model from this computer (at most 1 MB)" }, "Open file…"),
      el.upload, h("span", { class: "mbw-sep" }), el.save, el.saveName, el.saveAs, h("span", { class: "mbw-sep" }),
      el.undo, el.redo, h("span", { class: "mbw-sep" }), h("span", {}, "Export:"), el.exports), el.status);
  } else {
    top.append(el.status);
  }
  const grid = h("div", { class: "mbw-grid" });
  top.append(grid);

  // the diagram ---------------------------------------------------------------------------------------
  el.svg = s("svg", { class: "mbw-svg", "data-role": "diagram" });
  el.svg.setAttribute("preserveAspectRatio", "xMidYMid meet");
  el.play = h("button", { "data-role": "play", onclick: () => setPlaying(!st.playing) }, "Play");
  el.range = h("input", { type: "range", min: 0, max: 0, value: 0, step: 1, "data-role": "slider",
                          oninput: () => { setPlaying(false); showFrame(+el.range.value, true); } });
  el.marks = h("div", { class: "mbw-marks", "data-role": "marks" });
  el.values = h("span", { class: "mbw-values" });
  el.speed = h("select", { "data-role": "speed", title: "animation speed (1×: a cycle in 6 s)",
                           onchange: e => { st.speed = +e.target.value; } },
               ...[0.25, 0.5, 1, 2, 4].map(v => h("option", { value: v, selected: v === 1 }, `${v}×`)));
  el.edit = h("button", { "data-role": "edit", title: "drag the joints' drawn positions; the table follows",
                          onclick: () => setEditing(!st.editing) }, "Edit mode");
  el.legend = h("div", { class: "mbw-legend", "data-role": "legend" });
  el.toggles = h("div", { class: "mbw-toggles" });
  for (const [key, label] of [["paths", "paths"], ["velocities", "velocities"], ["accelerations", "accelerations"],
                              ["centres", "instantaneous centres"], ["reactions", "reactions & balancing load"],
                              ["labels", "labels"]]) {
    const box = h("input", { type: "checkbox", checked: st.show[key], "data-toggle": key,
                             onchange: e => { st.show[key] = e.target.checked; redraw();
                                              if (key === "reactions" && st.shown && st.shown.kind === "pose") solveShown(); } });
    el.toggles.append(h("label", {}, box, " ", label));
  }
  el.speedMode = h("select", { "data-role": "speed-mode", title: "the speeds of the numbers",
                               onchange: e => { st.speedMode = e.target.value; solveShown(); } },
                   h("option", { value: "analogues" }, "ω = 1 (as mbplanar solve)"),
                   h("option", { value: "model" }, "the model's ω"));
  el.numbers = h("div", { class: "mbw-numbers", "data-role": "numbers" });
  const diagramBox = h("div", { class: "mbw-box mbw-diagram" }, h("h3", { "data-role": "picture-title" }, "Diagram"),
    el.svg, h("div", { class: "mbw-controls" }, el.play, h("div", { class: "mbw-slider" }, el.range, el.marks),
      el.values, el.speed, widget ? null : el.edit), el.toggles, el.legend,
    h("div", { class: "mbw-toggles" }, "numbers at ", el.speedMode), el.numbers);
  grid.append(diagramBox);

  // plots ---------------------------------------------------------------------------------------------
  el.plots = h("div", { class: "mbw-plots", "data-role": "plots" });
  el.addPlot = h("button", { "data-role": "add-plot", onclick: () => { st.plots.push({ columns: [] }); renderPlots(); } },
                 "+ plot");
  el.sweep = h("div", { class: "mbw-plot-head mbw-hidden", "data-role": "input-sweep" });
  grid.append(h("div", { class: "mbw-box" }, h("h3", {}, "Plots against the input ", el.addPlot), el.sweep, el.plots));

  // table and text ------------------------------------------------------------------------------------
  if (!widget) {
    el.table = h("div", { class: "mbw-table", "data-role": "table" });
    el.text = h("textarea", { spellcheck: false, "data-role": "text", oninput: onTyping });
    el.problems = h("div", { class: "mbw-problems", "data-role": "problems" });
    grid.append(h("div", { class: "mbw-box" }, h("h3", {}, "Table"), el.table));
    grid.append(h("div", { class: "mbw-box mbw-text" }, h("h3", {}, "Text (TOML)"), el.problems, el.text));
    el.tabs = h("div", { class: "mbw-tabs", "data-role": "panel-tabs" });
    el.panel = h("div", { "data-role": "panel" });
    grid.append(h("div", { class: "mbw-box mbw-full" }, h("h3", {}, "Analyses (the CLI's commands)"), el.tabs, el.panel));
  }

  // -- messages ---------------------------------------------------------------------------------------
  function send(obj) { transport.send(obj); }
  function status(text, bad = false) {
    el.status.textContent = text;
    el.status.classList.toggle("bad", !!bad);
  }
  transport.onclose(() => status("the connection to the server is closed: reload the page once it runs again", true));
  transport.onopen(() => { if (widget) send({ type: "hello" }); });
  transport.onmessage(msg => {
    try { receive(msg); } catch (e) { status("page error: " + e, true); console.error(e); }
  });

  function receive(msg) {
    switch (msg.type) {
      case "welcome": return welcome(msg);
      case "document": return showDocument(msg);
      case "picture": return showPicture(msg);
      case "forces": st.cycleForces = msg; return redraw();
      case "series":
        if (stale(msg)) return;
        if (msg.more) st.settled = msg.version;   // the state's last answer (the machine dynamics)
        if (msg.more && st.series) {
          st.series.groups = st.series.groups.filter(g => !msg.groups.some(m => m.name === g.name)).concat(msg.groups);
          if (msg.error) st.series.error = msg.error;
        } else st.series = msg;
        return renderPlots();
      case "marks": if (stale(msg)) return; st.marks = msg.marks || []; return renderMarks();
      case "pose": return showPose(msg);
      case "edit_error": return showEditError(msg);
      case "error": return status(msg.message, true);
      case "refused": return status(`refused: ${msg.message}`, true);
      case "files": st.files = msg.files; return fillFiles();
      case "saved":
        st.files = msg.files; fillFiles();
        if (st.document) { st.document.name = msg.path; st.document.dirty = false; }
        if (el.title) el.title.textContent = `mbplanar — ${msg.path}`;
        return status(`saved ${msg.path}`);
      case "save_as_needed": status(msg.message, true); el.saveName && el.saveName.focus(); return;
      case "confirm_overwrite":
        if (confirm(`${msg.path} exists: overwrite it?`)) saveAs(true); return;
      case "run_started": return runStarted(msg);
      case "run_progress": return runProgress(msg);
      case "run_done": return runDone(msg);
    }
  }

  function stale(msg) { return msg.version !== undefined && st.picture && msg.version !== st.picture.version; }

  function welcome(msg) {
    st.session = msg.session; st.files = msg.files; st.forms = msg.forms || {};
    st.panels = msg.panels || []; st.exports = msg.exports || [];
    fillFiles(); renderPanels(); renderExports();
    const first = options.open || msg.initial;
    if (first) openPath(first); else status(`serving ${msg.folder}: open a model (folder or gallery)`);
  }

  function openPath(path) { status(`opening ${path} …`); send({ type: "open", path }); }

  function fillFiles() {
    if (!el.gallery) return;
    el.gallery.replaceChildren(h("option", { value: "" }, "Gallery …"),
      ...st.files.filter(f => f.where === "gallery" && ["model", "cam"].includes(f.kind))
        .map(f => h("option", { value: f.path, title: f.title },
                    `${f.path.replace(/^gallery\//, "").replace(/\.toml$/, "")} — ${f.title}`)));
    el.folder.replaceChildren(h("option", { value: "" }, "Folder …"),
      ...st.files.filter(f => f.where === "folder" && f.path.endsWith(".toml"))
        .map(f => h("option", { value: f.path }, f.path)));
  }

  async function upload(file) {
    if (!file) return;
    if (!st.session) return status("not connected", true);
    const url = `api/upload?session=${encodeURIComponent(st.session)}&name=${encodeURIComponent(file.name)}` +
                `&token=${encodeURIComponent(token)}`;
    const answer = await fetch(url, { method: "POST", body: file });
    if (!answer.ok) status(await answer.text(), true); else status(`opened ${file.name} (not saved in the folder yet)`);
    el.upload.value = "";
  }

  function saveAs(overwrite) {
    const path = (el.saveName.value || "").trim();
    if (!path) { status("give the new file's name (relative to the served folder)", true); el.saveName.focus(); return; }
    send({ type: "save_as", path: path.endsWith(".toml") ? path : path + ".toml", overwrite });
  }

  // -- the document: table, text, errors ----------------------------------------------------------------
  function showDocument(doc) {
    st.document = doc;
    if (el.title) el.title.textContent = `mbplanar — ${doc.name}${doc.dirty ? " *" : ""}`;
    if (el.undo) { el.undo.disabled = !doc.undo; el.redo.disabled = !doc.redo; }
    if (el.text && doc.text !== el.text.value && doc.text !== st.sentText) {
      const focused = document.activeElement === el.text;
      const [a, b] = [el.text.selectionStart, el.text.selectionEnd];
      el.text.value = doc.text;
      if (focused) el.text.setSelectionRange(Math.min(a, doc.text.length), Math.min(b, doc.text.length));
    }
    if (doc.text === st.sentText) st.sentText = null;
    renderTable(doc);
    renderProblems(doc);
    if (doc.errors.length) status(doc.errors[0].message, true);
    else if (doc.note) status(doc.note);
    else status(`${doc.name}: ${doc.warnings.length ? doc.warnings.length + " warning(s)" : "no error"}`);
  }

  function renderProblems(doc) {
    if (!el.problems) return;
    const items = [];
    for (const e of doc.errors) items.push(h("div", { class: "error", "data-role": "problem", onclick: () => focusProblem(e) },
      e.message));
    for (const w of doc.warnings) items.push(h("div", { class: "warn", onclick: () => focusProblem(w) }, "warning: " + w.message));
    if (doc.note) items.push(h("div", { class: "note" }, doc.note));
    el.problems.replaceChildren(...items);
  }

  function focusProblem(p) {
    if (p.line && el.text) {
      const lines = el.text.value.split("\n");
      let start = 0;
      for (let k = 0; k < p.line - 1 && k < lines.length; k++) start += lines[k].length + 1;
      el.text.focus();
      el.text.setSelectionRange(start, start + (lines[p.line - 1] || "").length);
    } else if (p.section !== undefined) {
      const row = el.table.querySelector(`tr[data-section="${CSS.escape(p.section)}"][data-row="${p.row}"] input`);
      if (row) row.focus();
    }
  }

  let typing = null;
  function onTyping() {
    clearTimeout(typing);
    typing = setTimeout(() => {
      const text = el.text.value;
      if (text.length > 1048576) return status("a model's text is at most 1 MB", true);
      st.sentText = text;
      send({ type: "text", text });
    }, 60);
  }

  const extraColumns = {};
  function renderTable(doc) {
    if (!el.table) return;
    const focus = document.activeElement && el.table.contains(document.activeElement) ?
      [document.activeElement.dataset.section, document.activeElement.dataset.row, document.activeElement.dataset.key] : null;
    const problems = {};
    for (const [kind, list] of [["bad", doc.errors], ["warned", doc.warnings]])
      for (const p of list) if (p.section !== undefined) {
        const key = `${p.section}#${p.row}`;
        (problems[key] = problems[key] || []).push([kind, p.message]);
      }
    const parts = [];
    if (!doc.sections.length && doc.errors.length) parts.push(h("p", {}, "The text does not parse: correct it in the text."));
    for (const sec of doc.sections) {
      const columns = [...sec.columns, ...(extraColumns[sec.name] || []).filter(c => !sec.columns.includes(c))];
      const newCol = h("input", { class: "newcol", placeholder: "+ column", title: "add a column (a key of the rows)",
        onkeydown: e => { if (e.key === "Enter" && e.target.value.trim()) {
          (extraColumns[sec.name] = extraColumns[sec.name] || []).push(e.target.value.trim()); renderTable(st.document); } } });
      const head = h("h4", {}, sec.name, sec.kind === "rows" ?
        h("button", { "data-role": "add-row", onclick: () => send({ type: "add_row", section: sec.name }) }, "+ row") : null, newCol);
      const table = h("table", { "data-section": sec.name });
      table.append(h("tr", {}, ...columns.map(c => h("th", {}, c)), h("th", {})));
      sec.rows.forEach((row, r) => {
        const rowIndex = sec.kind === "rows" ? r : null;
        const tr = h("tr", { "data-section": sec.name, "data-row": rowIndex === null ? 0 : r });
        columns.forEach((c, k) => {
          const value = k < sec.columns.length ? row[k] : "";
          const input = h("input", { value, "data-section": sec.name, "data-row": rowIndex === null ? "" : r, "data-key": c,
            title: value, onchange: e => send({ type: "cell", section: sec.name, row: rowIndex, key: c, value: e.target.value }),
            onkeydown: e => { if (e.key === "Enter") e.target.blur(); } });
          tr.append(h("td", {}, input));
        });
        tr.append(h("td", { class: "act" }, sec.kind === "rows" ? h("button", { title: "delete this row",
          onclick: () => send({ type: "delete_row", section: sec.name, row: r }) }, "×") : null));
        const found = problems[`${sec.name}#${r}`] || (sec.kind !== "rows" ? problems[`${sec.name}#0`] : null);
        table.append(tr);
        if (found) {
          tr.classList.add(found.some(f => f[0] === "bad") ? "bad" : "warned");
          for (const [kind, message] of found)
            table.append(h("tr", { class: "msg" + (kind === "bad" ? "" : " warn"), "data-role": "row-error" },
              h("td", { colspan: columns.length + 1 }, message)));
        }
      });
      parts.push(head, table);
    }
    el.table.replaceChildren(...parts);
    if (focus) {
      const again = el.table.querySelector(`input[data-section="${CSS.escape(focus[0] || "")}"][data-row="${focus[1]}"][data-key="${CSS.escape(focus[2] || "")}"]`);
      if (again) again.focus();
    }
  }

  function showEditError(msg) {
    status(msg.message, true);
    if (!el.table || msg.section === null || msg.section === undefined) return;
    const row = el.table.querySelector(`tr[data-section="${CSS.escape(msg.section)}"][data-row="${msg.row ?? 0}"]`);
    if (row) {
      row.classList.add("bad");
      row.after(h("tr", { class: "msg", "data-role": "row-error" }, h("td", { colspan: row.children.length }, msg.message)));
    }
  }

  // -- the picture ------------------------------------------------------------------------------------
  const view = {};
  function showPicture(pic) {
    const same = st.picture && st.picture.source === pic.source && st.picture.model === pic.model;
    const keepFrame = same ? st.frame : null;
    if (!same) { st.extraGroups = null; st.plots = []; }
    st.picture = pic; st.frames = pic.frames; st.drawn = pic.drawn; st.cycleForces = null;
    const n = pic.frames.count;
    el.range.max = Math.max(n - 1, 0);
    buildScene(pic);
    renderValues(pic);
    renderSweepForm(pic);
    const title = diagramBox.querySelector("[data-role=picture-title]");
    title.textContent = `${pic.title}` + (pic.message ? ` — ${pic.message}` : "");
    renderMarks();
    st.pictures = (st.pictures || 0) + 1;
    const count = st.pictures;
    requestAnimationFrame(() => {            // (times for benchmarks/workbench.py: the picture is on screen)
      st.paintedAt = performance.now(); st.painted = count;
      if (st.firstPaint === undefined) st.firstPaint = st.paintedAt;
    });
    if (st.editing) showDrawn();
    else if (same && st.shown && st.shown.kind === "pose" && st.values.length === pic.inputs.length) solve(st.values);
    else showFrame(keepFrame !== null ? Math.min(keepFrame, n - 1) : 0, true);
  }

  function buildScene(pic) {
    const svg = el.svg;
    svg.replaceChildren();
    const [x0, x1, y0, y1] = pic.extent;
    svg.setAttribute("viewBox", `${x0} ${-y1} ${x1 - x0} ${y1 - y0}`);
    const size = pic.size, lw = 0.012 * size;
    view.size = size; view.lw = lw;
    const defs = s("defs", {}, svg);
    for (const [name, color] of [["v", VEL], ["a", ACC], ["r", REACTION]]) {
      const m = s("marker", { id: `${id}-arrow-${name}`, viewBox: "0 0 10 10", refX: 9, refY: 5, markerWidth: 5,
                              markerHeight: 5, orient: "auto-start-reverse", markerUnits: "strokeWidth" }, defs);
      s("path", { d: "M0,0 L10,5 L0,10 z", fill: color }, m);
    }
    const world = s("g", { transform: "scale(1,-1)", stroke: INK, fill: "none", "stroke-width": lw * 0.3 }, svg);
    view.world = world;
    view.paths = s("g", { "data-layer": "paths" }, world);
    const ground = s("g", { "data-layer": "ground" }, world);
    view.guides = s("g", {}, world);
    view.pairLayer = s("g", { "data-layer": "pairs" }, world);
    view.links = s("g", { "data-layer": "links" }, world);
    view.blocks = s("g", {}, world);
    view.pins = s("g", { "data-layer": "pins" }, world);
    view.overlay = s("g", { "data-layer": "overlay" }, world);
    view.handles = s("g", { "data-layer": "handles" }, world);
    const texts = s("g", { "font-family": "sans-serif", "font-size": 0.045 * size, fill: INK }, svg);
    view.texts = texts;
    view.overlayText = s("g", { "font-family": "sans-serif", "font-size": 0.04 * size }, svg);
    const F = pic.frames;
    // ground: hatched guides and pivots (fixed), drawn from the first position as the CLI does
    F.sliders.forEach(sl => {
      if (!sl.grounded) return;
      const g = [sl.guide[0], sl.guide[1], sl.guide[2], sl.guide[3]];
      const ux = g[2] - g[0], uy = g[3] - g[1], len = Math.hypot(ux, uy) || 1;
      let nx = -uy / len, ny = ux / len;
      if (ny > 1e-9 || (Math.abs(ny) <= 1e-9 && nx > 0)) { nx = -nx; ny = -ny; }
      const off = 0.032 * size;
      s("polyline", { points: `${g[0]},${g[1]} ${g[2]},${g[3]}`, "stroke-width": lw * 0.3,
                      "stroke-dasharray": `${size * 0.03} ${size * 0.01}` }, ground);
      hatch(ground, [g[0] + off * nx, g[1] + off * ny], [g[2] + off * nx, g[3] + off * ny], [nx, ny], 0.022 * size, 0.025 * size);
    });
    for (const name of pic.pivots) {
      const j = pic.joints.indexOf(name);
      const x = F.joint_xy[2 * j], y = F.joint_xy[2 * j + 1];
      const hh = 0.055 * size, w = 0.032 * size;
      s("polygon", { points: `${x},${y} ${x - w},${y - hh} ${x + w},${y - hh}`, fill: "white", "data-pivot": name }, ground);
      hatch(ground, [x - 1.6 * w, y - hh], [x + 1.6 * w, y - hh], [0, -1], 0.35 * w, 0.45 * w);
    }
    // moving shapes, updated per frame
    const inputLinks = {};
    pic.inputs.forEach((inp, k) => {
      const [a, b] = inp.links;
      inputLinks[b !== pic.ground ? b : a] = k;
    });
    view.pairs = (F.pairs || []).map(pr => ({   // gears, racks, cams, slots: their lines, tooth marks, contact
      lines: pr.lines.map(ln => {
        const [width, dashed, fill] = PAIR_STYLES[ln.kind];
        return s(ln.closed ? "polygon" : "polyline", { "stroke-width": lw * width, fill: ln.closed && fill ? fill : "none",
          ...(dashed ? { "stroke-dasharray": `${size * 0.03} ${size * 0.01}` } : {}), "data-pair": pr.name }, view.pairLayer);
      }),
      marks: s("path", { "stroke-width": lw * 0.12, "data-pair": pr.name }, view.pairLayer),
      contact: s("circle", { r: 0.008 * size, fill: VEL, stroke: "none", "data-contact": pr.name }, view.pins),
    }));
    view.sliderGuides = F.sliders.map(sl => sl.grounded ? null :
      s("polyline", { "stroke-width": lw * 0.8, "stroke-linecap": "round" }, view.guides));
    view.links = F.links.map((lk, k) => {
      const grab = lk.name in inputLinks ? { class: "grab", "data-input": inputLinks[lk.name] } : {};
      const shape = lk.kind === "bar" ? s("polyline", { "stroke-width": lw, "stroke-linecap": "round", "data-link": lk.name, ...grab }, view.links)
        : lk.kind === "polygon" ? s("polygon", { fill: LINK_FILL, "stroke-width": lw * 0.75, "stroke-linejoin": "round", "data-link": lk.name, ...grab }, view.links)
        : null;
      const stubs = [];
      const m = lk.stubs.shape[1];
      for (let q = 0; q < m; q++) stubs.push(s("polyline", { "stroke-width": lw * 0.8, "stroke-linecap": "round", ...grab }, view.links));
      const label = s("text", { "font-weight": "bold", fill: COLORS[k % COLORS.length], "text-anchor": "middle",
                                "dominant-baseline": "middle", "data-label": lk.name }, texts);
      label.textContent = lk.name;
      return { shape, stubs, label };
    });
    view.blocks = F.sliders.map(sl => {
      const grabK = pic.inputs.findIndex(inp => inp.joint === sl.joint);
      const grab = grabK >= 0 ? { class: "grab", "data-input": grabK } : {};
      return s("polygon", { fill: BLOCK_FILL, "stroke-width": lw * 0.5, "data-slider": sl.joint, ...grab }, view.blocks);
    });
    view.pinEls = pic.revolute.map(name => s("circle", { r: 0.016 * size, fill: "white", "stroke-width": lw * 0.4,
                                                          "data-joint": name }, view.pins));
    view.pointEls = pic.points.map(name => {
      const centre = pic.centres.includes(name);
      return s("circle", { r: (centre ? 0.013 : 0.009) * size, fill: centre ? "white" : INK, "stroke-width": lw * 0.35,
                           "data-point": name }, view.pins);
    });
    view.jointLabels = pic.joints.map(name => {
      if (!pic.labels[name]) return null;
      const t = s("text", { "font-style": "italic", "data-joint-label": name }, texts);
      t.textContent = pic.labels[name];
      return t;
    });
    view.pointLabels = pic.points.map(name => {
      const t = s("text", { "font-size": 0.034 * size, fill: "#444" }, texts);
      t.textContent = name;
      return t;
    });
    drawPaths();
    svg.onpointerdown = pointerDown;
  }

  function hatch(parent, a, b, n, step, depth) {
    const ux = b[0] - a[0], uy = b[1] - a[1], len = Math.hypot(ux, uy) || 1;
    s("polyline", { points: `${a[0]},${a[1]} ${b[0]},${b[1]}`, "stroke-width": depth * 0.35 }, parent);
    const count = Math.max(Math.floor(len / step), 2);
    for (let k = 1; k <= count; k++) {
      const t = k / count, px = a[0] + t * ux, py = a[1] + t * uy;
      s("polyline", { points: `${px},${py} ${px + depth * n[0] - depth * ux / len},${py + depth * n[1] - depth * uy / len}` }, parent);
    }
  }

  function pointXY(F, name, b) {
    const pic = st.picture;
    let j = pic.joints.indexOf(name);
    if (j >= 0) { const J = pic.joints.length; return [F.joint_xy[(b * J + j) * 2], F.joint_xy[(b * J + j) * 2 + 1]]; }
    j = pic.points.indexOf(name);
    const P = pic.points.length;
    return [F.point_xy[(b * P + j) * 2], F.point_xy[(b * P + j) * 2 + 1]];
  }

  function drawPaths() {
    view.paths.replaceChildren();
    if (!st.show.paths || !st.frames) return;
    const F = st.frames, n = F.count;
    F.moving.forEach((name, k) => {
      let p = "";
      for (let b = 0; b < n; b++) { const [x, y] = pointXY(F, name, b); if (finite(x, y)) p += `${x},${y} `; }
      if (st.picture.full_turn && n > 2) { const [x, y] = pointXY(F, name, 0); p += `${x},${y}`; }
      s("polyline", { points: p, stroke: COLORS[k % COLORS.length], "stroke-width": view.lw * 0.3, opacity: 0.85,
                      "data-path": name }, view.paths);
    });
  }

  function drawFrame(F, b, forces) {
    const pic = st.picture, size = view.size, lw = view.lw;
    F.links.forEach((lk, k) => {
      const v = view.links[k];
      const n = lk.outline.shape[1];
      if (v.shape) v.shape.setAttribute("points", pts(lk.outline, b * n * 2, n));
      const m = lk.stubs.shape[1];
      for (let q = 0; q < m; q++) v.stubs[q].setAttribute("points", pts(lk.stubs, (b * m + q) * 4, 2));
      const lx = lk.label[2 * b], ly = lk.label[2 * b + 1];
      v.label.setAttribute("display", st.show.labels && finite(lx, ly) ? "inline" : "none");
      if (finite(lx, ly)) { v.label.setAttribute("x", lx); v.label.setAttribute("y", -ly); }
    });
    (F.pairs || []).forEach((pr, k) => {
      const v = view.pairs[k];
      pr.lines.forEach((ln, q) => { const n = ln.xy.shape[1]; v.lines[q].setAttribute("points", pts(ln.xy, b * n * 2, n)); });
      const m = pr.marks.shape[1], mk = pr.marks;
      let d = "";
      for (let q = 0; q < m; q++) { const o = (b * m + q) * 4; d += `M${mk[o]},${mk[o + 1]}L${mk[o + 2]},${mk[o + 3]}`; }
      v.marks.setAttribute("d", d);
      v.contact.setAttribute("cx", pr.contact[2 * b]); v.contact.setAttribute("cy", pr.contact[2 * b + 1]);
    });
    F.sliders.forEach((sl, k) => {
      view.blocks[k].setAttribute("points", pts(sl.corners, b * 8, 4));
      if (view.sliderGuides[k]) view.sliderGuides[k].setAttribute("points", pts(sl.guide, b * 4, 2));
    });
    const J = pic.joints.length;
    pic.revolute.forEach((name, k) => {
      const j = pic.joints.indexOf(name);
      view.pinEls[k].setAttribute("cx", F.joint_xy[(b * J + j) * 2]);
      view.pinEls[k].setAttribute("cy", F.joint_xy[(b * J + j) * 2 + 1]);
    });
    const P = pic.points.length;
    pic.points.forEach((name, k) => {
      const x = F.point_xy[(b * P + k) * 2], y = F.point_xy[(b * P + k) * 2 + 1];
      view.pointEls[k].setAttribute("cx", x); view.pointEls[k].setAttribute("cy", y);
      const t = view.pointLabels[k];
      t.setAttribute("display", st.show.labels ? "inline" : "none");
      t.setAttribute("x", x + 0.012 * size); t.setAttribute("y", -y + 0.035 * size);
    });
    pic.joints.forEach((name, j) => {
      const t = view.jointLabels[j];
      if (!t) return;
      t.setAttribute("display", st.show.labels ? "inline" : "none");
      t.setAttribute("x", F.joint_xy[(b * J + j) * 2] + 0.025 * size);
      t.setAttribute("y", -(F.joint_xy[(b * J + j) * 2 + 1] + 0.025 * size));
    });
    drawOverlay(F, b, forces);
    st.redraws++;
  }

  function arrow(parent, x, y, dx, dy, kind, color, width) {
    s("line", { x1: x, y1: y, x2: x + dx, y2: y + dy, stroke: color, "stroke-width": width,
                "marker-end": `url(#${id}-arrow-${kind})`, "data-vector": kind }, parent);
  }

  function drawOverlay(F, b, forces) {
    const pic = st.picture, size = view.size, lw = view.lw;
    view.overlay.replaceChildren();
    view.overlayText.replaceChildren();
    const legend = [];
    for (const [which, key, color] of [["v", "velocities", VEL], ["a", "accelerations", ACC]]) {
      if (!st.show[key]) continue;
      const arr = F[which], K = F.moving.length;
      let big = 0;
      for (let k = 0; k < K; k++) big = Math.max(big, Math.hypot(arr[(b * K + k) * 2], arr[(b * K + k) * 2 + 1]) || 0);
      if (!(big > 0)) continue;
      const scale = 0.3 * size / big;
      F.moving.forEach((name, k) => {
        const [x, y] = pointXY(F, name, b);
        const qx = arr[(b * K + k) * 2], qy = arr[(b * K + k) * 2 + 1];
        if (finite(x, y, qx, qy) && Math.hypot(qx, qy) > 1e-12 * big) arrow(view.overlay, x, y, qx * scale, qy * scale, which, color, lw * 0.35);
      });
      const unit = which === "v" ? "m/s" : "m/s²";
      legend.push(`${which === "v" ? "velocity" : "acceleration"}: ${g6(0.3 * size)} m ≙ ${g6(big)} ${unit}`);
    }
    if (st.show.centres) {
      const [x0, x1, y0, y1] = pic.extent, w = x1 - x0, hgt = y1 - y0, L = F.ic_links.length;
      F.ic_links.forEach((name, k) => {
        const x = F.ic[(b * L + k) * 2], y = F.ic[(b * L + k) * 2 + 1];
        if (!finite(x, y) || x < x0 - 1.5 * w || x > x1 + 1.5 * w || y < y0 - 1.5 * hgt || y > y1 + 1.5 * hgt) return;
        const d = 0.02 * size;
        s("path", { d: `M${x - d},${y - d}L${x + d},${y + d}M${x - d},${y + d}L${x + d},${y - d}`, stroke: IC,
                    "stroke-width": lw * 0.4, "data-ic": name }, view.overlay);
        const t = s("text", { x: x + 0.02 * size, y: -y - 0.02 * size, fill: IC }, view.overlayText);
        t.textContent = `P${name}0`;
      });
    }
    if (st.show.reactions) {
      if (!forces || !forces.reactions) legend.push(forces === null ? "reactions: solving …" :
        "reactions: the model has no loads, gravity or masses");
      else {
        let big = 0;
        const names = Object.keys(forces.reactions);
        for (const n of names) { const f = forces.reactions[n].f; big = Math.max(big, Math.hypot(f[2 * b], f[2 * b + 1]) || 0); }
        if (big > 0) {
          const scale = 0.3 * size / big, seen = {};
          for (const n of names) {
            const r = forces.reactions[n], fx = r.f[2 * b], fy = r.f[2 * b + 1];
            if (!finite(fx, fy) || Math.hypot(fx, fy) <= 1e-9 * big) continue;
            const [x, y] = r.at ? [r.at[2 * b], r.at[2 * b + 1]] : pointXY(F, n, b);   // (a higher pair: its contact)
            arrow(view.overlay, x, y, fx * scale, fy * scale, "r", REACTION, lw * 0.45);
            const key = `${Math.round((x + fx * scale) / (1e-4 * size))},${Math.round((y + fy * scale) / (1e-4 * size))}`;
            if (seen[key]) { seen[key].textContent += " = " + r.label; continue; }
            const t = s("text", { x: x + fx * scale + 0.01 * size, y: -(y + fy * scale) - 0.01 * size, fill: REACTION,
                                  "font-weight": "bold", "data-reaction": n }, view.overlayText);
            t.textContent = r.label;
            seen[key] = t;
          }
          legend.push(`reactions: ${g6(0.3 * size)} m ≙ ${g6(big)} N`);
        }
        for (const [n, q] of Object.entries(forces.balancing || {}))
          legend.push(`balancing ${q.unit === "N" ? "force" : "moment"} at ${n}: ${g6(q.values[b])} ${q.unit}`);
        if (forces.forces_message) legend.push(forces.forces_message);
      }
    }
    el.legend.textContent = legend.join("; ");
  }

  // which pose is shown -------------------------------------------------------------------------------
  function currentValues(F, b) {
    const n = st.picture.inputs.length;
    return Array.from({ length: n }, (_, k) => F.phi[b * n + k]);
  }

  function showFrame(k, askNumbers) {
    if (!st.frames || !st.frames.count) return;
    k = Math.max(0, Math.min(st.frames.count - 1, Math.round(k)));
    st.frame = k; st.shown = { kind: "frame", k };
    el.range.value = k;
    st.values = currentValues(st.frames, k);
    drawFrame(st.frames, k, st.cycleForces);
    setValueBoxes(st.values);
    updateCursors();
    if (askNumbers) scheduleNumbers();
  }

  let numbersTimer = null;
  function scheduleNumbers() {
    clearTimeout(numbersTimer);
    numbersTimer = setTimeout(() => solve(st.values, "numbers"), 80);
  }

  function solveShown() { if (st.values.length) solve(st.values, "numbers"); }

  function solve(values, why = "pose") {
    clearTimeout(numbersTimer);
    st.pending = { values: values.slice(), why };
    pump();
  }

  function pump() {
    if (st.inflight || !st.pending) return;
    const { values, why } = st.pending;
    st.pending = null; st.inflight = true;
    send({ type: "solve", id: ++st.requestId, values, why, speed: st.speedMode, forces: st.show.reactions });
  }

  function showPose(msg) {
    st.inflight = false;
    if (!st.picture || (msg.version !== undefined && msg.version !== st.picture.version)) {
      // the answer of a model that is no longer shown
    } else if (msg.error) {
      status(msg.error, true);
      el.numbers.dataset.error = msg.error;
    } else if (st.picture && !st.editing) {
      st.poses++;
      st.shown = { kind: "pose", pose: msg };
      drawFrame(msg.frame, 0, msg.frame);
      // a newer request waits: the boxes hold what was typed since, which this older answer must not undo
      if (!st.pending) { st.values = msg.values; setValueBoxes(msg.values); }
      if (msg.numbers) renderNumbers(msg);
      updateCursors();
      delete el.numbers.dataset.error;
      if (st.lastError === "pose") status(`${st.document ? st.document.name : ""}: solved`);
    }
    st.lastError = msg.error ? "pose" : null;
    pump();
  }

  function renderValues(pic) {
    el.values.replaceChildren(...pic.inputs.map((inp, k) => h("label", { title: `the input ${inp.name} (${inp.unit})` },
      ` ${inp.name} = `, h("input", { type: "number", step: "any", "data-input": k, "data-role": "value",
        onchange: () => { setPlaying(false); const vals = [...el.values.querySelectorAll("input")].map(i => +i.value);
                          solve(vals); nearestFrame(vals); } }), ` ${inp.unit}`)));
  }

  // several inputs: a path or a grid in input space, as `mbplanar sweep --from --to [--grid]` makes it
  function renderSweepForm(pic) {
    if (!el.sweep) return;
    const several = pic.inputs.length > 1 && st.exports.includes("sweep");
    el.sweep.classList.toggle("mbw-hidden", !several);
    if (!several) return;
    const list = k => pic.inputs.map(inp => String(+inp[k].toPrecision(8))).join(",");
    const from = h("input", { type: "text", value: list("lo"), size: 14, "data-role": "sweep-from", title: "--from: one value per input" });
    const to = h("input", { type: "text", value: list("hi"), size: 14, "data-role": "sweep-to", title: "--to: one value per input" });
    const steps = h("input", { type: "text", value: "36", size: 5, "data-role": "sweep-steps", title: "--steps" });
    const gridBox = h("input", { type: "checkbox", "data-role": "sweep-grid" });
    const go = h("button", { "data-role": "sweep-run", onclick: () => {
      const rid = `s${++st.requestId}`;
      st.runs[rid] = { sweep: true, grid: gridBox.checked };
      status("mbplanar sweep " + (gridBox.checked ? "(grid)" : "(path)") + " …");
      send({ type: "run", id: rid, command: "sweep", values: { start: from.value, stop: to.value, steps: steps.value,
                                                               "--grid": gridBox.checked, output: `${modelStem()}-inputs.csv` } });
    } }, "sweep");
    el.sweep.replaceChildren("inputs from ", from, " to ", to, " steps ", steps, h("label", {}, gridBox, " grid"), go);
  }

  async function sweepDone(msg, run) {
    if (!msg.files.length) return status(msg.stderr || "the sweep wrote nothing", true);
    const text = await (await fetch(fileUrl(msg.files[0]))).text();
    const [head, ...rows] = text.trim().split(/\r?\n/);
    const names = head.split(",");
    const cells = rows.map(r => r.split(",").map(c => (c === "" ? NaN : +c)));
    const column = k => Float64Array.from(cells, r => r[k]);
    const n = st.picture.inputs.length;
    const xk = run.grid ? n - 1 : 0;        // a grid: one line per value of the slower inputs, against the last
    const group = { name: `sweep ${run.grid ? "grid" : "path"} in input space (${msg.argv.slice(3).join(" ")})`,
                    grid: run.grid, x: [{ name: names[xk], values: column(xk) }],
                    columns: names.map((c, k) => ({ name: c, values: column(k) })).filter((c, k) => k !== xk) };
    st.extraGroups = [group];
    const spread = c => { let lo = Infinity, hi = -Infinity; for (const v of c.values) if (Number.isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); } return hi - lo; };
    const coords = group.columns.filter(c => /\.[xy]\[/.test(c.name));   // the point that moves most
    const first = coords.length ? coords.reduce((a, b) => (spread(b) > spread(a) ? b : a)) : group.columns[n - 1];
    st.plots.push({ columns: [`${allGroups().length - 1}:${first.name}`] });
    renderPlots();
    status(`${(msg.argv || []).join(" ")}: ${rows.length} positions` + (msg.stderr ? ` — ${msg.stderr}` : ""), !!msg.code);
  }

  function setValueBoxes(values) {
    el.values.querySelectorAll("input").forEach((box, k) => {
      if (document.activeElement !== box) box.value = String(+values[k].toPrecision(10));
    });
  }

  function nearestFrame(values) {
    const F = st.frames, n = st.picture.inputs.length;
    let best = 0, bd = Infinity;
    for (let b = 0; b < F.count; b++) {
      let d = 0;
      for (let k = 0; k < n; k++) d += (F.phi[b * n + k] - values[k]) ** 2;
      if (d < bd) { bd = d; best = b; }
    }
    st.frame = best; el.range.value = best;
  }

  function renderNumbers(msg) {
    const doc = msg.numbers, unit = st.picture.length_unit;
    // as mbplanar solve prints them: round-off below 1e-12 of the drawing's largest coordinate shown as 0
    const size = Math.max(1e-300, ...Object.values(doc.points).flatMap(p => [Math.abs(p.x), Math.abs(p.y)]));
    const shown = v => g6(Math.abs(v) < 1e-12 * size ? 0 : v);
    const at = msg.values.map(v => g6(v)).join(",");
    const caption = `mbplanar solve ${st.document ? st.document.name : ""} --at ${at}` +
      (msg.speed === "model" ? " --omega (the model's)" : "") + "   (SI units)";
    const points = h("table", { "data-role": "points" }, h("caption", {}, caption),
      h("tr", {}, ...["point", "x [m]", "y [m]", "vx [m/s]", "vy [m/s]", "ax [m/s²]", "ay [m/s²]"].map(t => h("th", {}, t))),
      ...Object.entries(doc.points).map(([name, p]) => h("tr", { "data-point": name }, h("td", {}, name),
        ...["x", "y", "vx", "vy", "ax", "ay"].map(q => h("td", { "data-q": q, "data-value": String(p[q]) }, shown(p[q]))))));
    const links = h("table", { "data-role": "links" },
      h("tr", {}, ...["link", "angle [°]", "ω [rad/s]", "ε [rad/s²]"].map(t => h("th", {}, t))),
      ...Object.entries(doc.links).map(([name, l]) => h("tr", { "data-link": name }, h("td", {}, name),
        h("td", { "data-value": String(l.angle) }, g6(l.angle * 180 / Math.PI)),
        h("td", { "data-value": String(l.omega) }, g6(l.omega)), h("td", { "data-value": String(l.epsilon) }, g6(l.epsilon)))));
    el.numbers.replaceChildren(points, links);
    el.numbers.dataset.values = JSON.stringify(msg.values);
    void unit;
  }

  // animation -------------------------------------------------------------------------------------------
  function setPlaying(on) {
    if (on && (!st.frames || st.editing)) return;
    st.playing = on;
    el.play.textContent = on ? "Pause" : "Play";
    el.play.classList.toggle("on", on);
    if (on) { st.pos = st.frame; st.last = performance.now(); requestAnimationFrame(tick); }
    else scheduleNumbers();
  }

  function tick(t) {
    if (!st.playing) return;
    const n = st.frames.count;
    st.pos = (st.pos + (t - st.last) / 1000 * n * st.speed / CYCLE_SECONDS) % n;
    st.last = t;
    const k = Math.floor(st.pos);
    if (k !== st.frame || !st.shown || st.shown.kind !== "frame") showFrame(k, false);
    requestAnimationFrame(tick);
  }

  function redraw() {
    if (!st.picture) return;
    drawPaths();
    if (st.editing && st.drawn) return drawFrame(st.drawn, 0, st.drawn);
    if (st.shown && st.shown.kind === "pose") drawFrame(st.shown.pose.frame, 0, st.shown.pose.frame);
    else if (st.frames) drawFrame(st.frames, st.frame, st.cycleForces);
  }

  function renderMarks() {
    el.marks.replaceChildren();
    if (!st.frames || !st.marks.length || st.picture.inputs.length !== 1) return;
    const F = st.frames, n = F.count;
    const mark = (where, m) => el.marks.append(h("div", { class: `mbw-mark ${m.kind}`, title: m.text, "data-mark": m.kind,
                                                         style: `left:${(100 * where).toFixed(3)}%` }));
    for (const m of st.marks) {
      let found = 0;
      for (let b = 0; b + 1 < n; b++) {            // where the cycle's input passes the mark's value
        const a = F.phi[b], c = F.phi[b + 1];
        if (a === c || (a - m.at) * (c - m.at) > 0 || c === m.at) continue;
        mark((b + (m.at - a) / (c - a)) / Math.max(n - 1, 1), m); found++;
      }
      if (F.phi[n - 1] === m.at) { mark(1, m); found++; }
      if (!found && m.kind === "limit") {          // a limit the cycle stops just short of: its nearest frames
        let best = Infinity;
        for (let b = 0; b < n; b++) best = Math.min(best, Math.abs(F.phi[b] - m.at));
        for (let b = 0; b < n; b++) if (Math.abs(F.phi[b] - m.at) <= best * (1 + 1e-9)) mark(b / Math.max(n - 1, 1), m);
      }
    }
  }

  // mouse ---------------------------------------------------------------------------------------------
  function toWorld(ev) {
    const m = view.world.getScreenCTM();
    if (!m) return [0, 0];
    const p = new DOMPoint(ev.clientX, ev.clientY).matrixTransform(m.inverse());
    return [p.x, p.y];
  }

  function capture(ev) {
    try { el.svg.setPointerCapture(ev.pointerId); } catch (e) { /* a pointer the browser does not track */ }
  }

  function pointerDown(ev) {
    if (!st.picture) return;
    const target = ev.target;
    if (st.editing) {
      const name = target.dataset.joint || target.dataset.point;
      if (!name) return;
      ev.preventDefault();
      capture(ev);
      const handle = s("circle", { r: 0.022 * view.size, fill: "none", stroke: "#d35400", "stroke-width": view.lw * 0.5,
                                   "data-role": "handle" }, view.handles);
      let last = 0, timer = null, xy = toWorld(ev);
      const move = e => {
        xy = toWorld(e);
        moved = true;
        handle.setAttribute("cx", xy[0]); handle.setAttribute("cy", xy[1]);
        const now = performance.now();
        clearTimeout(timer);
        if (now - last > 60) { last = now; send({ type: "move", name, xy }); }
        else timer = setTimeout(() => { last = performance.now(); send({ type: "move", name, xy }); }, 60);
      };
      handle.setAttribute("cx", xy[0]); handle.setAttribute("cy", xy[1]);
      let moved = false;
      const up = () => {
        clearTimeout(timer);
        if (moved) send({ type: "move", name, xy });
        handle.remove();
        el.svg.removeEventListener("pointermove", move);
        el.svg.removeEventListener("pointerup", up);
      };
      el.svg.addEventListener("pointermove", move);
      el.svg.addEventListener("pointerup", up);
      return;
    }
    // the input link's shapes, or what lies under a label or a pin drawn over them
    const grabbed = target.dataset && target.dataset.input !== undefined ? target :
      document.elementsFromPoint(ev.clientX, ev.clientY).find(e => el.svg.contains(e) && e.dataset && e.dataset.input !== undefined);
    if (!grabbed) return;
    ev.preventDefault();
    setPlaying(false);
    capture(ev);
    const k = +grabbed.dataset.input, inp = st.picture.inputs[k];
    const F = st.shown.kind === "pose" ? st.shown.pose.frame : st.frames;
    const b = st.shown.kind === "pose" ? 0 : st.frame;
    const start = st.values.slice(), p0 = toWorld(ev);
    const link = grabbed.dataset.link || inp.links[1];
    const sign = link === inp.links[0] ? -1 : 1;
    let value0 = start[k], turned = 0, lastAngle = null, dir = null, pivot = null;
    if (inp.kind === "R") {
      pivot = pointXY(F, inp.joint, b);
      lastAngle = Math.atan2(p0[1] - pivot[1], p0[0] - pivot[0]);
    } else {
      const sl = F.sliders.find(x => x.joint === inp.joint);
      const g = sl.guide, o = b * 4;
      const ux = g[o + 2] - g[o], uy = g[o + 3] - g[o + 1], len = Math.hypot(ux, uy) || 1;
      dir = [ux / len, uy / len];
    }
    const move = e => {
      const p = toWorld(e);
      let delta;
      if (inp.kind === "R") {
        const angle = Math.atan2(p[1] - pivot[1], p[0] - pivot[0]);
        let d = angle - lastAngle;
        d -= 2 * Math.PI * Math.round(d / (2 * Math.PI));
        turned += d; lastAngle = angle;
        delta = turned;
      } else delta = (p[0] - p0[0]) * dir[0] + (p[1] - p0[1]) * dir[1];
      const values = start.slice();
      values[k] = value0 + sign * delta / (inp.sense * inp.scale);
      last = values;
      solve(values, "drag");
    };
    let last = null;
    const up = () => {
      el.svg.removeEventListener("pointermove", move);
      el.svg.removeEventListener("pointerup", up);
      if (last) solve(last, "numbers");
    };
    el.svg.addEventListener("pointermove", move);
    el.svg.addEventListener("pointerup", up);
  }

  function setEditing(on) {
    st.editing = on;
    el.edit.classList.toggle("on", on);
    diagramBox.classList.toggle("editing", on);
    if (on) { setPlaying(false); showDrawn(); }
    else if (st.frames) showFrame(st.frame, true);
    for (const c of el.svg.querySelectorAll("[data-joint],[data-point]")) c.classList.toggle("handle", on);
  }

  function showDrawn() {
    if (!st.drawn) return;
    drawFrame(st.drawn, 0, st.drawn);
    st.values = currentValues(st.drawn, 0);
    setValueBoxes(st.values);
    for (const c of el.svg.querySelectorAll("[data-joint],[data-point]")) c.classList.add("handle");
    status("edit mode: drag a joint or a point; the table and the text follow (the drawn pose is shown)");
  }

  // plots ---------------------------------------------------------------------------------------------
  function allGroups() {
    return ((st.series && st.series.groups) || []).concat(st.extraGroups || []);
  }

  function columnsOf() {
    const out = [];
    allGroups().forEach((g, gi) => g.columns.forEach(c => out.push({ key: `${gi}:${c.name}`, group: g, column: c, gi })));
    return out;
  }

  function defaultPlots() {
    const cols = columnsOf().filter(c => c.gi === 0).map(c => c.column.name);
    const pick = [];
    const link = cols.find(c => /\.angle\[/.test(c) && !c.startsWith(st.picture.inputs[0].name));
    const angles = cols.filter(c => /\.angle\[/.test(c));
    if (angles.length > 1) pick.push({ columns: [`0:${angles[angles.length - 1]}`] });
    else if (link) pick.push({ columns: [`0:${link}`] });
    const bal = cols.find(c => c.includes(".balancing["));
    const tr = cols.find(c => c.startsWith("transmission."));
    if (bal) pick.push({ columns: [`0:${bal}`] });
    else if (tr) pick.push({ columns: [`0:${tr}`] });
    return pick.length ? pick : [{ columns: [] }];
  }

  function renderPlots() {
    if (!st.series && !st.extraGroups) return;
    if (!st.plots.length) st.plots = defaultPlots();
    const all = columnsOf();
    const byKey = Object.fromEntries(all.map(c => [c.key, c]));
    el.plots.replaceChildren(...st.plots.map((plot, pi) => {
      plot.columns = plot.columns.filter(k => byKey[k]);
      const select = h("select", { "data-role": "add-column", onchange: e => {
        if (e.target.value) { plot.columns.push(e.target.value); renderPlots(); } } },
        h("option", { value: "" }, "+ column …"),
        ...allGroups().map((g, gi) => h("optgroup", { label: g.name },
          ...g.columns.map(c => h("option", { value: `${gi}:${c.name}` }, c.name)))));
      const chips = plot.columns.map((k, ci) => h("span", { class: "mbw-chip", style: `color:${COLORS[ci % COLORS.length]}` },
        byKey[k].column.name, h("button", { title: "remove", onclick: () => { plot.columns.splice(ci, 1); renderPlots(); } }, "×")));
      const svg = s("svg", { "data-role": "plot", "data-plot": pi });
      const box = h("div", { class: "mbw-plot" }, h("div", { class: "mbw-plot-head" }, ...chips, select,
        h("button", { title: "remove this plot", onclick: () => { st.plots.splice(pi, 1); renderPlots(); } }, "remove plot")), svg);
      requestAnimationFrame(() => drawPlot(svg, plot, byKey));
      return box;
    }));
    if (st.series && st.series.error) el.plots.append(h("p", { class: "bad" }, st.series.error));
  }

  function drawPlot(svg, plot, byKey) {
    svg.replaceChildren();
    const W = svg.clientWidth || 480, H = svg.clientHeight || 170;
    svg.setAttribute("viewBox", `0 0 ${W} ${H}`);
    const series = plot.columns.map(k => byKey[k]).filter(Boolean);
    if (!series.length) { const t = s("text", { x: 10, y: 20, fill: "#888", "font-size": 12 }, svg); t.textContent = "choose columns to plot"; return; }
    let xmin = Infinity, xmax = -Infinity, ymin = Infinity, ymax = -Infinity;
    for (const c of series) {
      const x = c.group.x[0].values, y = c.column.values;
      for (let i = 0; i < y.length; i++) if (finite(x[i], y[i])) {
        xmin = Math.min(xmin, x[i]); xmax = Math.max(xmax, x[i]); ymin = Math.min(ymin, y[i]); ymax = Math.max(ymax, y[i]);
      }
    }
    if (!finite(xmin, xmax, ymin, ymax)) return;
    if (ymax - ymin < 1e-12 * Math.max(1, Math.abs(ymax))) { ymin -= 1; ymax += 1; }
    if (xmax === xmin) { xmin -= 1; xmax += 1; }
    const pad = (ymax - ymin) * 0.06; ymin -= pad; ymax += pad;
    const L = 58, R = 8, T = 6, B = 24;
    const X = x => L + (x - xmin) / (xmax - xmin) * (W - L - R), Y = y => H - B - (y - ymin) / (ymax - ymin) * (H - T - B);
    const axes = s("g", { "font-size": 10, fill: "#555", stroke: "none" }, svg);
    const xs = niceStep(xmax - xmin, 6), ys = niceStep(ymax - ymin, 4);
    for (let v = Math.ceil(xmin / xs) * xs; v <= xmax + 1e-9 * xs; v += xs) {
      s("line", { x1: X(v), x2: X(v), y1: T, y2: H - B, stroke: "#eee" }, axes);
      const t = s("text", { x: X(v), y: H - B + 12, "text-anchor": "middle" }, axes); t.textContent = g6(+v.toPrecision(10));
    }
    for (let v = Math.ceil(ymin / ys) * ys; v <= ymax + 1e-9 * ys; v += ys) {
      s("line", { x1: L, x2: W - R, y1: Y(v), y2: Y(v), stroke: "#eee" }, axes);
      const t = s("text", { x: L - 4, y: Y(v) + 3, "text-anchor": "end" }, axes); t.textContent = g6(+v.toPrecision(10));
    }
    const xl = s("text", { x: W - R, y: H - 2, "text-anchor": "end" }, axes); xl.textContent = series[0].group.x[0].name;
    s("rect", { x: L, y: T, width: W - L - R, height: H - T - B, fill: "none", stroke: "#bbb" }, svg);
    series.forEach((c, ci) => {
      const x = c.group.x[0].values, y = c.column.values;
      let d = "", pen = false;
      for (let i = 0; i < y.length; i++) {
        if (!finite(x[i], y[i])) { pen = false; continue; }
        if (c.group.grid && i > 0 && x[i] < x[i - 1]) pen = false;   // the next line of a grid
        d += (pen ? "L" : "M") + X(x[i]).toFixed(2) + "," + Y(y[i]).toFixed(2);
        pen = true;
      }
      s("path", { d, fill: "none", stroke: COLORS[ci % COLORS.length], "stroke-width": 1.5, "data-series": c.column.name }, svg);
    });
    const cursor = s("line", { y1: T, y2: H - B, stroke: "#d35400", "stroke-width": 1.2, "data-role": "cursor" }, svg);
    svg.plotMap = { X, xmin, xmax, L, R, W, cursor };
    svg.onclick = e => {
      const r = svg.getBoundingClientRect();
      const px = (e.clientX - r.left) / r.width * W;
      const x = xmin + (px - L) / (W - L - R) * (xmax - xmin);
      if (st.picture.inputs.length === 1 && x >= xmin && x <= xmax) {
        setPlaying(false);
        const vals = [x]; nearestFrame(vals); showFrame(st.frame, false); solve(vals);
      }
    };
    updateCursors();
  }

  function updateCursors() {
    if (!st.values.length) return;
    for (const svg of el.plots.querySelectorAll("svg[data-role=plot]")) {
      const m = svg.plotMap;
      if (!m) continue;
      const x = st.values[0];
      const on = x >= m.xmin && x <= m.xmax;
      m.cursor.setAttribute("display", on ? "inline" : "none");
      if (on) { m.cursor.setAttribute("x1", m.X(x)); m.cursor.setAttribute("x2", m.X(x)); }
      m.cursor.dataset.x = String(x);
    }
  }

  // panels and exports ---------------------------------------------------------------------------------
  const panelState = {};
  function renderPanels() {
    if (!el.tabs) return;
    el.tabs.replaceChildren(...st.panels.map(name => h("button", { "data-panel": name, onclick: () => showPanel(name) }, name)));
    if (st.panels.length) showPanel(st.panels[0]);
  }

  function showPanel(name) {
    for (const b of el.tabs.querySelectorAll("button")) b.classList.toggle("on", b.dataset.panel === name);
    if (!panelState[name]) panelState[name] = buildPanel(name);
    el.panel.replaceChildren(panelState[name].box);
  }

  function fileChoices(field) {
    const opts = [h("option", { value: "" }, field.required ? "(choose a file)" : "(none)")];
    if (field.dest !== "variants") opts.push(h("option", { value: "(editor)" }, "the model in the editor"));
    for (const f of st.files) opts.push(h("option", { value: f.path }, f.path));
    return opts;
  }

  function buildFields(fields, values, container, command) {
    for (const f of fields) {
      if (f.kind === "model") continue;
      if (f.kind === "sub") {
        const sub = h("div", { class: "mbw-form" });
        const select = h("select", { "data-dest": f.dest, onchange: () => { values[f.dest] = select.value; fill(); } },
          ...Object.keys(f.choices).map(c => h("option", { value: c }, c)));
        values[f.dest] = select.value;
        const help = h("div", { class: "help" });
        const fill = () => {
          for (const k of Object.keys(values)) if (k !== f.dest) delete values[k];
          sub.replaceChildren(); buildFields(f.choices[select.value].fields, values, sub, command);
          help.textContent = f.choices[select.value].help;
        };
        container.append(h("label", {}, f.dest), select, help, h("div", { style: "grid-column:1/-1" }, sub));
        fill();
        continue;
      }
      const label = (f.flag || f.dest) + (f.required && !f.flag ? " *" : "");
      let input;
      if (f.kind === "flag") {
        input = h("input", { type: "checkbox", "data-dest": f.dest, "data-flag": f.flag,
                             onchange: e => { values[f.flag] = e.target.checked; } });
      } else if (f.kind === "choice") {
        input = h("select", { "data-dest": f.dest, onchange: e => { values[f.dest] = e.target.value || null; } },
          h("option", { value: "" }, f.default !== null && f.default !== undefined ? `(default: ${f.default})` : "(none)"),
          ...f.choices.map(c => h("option", { value: c }, c)));
      } else if (f.kind === "read") {
        input = h("select", { "data-dest": f.dest, onchange: e => { values[f.dest] = e.target.value || null; } }, ...fileChoices(f));
      } else if (f.kind === "write") {
        const name = (f.default || "out.csv").replace("{model}", modelStem());
        const text = h("input", { type: "text", value: name, "data-dest": f.dest,
                                  oninput: e => { if (values[f.dest]) values[f.dest] = e.target.value; } });
        const on = h("input", { type: "checkbox", "data-write": f.dest,
                                onchange: e => { values[f.dest] = e.target.checked ? text.value : null; } });
        input = h("span", {}, on, " write ", text);
      } else if (f.append) {
        input = h("textarea", { rows: 2, "data-dest": f.dest, placeholder: "one per line",
                                oninput: e => { values[f.dest] = e.target.value; } });
      } else {
        input = h("input", { type: "text", "data-dest": f.dest, placeholder: f.default !== null && f.default !== undefined ?
          `default: ${f.default}` : (f.metavar || ""), oninput: e => { values[f.dest] = e.target.value; } });
      }
      container.append(h("label", {}, label), input);
      if (f.help) container.append(h("div", { class: "help" }, f.help));
    }
  }

  function modelStem() {
    const name = st.document ? st.document.name : "model.toml";
    return name.split("/").pop().replace(/\.toml$/, "");
  }

  function buildPanel(name) {
    const fields = st.forms[name] || [];
    const values = {};
    const form = h("div", { class: "mbw-form", "data-form": name });
    buildFields(fields, values, form, name);
    const usesAt = fields.some(f => f.dest === "at");
    const atShown = usesAt ? h("input", { type: "checkbox", checked: name === "forces", "data-role": "at-shown" }) : null;
    const out = h("div", { class: "mbw-out", "data-role": "output" });
    const progress = h("div", { class: "mbw-progress", "data-role": "progress" });
    const runButton = h("button", { "data-role": "run", onclick: () => {
      const vals = { ...values };
      if (atShown && atShown.checked && st.values.length) vals.at = st.values.map(v => String(v)).join(",");
      startRun(name, vals, panel);
    } }, `Run mbplanar ${name}`);
    const cancel = h("button", { "data-role": "cancel", disabled: true,
                                 onclick: () => { if (panel.current) send({ type: "cancel", id: panel.current }); } }, "Cancel");
    const panel = { box: null, out, progress, runButton, cancel, values, current: null };
    panel.box = h("div", { "data-panel-body": name }, form,
      h("div", { class: "mbw-run" }, runButton, cancel, atShown ? h("label", {}, atShown, " --at the shown position") : null,
        progress), out);
    return panel;
  }

  function startRun(command, values, panel) {
    const rid = `r${++st.requestId}`;
    st.runs[rid] = panel;
    panel.current = rid;
    panel.runButton.disabled = true; panel.cancel.disabled = false;
    panel.progress.textContent = "starting …";
    send({ type: "run", id: rid, command, values });
  }

  function runStarted(msg) {
    const p = st.runs[msg.id];
    if (p && p.progress) p.progress.textContent = msg.argv.join(" ");
  }

  function runProgress(msg) {
    const p = st.runs[msg.id];
    if (p && p.progress) p.progress.textContent = msg.line;
    else if (p) status(msg.line);
  }

  function fileUrl(f, inline) {
    return `${f.url}?token=${encodeURIComponent(token)}${inline ? "&inline=1" : ""}`;
  }

  function runDone(msg) {
    const p = st.runs[msg.id];
    delete st.runs[msg.id];
    if (!p) return;
    if (p.export) return exportDone(msg, p);
    if (p.sweep) return sweepDone(msg, p);
    p.runButton.disabled = false; p.cancel.disabled = true; p.current = null;
    p.progress.textContent = (msg.argv || []).join(" ") + (msg.cancelled ? "  — cancelled" : `  — exit ${msg.code}`);
    const parts = [];
    if (msg.stdout) parts.push(h("pre", { "data-role": "stdout" }, msg.stdout));
    if (msg.stderr) parts.push(h("pre", { class: msg.code ? "err" : "", "data-role": "stderr" }, msg.stderr));
    const files = (msg.files || []).map(f => fileView(f));
    if (files.length) parts.push(h("div", { class: "files" }, ...files));
    p.out.replaceChildren(...parts);
    p.out.dataset.code = msg.code;
  }

  function fileView(f) {
    if (f.kind === "image") return h("div", {}, h("img", { src: fileUrl(f, true), alt: f.name }), h("a", { href: fileUrl(f), download: f.name }, f.name));
    if (f.kind === "model") return h("span", {}, h("a", { href: fileUrl(f), download: f.name }, f.name), " ",
      h("button", { onclick: () => send({ type: "open", run: f.run, name: f.name }) }, "open in the editor"));
    if (f.kind === "page") return h("a", { href: fileUrl(f, true), target: "_blank", rel: "noopener" }, f.name);
    return h("a", { href: fileUrl(f), download: f.name }, f.name);
  }

  function renderExports() {
    if (!el.exports) return;
    const buttons = [];
    const add = (label, command, values) => buttons.push(h("button", { "data-export": label, onclick: () => runExport(label, command, values()) }, label));
    if (st.exports.includes("report")) add("report", "report", () => ({ output: `${modelStem()}.html` }));
    if (st.exports.includes("animate")) {
      add("animation", "animate", () => ({ output: `${modelStem()}-animation.html` }));
      add("GIF", "animate", () => ({ output: `${modelStem()}.gif` }));
    }
    if (st.exports.includes("sweep")) add("CSV", "sweep", () => ({ output: `${modelStem()}.csv`, steps: "360" }));
    if (st.exports.includes("plot")) for (const ext of ["png", "svg"])
      add(ext.toUpperCase(), "plot", () => ({ what: "diagram", output: `${modelStem()}.${ext}`,
        at: st.values.map(String).join(","), show: shownItems() }));
    el.exports.replaceChildren(...buttons);
  }

  function shownItems() {
    const items = [];
    if (st.show.velocities) items.push("velocities");
    if (st.show.accelerations) items.push("accelerations");
    if (st.show.reactions) items.push("reactions");
    if (st.show.centres) items.push("centres");
    return items.join(",") || null;
  }

  function runExport(label, command, values) {
    const rid = `x${++st.requestId}`;
    st.runs[rid] = { export: label };
    status(`export ${label}: running mbplanar ${command} …`);
    send({ type: "run", id: rid, command, values });
  }

  function exportDone(msg, p) {
    if (msg.code || !msg.files.length) return status(`export ${p.export}: ${msg.stderr || "no file"}`, true);
    for (const f of msg.files) {
      const a = h("a", { href: fileUrl(f), download: f.name, "data-role": "download" });
      document.body.append(a); a.click(); a.remove();
    }
    status(`exported ${msg.files.map(f => f.name).join(", ")} (${(msg.argv || []).join(" ")})`);
  }

  // keyboard: undo and redo outside the text fields
  if (!widget) document.addEventListener("keydown", e => {
    const inField = ["INPUT", "TEXTAREA", "SELECT"].includes((document.activeElement || {}).tagName);
    if (inField || !(e.ctrlKey || e.metaKey)) return;
    if (e.key === "z" && !e.shiftKey) { send({ type: "undo" }); e.preventDefault(); }
    if (e.key === "y" || (e.key === "z" && e.shiftKey)) { send({ type: "redo" }); e.preventDefault(); }
  });
  window.addEventListener("resize", () => { if (st.series) renderPlots(); });

  return { state: st, send, showFrame, solve, setPlaying, setEditing, openPath };
}

// anywidget: the Jupyter widget of mbplanar.widget() mounts the same workbench, without the file
// menu, the table, the text and the panels
export default {
  render({ model, el }) {
    mount(el, widgetTransport(model), { widget: true });
  },
};
