// The design page: the spec as a form and a table of taxels, live prediction and band chart, geometry preview,
// save/load/share, build with progress. BOOT (schema, initial values, templates) is set by the server.
const $ = (id) => document.getElementById(id);
const SVGNS = "http://www.w3.org/2000/svg";
const fields = BOOT.schema.filter((row) => !row.key.includes("[]"));
const taxelCols = BOOT.schema.filter((row) => /^taxel\[\]\.[a-z_]+$/.test(row.key))
  .map((row) => ({...row, name: row.key.split(".")[1]}));
const SHORT = {name: "name", x: "x", y: "y", cavity_diameter: "D", cavity_length: "L", neck_diameter: "d",
               cap_outer_diameter: "cap Ø", cap_top_thickness: "top", needle_theta_deg: "θ", needle_y: "needle y"};
const inputs = {};
let taxelRows = [];      // [{cells: {column: input}, extra: {...}}]: extra keeps what the table does not edit
let preserved = {};      // other arrays of tables ([[measured]], ...) passed through unchanged
let INITIAL = BOOT.initial;
window.matcad = {stages: [], bandsShownMs: null, riseShownMs: null, previewMs: [], editToSectionMs: [], meshMs: null,
                 moldMs: null, editAt: null};

function initialValue(key) {
  let node = INITIAL;
  for (const part of key.split(".")) { if (node === undefined || node === null) return undefined; node = node[part]; }
  return node;
}

function shown(row, value) {
  if (value === undefined || value === null) value = row.default;
  if (value === undefined || value === null) return "";
  if (Array.isArray(value)) return value.join(", ");
  return String(value);
}

function onEdit() { window.matcad.editAt = performance.now(); schedulePredict(); drawPlan(); }

function buildForm() {
  const holder = $("fields");
  holder.replaceChildren();
  for (const key of Object.keys(inputs)) delete inputs[key];
  const sections = {};
  for (const row of fields) {
    const section = row.key.includes(".") ? row.key.split(".")[0] : "design";
    if (!sections[section]) {
      const fs = document.createElement("fieldset");
      fs.id = "section-" + section;
      fs.innerHTML = `<legend>${section}</legend><div class="error" id="err-${section}"></div>`;
      holder.appendChild(fs);
      sections[section] = fs;
    }
    const div = document.createElement("div");
    div.className = "row";
    div.title = row.doc;
    const label = document.createElement("label");
    label.textContent = row.key.split(".").pop() + (row.required ? " *" : "");
    label.htmlFor = "in-" + row.key;
    let input;
    const value = initialValue(row.key);
    if (row.kind === "choice") {
      input = document.createElement("select");
      for (const c of row.choices) input.add(new Option(c, c));
      input.value = shown(row, value);
    } else if (row.kind === "bool") {
      input = document.createElement("input");
      input.type = "checkbox";
      input.checked = value !== undefined ? value : !!row.default;
    } else {
      input = document.createElement("input");
      input.type = "text";
      input.value = shown(row, value);
      if (row.default === null && !row.required_in_table) input.placeholder = "auto";
    }
    input.id = "in-" + row.key;
    input.name = row.key;
    input.addEventListener("input", onEdit);
    input.addEventListener("change", onEdit);
    inputs[row.key] = {row, input};
    const unit = document.createElement("span"); unit.className = "unit"; unit.textContent = row.unit;
    const allowed = document.createElement("span"); allowed.className = "allowed"; allowed.textContent = row.allowed;
    const err = document.createElement("div"); err.className = "error"; err.id = "err-" + row.key;
    div.append(label, input, unit, allowed, err);
    sections[section].appendChild(div);
  }
  preserved = {};
  for (const [key, value] of Object.entries(INITIAL)) {
    if (key !== "taxel" && Array.isArray(value) && value.length && typeof value[0] === "object") preserved[key] = value;
  }
  buildTaxels(Array.isArray(INITIAL.taxel) ? INITIAL.taxel : []);
}

// ---- the taxels of a board ([[taxel]]) ------------------------------------------------------------------------

function buildTaxels(entries) {
  $("section-taxel").hidden = !taxelCols.length;
  const head = document.createElement("tr");
  for (const col of taxelCols) {
    const th = document.createElement("th");
    th.textContent = SHORT[col.name] || col.name;
    th.title = `${col.key} [${col.unit}]: ${col.doc}`;
    head.appendChild(th);
  }
  head.prepend(document.createElement("th"));
  $("taxels").tHead.replaceChildren(head);
  $("taxels").tBodies[0].replaceChildren();
  taxelRows = [];
  for (const entry of entries) addTaxel(entry);
}

function addTaxel(entry) {
  const tr = document.createElement("tr");
  const row = {tr, cells: {}, extra: {}};
  for (const [k, v] of Object.entries(entry)) {
    if (!taxelCols.some((c) => c.name === k)) row.extra[k] = v;  // e.g. its own [taxel.calibration]
  }
  for (const col of taxelCols) {
    const td = document.createElement("td");
    const input = document.createElement("input");
    input.type = "text";
    input.className = col.name === "name" ? "name" : "";
    input.value = entry[col.name] === undefined ? "" : String(entry[col.name]);
    input.placeholder = col.required_in_table ? "" : col.name === "name" ? "auto" : "shared";
    input.title = `${col.key} [${col.unit}] ${col.allowed}`;
    input.dataset.col = col.name;
    input.addEventListener("input", onEdit);
    td.appendChild(input);
    tr.appendChild(td);
    row.cells[col.name] = input;
  }
  const td = document.createElement("td");
  const remove = document.createElement("button");
  remove.type = "button";
  remove.textContent = "×";
  remove.title = "remove this taxel";
  remove.className = "remove-taxel";
  remove.addEventListener("click", () => {
    taxelRows = taxelRows.filter((r) => r !== row);
    tr.remove();
    numberTaxels();
    onEdit();
  });
  td.appendChild(remove);
  tr.prepend(td);
  $("taxels").tBodies[0].appendChild(tr);
  taxelRows.push(row);
  numberTaxels();
}

function numberTaxels() {  // ids follow the spec's own field names: taxel[1].x, taxel[2].neck_diameter, ...
  taxelRows.forEach((row, i) => {
    for (const [name, input] of Object.entries(row.cells)) input.id = `in-taxel[${i + 1}].${name}`;
  });
}

function newTaxel() {
  const last = taxelRows[taxelRows.length - 1];
  const entry = {};
  if (last) {
    for (const [name, input] of Object.entries(last.cells)) if (input.value.trim() && name !== "name") entry[name] = parse({kind: "number"}, input.value);
    entry.y = (Number(entry.y) || 0) - 7;
  } else {
    entry.x = 0; entry.y = 0;
  }
  addTaxel(entry);
  onEdit();
}

function collectTaxels() {
  return taxelRows.map((row) => {
    const entry = {...row.extra};
    for (const col of taxelCols) {
      const text = row.cells[col.name].value;
      if (text.trim() !== "") entry[col.name] = col.kind === "name" ? text.trim() : parse(col, text);
    }
    return entry;
  });
}

// ---- the spec ---------------------------------------------------------------------------------------------------

function parse(row, text) {
  const t = text.trim();
  const num = (s) => (/^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$/.test(s.trim()) ? Number(s) : s.trim());
  if (row.kind === "number" || row.kind === "integer") return num(t);
  if (row.kind === "range" || row.kind === "vector9") return t.replace(/^\[|\]$/g, "").split(",").map(num);
  return text;
}

function collect() {
  const spec = {};
  for (const [key, {row, input}] of Object.entries(inputs)) {
    let value;
    if (row.kind === "bool") value = input.checked;
    else if (input.value.trim() === "") continue;
    else value = parse(row, input.value);
    if (!key.includes(".")) { spec[key] = value; continue; }
    const [section, name] = key.split(".");
    (spec[section] = spec[section] || {})[name] = value;
  }
  // an optional table whose own required fields are all blank (e.g. [calibration]) is left out
  for (const section of Object.keys(spec)) {
    const own = fields.filter((r) => r.key.startsWith(section + ".") && r.required_in_table && !r.required);
    if (own.length && own.every((r) => inputs[r.key].input.value.trim() === "")) delete spec[section];
  }
  // a table the spec did not have, still at its defaults, is left out (a board's [array] is 1 x 1 by default,
  // and [array] with [[taxel]] is refused)
  for (const section of Object.keys(spec)) {
    if (section in INITIAL || !(spec[section] instanceof Object) || Array.isArray(spec[section])) continue;
    const own = fields.filter((r) => r.key.startsWith(section + "."));
    const atDefault = (r) => (r.kind === "bool" ? inputs[r.key].input.checked === !!r.default
                                                : inputs[r.key].input.value.trim() === shown(r, undefined));
    if (own.every(atDefault)) delete spec[section];
  }
  if (taxelRows.length) spec.taxel = collectTaxels();
  return {...spec, ...preserved};
}

function clearErrors() {
  for (const el of document.querySelectorAll(".error")) el.textContent = "";
  for (const el of document.querySelectorAll("input.bad")) el.classList.remove("bad");
}

function showError(error) {
  const field = error.field || "";
  const cell = document.getElementById("in-" + field);
  const target = $("err-" + field) || (field.startsWith("taxel[") && $("err-taxel")) ||
                 $("err-" + field.split(".")[0]) || $("form-error");
  target.textContent = error.message;
  if (cell && cell.tagName === "INPUT") cell.classList.add("bad");
}

async function post(path, body) {
  const response = await fetch(path, {method: "POST", headers: {"Content-Type": "application/json"},
                                      body: JSON.stringify(body || {spec: collect()})});
  return [response.status, await response.json()];
}

function list(id, items) {
  $(id).replaceChildren(...items.map((t) => { const li = document.createElement("li"); li.textContent = t; return li; }));
}

// ---- prediction ---------------------------------------------------------------------------------------------------

let timer = null, generation = 0, lastPrediction = null;
let riseBusy = false, riseWanted = null;
function schedulePredict() { clearTimeout(timer); timer = setTimeout(predict, 200); }

async function predict() {  // the bands at once (a board's without its caps' rise under load), then the rises
  const mine = ++generation;
  $("status").textContent = "predicting…";
  const spec = collect();
  const [status, data] = await post("/predict", {spec, mechanics: false});
  if (mine !== generation) return;  // a newer edit is on its way
  $("status").textContent = "";
  if (!show(status, data)) return;
  schedulePreview(spec);
  if (data.rise_pending) { riseWanted = {spec, mine}; askRise(); }
}

async function askRise() {  // one request at a time, for the newest edit: a new cap costs a FElupe run (seconds)
  if (riseBusy || riseWanted === null) return;
  const {spec, mine} = riseWanted;
  riseWanted = null;
  riseBusy = true;
  $("status").textContent = "computing each cap's rise under load…";
  try {
    const [status, data] = await post("/predict", {spec});
    if (mine === generation) {
      $("status").textContent = "";
      if (show(status, data) && window.matcad.riseShownMs === null) window.matcad.riseShownMs = performance.now();
    }
  } finally {
    riseBusy = false;
    askRise();
  }
}

function show(status, data) {  // a /predict reply on the page; false for an error (told beside its field)
  clearErrors();
  if (status !== 200) {
    showError(data.error);
    $("f0").textContent = "—";
    $("model").textContent = $("band").textContent = "";
    $("bandchart").replaceChildren();
    for (const id of ["warnings", "notes", "conflicts", "layout"]) list(id, []);
    return false;
  }
  lastPrediction = data;
  if (data.board) {
    $("f0").textContent = `${data.taxels.length} taxels`;
    $("model").textContent = "";
    $("band").textContent = `f0 ${data.taxels.map((t) => `${t.name} ${t.f0_hz.toFixed(0)}`).join(", ")} Hz`;
  } else {
    $("f0").textContent = `f0 = ${data.f0_hz.toFixed(0)} Hz`;
    $("model").textContent = `(${data.model}${data.models[data.model]?.valid === false ? ", outside its checks" : ""})`;
    $("band").textContent = `band ${data.band_hz[0].toFixed(0)}–${data.band_hz[1].toFixed(0)} Hz`;
  }
  drawBands(data);
  if (window.matcad.bandsShownMs === null) window.matcad.bandsShownMs = performance.now();
  list("conflicts", data.conflicts.map((c) => "conflict: " + c.message));
  list("layout", data.layout.map((f) => `${f.level} ${f.id}: ${f.message}`));  // a board's taxels on the plate
  list("warnings", data.warnings);
  list("notes", data.notes);
  showDetails();
  return true;
}

function el(tag, attrs, text) {
  const node = document.createElementNS(SVGNS, tag);
  for (const [k, v] of Object.entries(attrs)) node.setAttribute(k, v);
  if (text !== undefined) node.textContent = text;
  return node;
}

function drawBands(data) {  // every taxel's unloaded band (blue) and loaded rise (orange) on one axis, f0 ticks
  const rows = data.taxels, g = data.guard_hz;
  let lo = Math.min(...rows.map((t) => t.loaded_hz[0])) - 3 * g, hi = Math.max(...rows.map((t) => t.loaded_hz[1])) + 3 * g;
  const span = hi - lo; lo -= 0.04 * span; hi += 0.04 * span;
  const W = 720, left = 120, right = 20, rowH = 26, top = 24, H = top + rowH * rows.length + 34;
  const x = (f) => left + (f - lo) / (hi - lo) * (W - left - right);
  const svg = el("svg", {viewBox: `0 0 ${W} ${H}`, id: "bands-svg", role: "img",
                         "data-rise": data.rise_pending ? "pending" : "done"});
  svg.appendChild(el("text", {x: left, y: 14, "font-size": 12, fill: data.conflicts.length ? "#b00020" : "#222"},
    `${rows.length} taxel band(s), guard ${g.toFixed(0)} Hz, ` + (data.rise_pending
      ? `unloaded (the rise to ${data.max_force_n} N follows): ` : `loaded to ${data.max_force_n} N: `) +
    (data.conflicts.length ? `${data.conflicts.length} conflict(s)` : "disjoint")));
  const step = [50, 100, 200, 250, 500, 1000, 2000, 5000].find((s) => (hi - lo) / s <= 9) || 10000;
  for (let f = Math.ceil(lo / step) * step; f <= hi; f += step) {
    svg.appendChild(el("line", {x1: x(f), x2: x(f), y1: top - 4, y2: H - 28, stroke: "#e3e6ee"}));
    svg.appendChild(el("text", {x: x(f), y: H - 14, "font-size": 10, "text-anchor": "middle", fill: "#556"}, f.toFixed(0)));
  }
  svg.appendChild(el("text", {x: (left + W) / 2, y: H - 2, "font-size": 10, "text-anchor": "middle", fill: "#556"}, "frequency [Hz]"));
  const clash = new Set(data.conflicts.flatMap((c) => [c.taxel, c.other]));
  rows.forEach((t, i) => {
    const y = top + i * rowH;
    const grp = el("g", {class: "band", "data-taxel": t.name, "data-f0": t.f0_hz.toFixed(1),
                         "data-low": t.unloaded_hz[0].toFixed(1), "data-high": t.loaded_hz[1].toFixed(1)});
    grp.appendChild(el("text", {x: left - 6, y: y + 15, "font-size": 11, "text-anchor": "end",
                                fill: clash.has(t.name) ? "#b00020" : "#222"}, `${t.name} ${t.f0_hz.toFixed(0)} Hz`));
    const [ul, uh] = t.unloaded_hz, [, lh] = t.loaded_hz;
    grp.appendChild(el("rect", {x: x(ul), y: y + 5, width: Math.max(1, x(uh) - x(ul)), height: 14, fill: "#5b8fc7"}));
    if (lh > uh) grp.appendChild(el("rect", {x: x(uh), y: y + 5, width: x(lh) - x(uh), height: 14, fill: "#e08a3c"}));
    grp.appendChild(el("line", {x1: x(t.f0_hz), x2: x(t.f0_hz), y1: y + 1, y2: y + 23, stroke: "#000", "stroke-width": 2}));
    const tip = el("title", {}, `${t.name}: f0 ${t.f0_hz.toFixed(0)} Hz (${t.model}); unloaded ${ul.toFixed(0)}–` +
      `${uh.toFixed(0)} Hz; loaded ${t.loaded_hz[0].toFixed(0)}–${lh.toFixed(0)} Hz; rise from ${t.rise_source}`);
    grp.appendChild(tip);
    svg.appendChild(grp);
  });
  $("bandchart").replaceChildren(svg);
}

function showDetails() {  // the chosen taxel's model table and uncertainty budget
  const data = lastPrediction;
  if (!data) return;
  const select = $("detail");
  const names = data.taxels.map((t) => t.name);
  if ([...select.options].map((o) => o.value).join() !== names.join()) {
    const keep = select.value;
    select.replaceChildren(...names.map((n) => new Option(n, n)));
    if (names.includes(keep)) select.value = keep;
  }
  select.hidden = names.length < 2;
  const t = data.taxels.find((r) => r.name === select.value) || data.taxels[0];
  const models = $("models");
  models.innerHTML = "<tr><th>model</th><th>f0 [Hz]</th><th>checks</th></tr>";
  for (const [name, m] of Object.entries(t.models)) {
    const tr = models.insertRow();
    tr.insertCell().textContent = name + (name === t.model ? " ★" : "");
    tr.insertCell().textContent = m.f0_hz === null ? "—" : m.f0_hz.toFixed(0);
    tr.insertCell().textContent = m.valid ? "valid" : "outside its checks";
  }
  const budget = $("budget");
  budget.innerHTML = `<tr><th>uncertainty (${t.name})</th><th>−Hz</th><th>+Hz</th></tr>`;
  for (const b of t.budget) {
    const tr = budget.insertRow();
    tr.insertCell().textContent = b.source;
    tr.insertCell().textContent = Math.abs(b.low_hz).toFixed(0);
    tr.insertCell().textContent = b.high_hz.toFixed(0);
  }
  const caption = budget.createCaption();
  caption.textContent = `band ${t.band_hz[0].toFixed(0)}–${t.band_hz[1].toFixed(0)} Hz: the chosen model's f0 ` +
    "with these, root-sum-square in ln f";
}

// ---- geometry -------------------------------------------------------------------------------------------------------

function num(key, fallback) {
  const v = inputs[key] ? Number(inputs[key].input.value) : NaN;
  return Number.isFinite(v) && inputs[key].input.value.trim() !== "" ? v : fallback;
}

function drawPlan() {  // the plate and every taxel's cap flange and neck, from the fields (no server)
  const w = num("plate.width", 20), d = num("plate.depth", 20);
  const cap = num("end_cap.outer_diameter", 8), neck = num("neck.diameter", 2);
  let taxels = collectTaxels().map((t, i) => ({name: t.name || `t${i + 1}`, x: Number(t.x), y: Number(t.y),
    cap: Number(t.cap_outer_diameter) || cap, neck: Number(t.neck_diameter) || neck}));
  if (!taxels.length) {
    const cols = num("array.columns", 1), rows = num("array.rows", 1);
    const px = num("array.pitch_x", 0), py = num("array.pitch_y", 0);
    for (let r = 0; r < rows; r++) for (let c = 0; c < cols; c++)
      taxels.push({name: `t${r * cols + c + 1}`, x: (c - (cols - 1) / 2) * px, y: ((rows - 1) / 2 - r) * py, cap, neck});
  }
  taxels = taxels.filter((t) => Number.isFinite(t.x) && Number.isFinite(t.y));
  const m = 2, svg = el("svg", {viewBox: `${-w / 2 - m} ${-d / 2 - m} ${w + 2 * m} ${d + 2 * m}`, id: "plan-svg"});
  svg.appendChild(el("rect", {x: -w / 2, y: -d / 2, width: w, height: d, fill: "#eef1f7", stroke: "#203060",
                              "stroke-width": 0.15}));
  for (const t of taxels) {
    const g = el("g", {class: "plan-taxel", "data-taxel": t.name});
    g.appendChild(el("circle", {cx: t.x, cy: -t.y, r: t.cap / 2, fill: "#f3c9a0", stroke: "#7a4b00", "stroke-width": 0.12}));
    g.appendChild(el("circle", {cx: t.x, cy: -t.y, r: t.neck / 2, fill: "#fff", stroke: "#203060", "stroke-width": 0.12}));
    g.appendChild(el("text", {x: t.x, y: -t.y - t.cap / 2 - 0.5, "font-size": 1.8, "text-anchor": "middle",
                              fill: "#203060"}, t.name));
    svg.appendChild(g);
  }
  $("plan").replaceChildren(svg);
}

let previewBusy = false, previewDirty = false, previewTimer = null, previewSpec = null;
function schedulePreview(spec) {  // the spec just predicted (so known valid), drawn 150 ms later
  previewSpec = spec;
  clearTimeout(previewTimer);
  previewTimer = setTimeout(preview, 150);
}

async function preview() {  // the section, then the meshes; a newer edit waits for the one in flight
  if (previewBusy) { previewDirty = true; return; }
  previewBusy = true;
  const spec = previewSpec, t0 = performance.now(), editAt = window.matcad.editAt;
  $("preview-status").textContent = "drawing the section…";
  try {
    const [status, data] = await post("/preview", {spec, what: "section"});
    if (status === 200) {
      $("section").src = "data:image/svg+xml;base64," + btoa(unescape(encodeURIComponent(data.svg)));
      $("section").hidden = false;  // no empty (broken) picture before the first section arrives
      const ms = performance.now() - t0;
      window.matcad.previewMs.push(ms);
      if (editAt !== null && !previewDirty) window.matcad.editToSectionMs.push(performance.now() - editAt);
      $("preview-status").textContent = `section ${ms.toFixed(0)} ms`;
      if (!previewDirty) await mesh(spec);
    } else {
      $("preview-status").textContent = "no section: " + data.error.message;
    }
  } finally {
    previewBusy = false;
    if (previewDirty) { previewDirty = false; schedulePreview(previewSpec); }
  }
}

async function mesh(spec) {  // the assembly, then (unless a newer edit waits) the mold beside it
  const t0 = performance.now();
  $("mesh-status").textContent = "(meshing…)";
  const [status, data] = await post("/preview", {spec, what: "assembly"});
  if (status !== 200) { $("mesh-status").textContent = "(no mesh: " + data.error.message + ")"; return; }
  window.matcad.meshMs = performance.now() - t0;
  $("mesh-status").textContent = `(${data.parts.length} parts, ${window.matcad.meshMs.toFixed(0)} ms; mold…)`;
  viewer.show(data.parts);
  if (previewDirty) return;
  const [moldStatus, molds] = await post("/preview", {spec, what: "molds"});
  if (moldStatus !== 200) { $("mesh-status").textContent = "(no mold mesh: " + molds.error.message + ")"; return; }
  window.matcad.moldMs = performance.now() - t0;
  const parts = data.parts.concat(molds.parts);
  $("mesh-status").textContent = `(${parts.length} parts, ${window.matcad.moldMs.toFixed(0)} ms)`;
  viewer.show(parts);
}

// ---- save, load, share ----------------------------------------------------------------------------------------------

function download(name, blob) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(blob);
  a.download = name;
  a.click();
}

async function saveToml() {
  const [status, data] = await post("/toml");
  if (status !== 200) { clearErrors(); showError(data.error); return; }
  window.matcad.savedToml = data.toml;
  download(data.name + ".toml", new Blob([data.toml], {type: "application/toml"}));
}

async function loadToml(text) {
  const [status, data] = await post("/parse", {toml: text});
  if (status !== 200) { clearErrors(); showError(data.error); return; }
  start(data.spec);
}

const b64url = (s) => btoa(unescape(encodeURIComponent(s))).replace(/\+/g, "-").replace(/\//g, "_").replace(/=+$/, "");
const unb64url = (s) => decodeURIComponent(escape(atob(s.replace(/-/g, "+").replace(/_/g, "/"))));

function share() {
  const url = location.origin + location.pathname + "#spec=" + b64url(JSON.stringify(collect()));
  history.replaceState(null, "", url);
  $("share-url").hidden = false;
  $("share-url").value = url;
  $("share-url").select();
}

function fromHash() {
  const m = location.hash.match(/^#spec=([A-Za-z0-9_-]+)$/);
  if (!m) return null;
  try { return JSON.parse(unb64url(m[1])); } catch (e) { $("form-error").textContent = "the link's spec is unreadable: " + e; return null; }
}

function start(initial) {
  INITIAL = initial;
  buildForm();
  drawPlan();
  predict();
}

// ---- build ---------------------------------------------------------------------------------------------------------

async function buildKit() {
  $("build-status").textContent = "building…";
  $("download").hidden = true;
  const id = [...crypto.getRandomValues(new Uint8Array(12))].map((b) => b.toString(16).padStart(2, "0")).join("");
  window.matcad.stages = [];
  $("build-progress").hidden = false;
  $("build-bar").value = 0;
  $("build-stage").textContent = "waiting for the build slot";
  const poll = setInterval(async () => {
    const response = await fetch("/progress?build=" + id);
    if (response.status !== 200) return;
    const p = await response.json();
    if (!p.running) return;  // not started yet (waiting for the build slot) or just finished
    $("build-bar").max = p.of;
    $("build-bar").value = p.index;
    $("build-stage").textContent = `${p.index}/${p.of} ${p.text} — ${p.files} files, ${p.elapsed_s.toFixed(0)} s`;
    if (!window.matcad.stages.includes(p.stage)) window.matcad.stages.push(p.stage);
  }, 400);
  let status, data;
  try {
    [status, data] = await post("/build", {spec: collect(), build_id: id});
  } finally {
    clearInterval(poll);
  }
  $("build-progress").hidden = true;
  clearErrors();
  if (status !== 200) {
    $("build-status").textContent = "not built";
    showError(data.error);
    list("findings", (data.findings || []).map((f) => `${f.level} ${f.id}: ${f.message}`));
    return;
  }
  const bytes = Uint8Array.from(atob(data.zip), (c) => c.charCodeAt(0));
  const link = $("download");
  link.href = URL.createObjectURL(new Blob([bytes], {type: "application/zip"}));
  link.download = data.name + ".zip";
  link.hidden = false;
  $("build-status").textContent = `${data.files.length} files, verdict ${data.verdict}` +
    (data.model_status ? ` (design rules); ${data.model_status}` : "");
  list("findings", data.findings.map((f) => `${f.level} ${f.id}: ${f.message}`));
  $("previews").replaceChildren(...data.previews.map((p) => {
    const fig = document.createElement("figure");
    const img = document.createElement("img"); img.src = p.src; img.alt = p.caption;
    const cap = document.createElement("figcaption"); cap.textContent = p.caption;
    fig.append(img, cap);
    return fig;
  }));
}

const viewer = makeViewer($("viewer"));
for (const name of BOOT.templates) $("template").add(new Option(name, name));
$("template").value = BOOT.template;
$("template").addEventListener("change", () => { location.href = location.pathname + "?template=" + $("template").value; });
$("build").addEventListener("click", buildKit);
$("add-taxel").addEventListener("click", newTaxel);
$("detail").addEventListener("change", showDetails);
$("save").addEventListener("click", saveToml);
$("share").addEventListener("click", share);
$("load").addEventListener("change", async (e) => { const f = e.target.files[0]; if (f) await loadToml(await f.text()); });
start(fromHash() || BOOT.initial);
