// The page of `csplab serve`: a form built from the solvers' declarations, an endless world
// map (chunks loaded as the view moves), local edits, a three.js viewer, runs followed over
// server-sent events, and a witness replayed step by step.
import * as THREE from "three";
import { OrbitControls } from "three/addons/controls/OrbitControls.js";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";

const $ = (id) => document.getElementById(id);
const S = { meta: null, world: null, view: { cx: 0, cy: 0, px: 8 }, chunks: new Map(),
            version: new Map(), core: [], rect: null, run: null, replay: null, step: 0,
            loaded: 0, glbReady: false };
window.csplab = S;

async function api(path, body) {
  const opt = body === undefined ? {} : { method: "POST", headers: { "content-type": "application/json" },
                                         body: JSON.stringify(body) };
  const r = await fetch(path, opt);
  const d = await r.json();
  if (!r.ok) throw new Error(d.error || r.statusText);
  return d;
}
function status(text, bad) { $("status").textContent = text; $("status").className = bad ? "doc error" : "doc"; }
function fill(sel, items, value) {
  sel.innerHTML = "";
  for (const it of items) {
    const o = document.createElement("option");
    [o.value, o.textContent] = Array.isArray(it) ? it : [it, it];
    sel.appendChild(o);
  }
  if (value !== undefined) sel.value = value;
}
function tab(name) {
  for (const b of document.querySelectorAll(".tab")) b.classList.toggle("active", b.dataset.tab === name);
  for (const p of document.querySelectorAll(".pane")) p.classList.toggle("active", p.id === "tab-" + name);
  if (name === "map") drawMap();
  if (name === "viewer") resize3d();
}

// ---- the form, from the declarations ---------------------------------------------------
function optionInputs(box, options, prefix) {
  box.innerHTML = "";
  for (const o of options) {
    if (o.name === "progress" || o.name === "time_limit") continue;
    const l = document.createElement("label");
    l.textContent = o.name + " ";
    l.title = o.doc || "";
    let el;
    if (o.values) {
      el = document.createElement("select");
      fill(el, [["", `(default ${o.default})`], ...o.values.map((v) => [v, v])]);
    } else {
      el = document.createElement("input");
      el.placeholder = `default ${JSON.stringify(o.default)}`;
      if (o.type === "int" || o.type === "float") { el.type = "number"; if (o.minimum !== undefined) el.min = o.minimum; }
    }
    el.dataset.option = o.name;
    el.id = prefix + o.name;
    l.appendChild(el);
    box.appendChild(l);
  }
}
function optionValues(box) {
  const out = {};
  for (const el of box.querySelectorAll("[data-option]")) if (el.value !== "") out[el.dataset.option] = el.value;
  return out;
}
async function init() {
  S.meta = await api("/api/meta");
  const models = S.meta.examples.map((e) => [e.name, e.name]).concat(S.meta.files.map((f) => [f, "file: " + f]));
  fill($("model"), models, S.meta.start || "loops");
  const doc = () => { const e = S.meta.examples.find((x) => x.name === $("model").value); $("model-doc").textContent = e ? e.description : ""; };
  $("model").onchange = doc; doc();
  const solvers = S.meta.solvers.filter((s) => s.installed);
  fill($("solver"), solvers.map((s) => [s.name, `${s.name}${s.complete ? "" : " (incomplete)"}`]), "catalog");
  const setSolver = () => { const s = solvers.find((x) => x.name === $("solver").value); optionInputs($("solver-options"), s.options, "opt-"); };
  $("solver").onchange = setSolver; setSolver();
  // a world's blocks run Alg. 3.1: the catalog solver's declared order and choice; not the
  // solver's order auto (it looks at a whole problem's global constraints): scanline
  const alg31 = solvers.find((s) => s.name === "catalog");
  const worldOption = (o) => o.name !== "order" ? o
    : { ...o, default: "scanline", values: o.values.filter((v) => v !== "auto") };
  optionInputs($("world-options"), alg31.options.filter((o) => o.name === "order" || o.name === "choice").map(worldOption), "world-");
  fill($("brush"), S.meta.brushes.map((b) => [b, { label: "must be label", empty: "must stay empty", reroll: "re-synthesize" }[b] || b]));
  fill($("world-format"), S.meta.formats, ".png");
  fill($("run-format"), S.meta.formats, ".png");
  fill($("constraints"), [["", "(none)"], ...S.meta.files.filter((f) => f.endsWith(".json")).map((f) => [f, f])], "");
  for (const b of document.querySelectorAll(".tab")) b.onclick = () => tab(b.dataset.tab);
  tab("map");
  S.ready = true;
}

// ---- the endless world ---------------------------------------------------------------
async function openWorld() {
  status("opening the world ...");
  const body = { model: $("model").value, seed: Number($("seed").value), chunk: $("chunk").value,
                 ...optionValues($("world-options")) };
  if ($("chunk").value.split("x").length === 3) {  // a 3D world: a region in the viewer
    const [X, Y] = $("chunk").value.split("x").map(Number);
    await startRun({ command: "world", model: body.model, seed: body.seed, chunk: body.chunk, region: `0:${2 * X},0:${2 * Y}` });
    return;
  }
  try {
    S.world = await api("/api/world", body);
  } catch (e) { status(e.message, true); return; }
  S.chunks.clear(); S.version.clear(); S.core = []; S.rect = null;
  const w = S.world;
  fill($("label"), w.names.map((n, b) => [b, `${b}: ${n}`]));
  $("world-info").textContent = `${w.id}: chunk ${w.chunk.join("x")}, K=${w.K}, order ${w.order}, choice ${w.choice}` +
    (w.dropped.length ? `\nnot honoured in an endless world: ${w.dropped.join("; ")}` : "");
  status("world " + w.id + " open");
  if (w.ndim === 3) { tab("viewer"); await viewGlb(`/api/world/${w.id}/model.glb?region=0:${w.chunk[0] * 2},0:${w.chunk[1] * 2}`); return; }
  S.view = { cx: w.chunk[0], cy: w.chunk[1], px: 8 };
  tab("map");
}
function cellPx() { return S.view.px; }
function toScreen(x, y) {
  const c = $("map");
  return [(x - S.view.cx) * cellPx() + c.width / 2, c.height / 2 - (y - S.view.cy) * cellPx()];
}
function toCell(sx, sy) {
  const c = $("map");
  return [Math.floor((sx - c.width / 2) / cellPx() + S.view.cx), Math.floor((c.height / 2 - sy) / cellPx() + S.view.cy)];
}
function chunkRect(i, j) {  // where chunk (i, j) is drawn: whole canvas pixels
  const [X, Y] = S.world.chunk, [sx, sy] = toScreen(i * X, (j + 1) * Y);
  return [Math.round(sx), Math.round(sy), X * cellPx(), Y * cellPx()];
}
function visibleChunks() {
  const w = S.world, c = $("map");
  const [x0, y1] = toCell(0, 0), [x1, y0] = toCell(c.width, c.height);
  const out = [];
  for (let i = Math.floor(x0 / w.chunk[0]); i <= Math.floor(x1 / w.chunk[0]); i++)
    for (let j = Math.floor(y0 / w.chunk[1]); j <= Math.floor(y1 / w.chunk[1]); j++) out.push([i, j]);
  return out;
}
function chunkImage(i, j) {
  const key = `${i},${j}`, v = S.version.get(key) || 0;
  let e = S.chunks.get(key);
  if (e && e.v === v) return e;
  const img = new Image();
  e = { img, v, ok: false };
  S.chunks.set(key, e);
  img.onload = () => { e.ok = true; S.loaded++; drawMap(); };
  img.src = `/api/world/${S.world.id}/chunk/${i}/${j}.png?v=${v}`;
  if (S.chunks.size > 600) S.chunks.delete(S.chunks.keys().next().value);
  return e;
}
function drawMap() {
  const c = $("map");
  if (!c.offsetWidth) return;
  if (c.width !== c.offsetWidth || c.height !== c.offsetHeight) { c.width = c.offsetWidth; c.height = c.offsetHeight; }
  const g = c.getContext("2d");
  g.imageSmoothingEnabled = false;
  g.fillStyle = "#202830"; g.fillRect(0, 0, c.width, c.height);
  if (!S.world || S.world.ndim !== 2) return;
  const [X, Y] = S.world.chunk, px = cellPx();
  for (const [i, j] of visibleChunks()) {
    const e = chunkImage(i, j);
    const [sx, sy] = chunkRect(i, j);
    if (e.ok) g.drawImage(e.img, sx, sy, X * px, Y * px);
    else { g.strokeStyle = "#445"; g.strokeRect(sx, sy, X * px, Y * px); }
  }
  if (S.rect) {
    const [sx, sy] = toScreen(S.rect[0], S.rect[3]);
    g.strokeStyle = "#ff0"; g.lineWidth = 2;
    g.strokeRect(sx, sy, (S.rect[1] - S.rect[0]) * px, (S.rect[3] - S.rect[2]) * px);
  }
  g.fillStyle = "rgba(255,255,0,0.5)";
  for (const [x, y] of S.stroke || []) { const [sx, sy] = toScreen(x, y + 1); g.fillRect(sx, sy, px, px); }
  g.fillStyle = "rgba(255,0,0,0.6)";
  for (const [x, y] of S.core) { const [sx, sy] = toScreen(x, y + 1); g.fillRect(sx, sy, px, px); }
  $("coords").textContent = `centre (${S.view.cx.toFixed(1)}, ${S.view.cy.toFixed(1)}), ${px} px/cell`;
}
function setupMap() {
  const c = $("map");
  let drag = null;
  c.addEventListener("mousedown", (ev) => {
    drag = { x: ev.offsetX, y: ev.offsetY, cx: S.view.cx, cy: S.view.cy, cell: toCell(ev.offsetX, ev.offsetY) };
  });
  window.addEventListener("mousemove", (ev) => {
    if (!drag || !S.world) return;
    const r = c.getBoundingClientRect(), x = ev.clientX - r.left, y = ev.clientY - r.top;
    if ($("tool").value === "pan") {
      S.view.cx = drag.cx - (x - drag.x) / cellPx();
      S.view.cy = drag.cy + (y - drag.y) / cellPx();
    } else if ($("tool").value === "paint") {
      const [u, v] = toCell(x, y);
      drag.stroke = drag.stroke || new Map([[String(drag.cell), drag.cell]]);
      drag.stroke.set(`${u},${v}`, [u, v]);
      S.stroke = [...drag.stroke.values()];
    } else {
      const [a, b] = drag.cell, [u, v] = toCell(x, y);
      S.rect = [Math.min(a, u), Math.max(a, u) + 1, Math.min(b, v), Math.max(b, v) + 1];
    }
    drawMap();
  });
  window.addEventListener("mouseup", async () => {
    const was = drag; drag = null;
    if (!was || !S.world) return;
    if ($("tool").value === "paint") {
      const cells = S.stroke || [was.cell];
      const xs = cells.map((c) => c[0]), ys = cells.map((c) => c[1]);
      S.rect = [Math.min(...xs), Math.max(...xs) + 1, Math.min(...ys), Math.max(...ys) + 1];
      S.stroke = null;
      await paint(S.rect, cells);
    } else if ($("tool").value === "brush" && S.rect) await paint(S.rect);
  });
  c.addEventListener("wheel", (ev) => {
    ev.preventDefault();
    S.view.px = Math.max(1, Math.min(64, ev.deltaY < 0 ? S.view.px * 2 : S.view.px / 2));
    drawMap();
  }, { passive: false });
  window.addEventListener("keydown", (ev) => {
    const step = 8 / Math.max(1, cellPx() / 8);
    const d = { ArrowLeft: [-step, 0], ArrowRight: [step, 0], ArrowUp: [0, step], ArrowDown: [0, -step] }[ev.key];
    if (d && S.world && document.activeElement.tagName !== "INPUT") { S.view.cx += d[0]; S.view.cy += d[1]; drawMap(); }
  });
  window.addEventListener("resize", () => { drawMap(); resize3d(); });
}
function invalidate(chunks) {
  for (const [i, j] of chunks) { const k = `${i},${j}`; S.version.set(k, (S.version.get(k) || 0) + 1); }
  drawMap();
}
async function paint(rect, cells) {
  const body = { brush: $("brush").value, label: Number($("label").value), x0: rect[0], x1: rect[1], y0: rect[2], y1: rect[3] };
  if (cells) body.cells = cells;
  status("re-synthesizing around the edit ...");
  try {
    const r = await api(`/api/world/${S.world.id}/edit`, body);
    S.lastEdit = r;
    S.core = r.core || [];
    if (r.status === "solved") {
      invalidate(r.touched);
      $("edit-info").textContent = `edit ${r.edits}: re-synthesized ${r.rect[0].join(":")},${r.rect[1].join(":")} (${r.solver}); chunks changed: ${r.changed.map((c) => "(" + c + ")").join(" ") || "none"}`;
      status("edit done");
    } else {
      $("edit-info").textContent = r.status === "unsat" ? `no completion: the red cells conflict (UNSAT core of ${S.core.length} painted cells)` : `not solved (${r.status})`;
      status("edit refused", true);
      drawMap();
    }
  } catch (e) { status(e.message, true); }
}
async function undo() {
  if (!S.world) return;
  try { const r = await api(`/api/world/${S.world.id}/undo`, {}); S.core = []; S.rect = null; invalidate(r.touched); S.lastUndo = r; status(`undone (${r.edits} edits left)`); }
  catch (e) { status(e.message, true); }
}
function worldDownload() {
  if (!S.world) return;
  const c = $("map"), [x0, y1] = toCell(0, 0), [x1, y0] = toCell(c.width, c.height);
  location.href = `/api/world/${S.world.id}/download?region=${x0}:${x1 + 1},${y0}:${y1 + 1}&format=${$("world-format").value}`;
}

// ---- the 3D viewer ---------------------------------------------------------------------
const V = {};
function setup3d() {
  V.renderer = new THREE.WebGLRenderer({ canvas: $("viewer"), antialias: false, preserveDrawingBuffer: true });
  V.scene = new THREE.Scene();
  V.scene.background = new THREE.Color(0x202830);
  V.camera = new THREE.PerspectiveCamera(45, 1, 0.1, 5000);
  V.controls = new OrbitControls(V.camera, $("viewer"));
  V.scene.add(new THREE.HemisphereLight(0xffffff, 0x404040, 2.0));
  const sun = new THREE.DirectionalLight(0xffffff, 2.0); sun.position.set(1, 2, 1.5); V.scene.add(sun);
  V.controls.addEventListener("change", render3d);
}
function resize3d() {
  const c = $("viewer");
  if (!V.renderer || !c.offsetWidth) return;
  V.renderer.setSize(c.offsetWidth, c.offsetHeight, false);
  V.camera.aspect = c.offsetWidth / c.offsetHeight; V.camera.updateProjectionMatrix();
  render3d();
}
function render3d() { if (V.renderer) V.renderer.render(V.scene, V.camera); }
async function viewGlb(url) {
  S.glbReady = false;
  tab("viewer");
  const r = await fetch(url);
  if (!r.ok) { status((await r.json()).error, true); return; }
  const buf = await r.arrayBuffer();
  const gltf = await new GLTFLoader().parseAsync(buf, "");
  if (V.model) V.scene.remove(V.model);
  V.model = gltf.scene;
  V.colors = [];
  V.model.traverse((o) => {
    if (!o.isMesh) return;
    V.colors.push("#" + o.material.color.getHexString(THREE.SRGBColorSpace));
    if ($("flat").checked) o.material = new THREE.MeshBasicMaterial({ color: o.material.color });
  });
  V.scene.add(V.model);
  const box = new THREE.Box3().setFromObject(V.model), size = box.getSize(new THREE.Vector3()), mid = box.getCenter(new THREE.Vector3());
  const d = Math.max(size.x, size.y, size.z, 1);
  V.camera.position.set(mid.x + d * 0.9, mid.y + d * 0.8, mid.z + d * 1.1);
  V.controls.target.copy(mid); V.controls.update();
  resize3d();
  S.glbReady = true;
  status(`3D view: ${V.colors.length} meshes`);
}

// ---- runs ------------------------------------------------------------------------------
async function startRun(body) {
  $("bar").style.width = "0";
  status(`${body.command} ...`);
  let r;
  try { r = await api("/api/run", body); } catch (e) { status(e.message, true); return; }
  S.run = { id: r.id, state: "running", events: [] };
  const es = new EventSource(`/api/run/${r.id}/events`);
  es.onmessage = (m) => {
    const e = JSON.parse(m.data);
    S.run.events.push(e);
    if (e.kind === "progress" && e.total) { $("bar").style.width = `${(100 * e.done) / e.total}%`; status(`${body.command}: ${e.desc} ${e.done}/${e.total}`); }
    else if (e.kind === "running") status(`${body.command} running ...`);
  };
  es.addEventListener("end", async () => { es.close(); await finished(r.id); });
}
async function finished(id) {
  const r = await api(`/api/run/${id}`);
  r.events = S.run ? S.run.events : [];
  S.run = r;
  $("bar").style.width = "100%";
  if (r.state === "error") { status(r.error, true); return; }
  const res = r.result || {};
  if (r.command === "world") {
    status(`world region ${r.info.size.join("x")}: ${res.chunks} chunks, ${res.violations} violations in ${res.seconds} s`, res.violations > 0);
    fill($("run-format"), r.formats, ".png");
    await viewGlb(`/api/run/${id}/result.glb`);
  } else if (r.command === "synthesize") {
    const ok = res.status === "solved";
    status(`${res.outcome || res.status} in ${(res.time_s || 0).toFixed(2)} s with ${res.solver}`, !ok);
    $("verdict").textContent = JSON.stringify({ status: res.status, solver: res.solver, seed: res.seed, settings: res.settings }, null, 1);
    fill($("run-format"), r.formats, r.formats.includes(".png") ? ".png" : r.formats[0]);
    $("constraint-rows").innerHTML = "";
    if (!ok) { tab("result"); return; }
    const three = r.info.kind === "PolyhedralModel" || (r.info.size && r.info.size.length === 3);
    if (three) { await viewGlb(`/api/run/${id}/result.glb`); return; }
    if (r.info.constraints) {
      const c = await api(`/api/run/${id}/constraints`);
      S.constraintRows = c.constraints;
      $("constraint-rows").innerHTML = "<b>global constraints</b> (cells outside them faded):<br>" + c.constraints.map((x) =>
        `${x.holds ? "✔" : "✘"} ${x.text}: ${x.cells} cells${x.breach ? " — " + x.breach : ""}`).join("<br>");
      $("result-img").src = `/api/run/${id}/constraints.png`;
    } else $("result-img").src = `/api/run/${id}/result.png`;
    tab("result");
  } else {
    $("verdict").textContent = `${r.command}: ${res.message}`;
    status(res.message, res.holds === false && r.command === "prove");
    if (r.command === "witness" && res.witness && typeof res.witness === "object") await loadReplay(id);
    else tab("result");
  }
}
function runBody(command) {
  return { command, model: $("model").value, seed: Number($("seed").value), time_limit: Number($("time-limit").value),
           size: $("size").value, solver: $("solver").value, options: optionValues($("solver-options")),
           boundary: $("boundary").value || undefined, constraints: $("constraints").value || undefined, order: $("order").value, max_size: $("max-size").value || undefined };
}

// ---- witness replay ------------------------------------------------------------------
async function loadReplay(id) {
  S.replay = await api(`/api/run/${id}/replay`);
  S.step = 0;
  tab("replay");
  drawReplay();
}
function drawReplay() {
  const R = S.replay;
  if (!R) return;
  const st = R.steps[S.step], [nx, ny] = [st.sizes.length, st.sizes[0].length], px = 64;
  const c = $("replay");
  c.width = nx * px; c.height = ny * px;
  const g = c.getContext("2d");
  const K = R.colors.length;
  for (let x = 0; x < nx; x++) for (let y = 0; y < ny; y++) {
    const sx = x * px, sy = (ny - 1 - y) * px, n = st.sizes[x][y], a = st.assigned[x][y];
    g.fillStyle = a >= 0 ? R.colors[a] : n === 0 ? "#d22" : `hsl(210, 30%, ${30 + (50 * n) / K}%)`;
    g.fillRect(sx, sy, px, px);
    g.strokeStyle = "#000"; g.strokeRect(sx, sy, px, px);
    g.fillStyle = "#fff"; g.font = "14px monospace";
    g.fillText(a >= 0 ? `=${a}` : `${n} left`, sx + 6, sy + 20);
    if (st.cell && st.cell[0] === x && st.cell[1] === y) { g.strokeStyle = "#ff0"; g.lineWidth = 3; g.strokeRect(sx + 2, sy + 2, px - 4, px - 4); g.lineWidth = 1; }
  }
  const last = S.step === R.steps.length - 1;
  $("step-text").textContent = `step ${S.step}/${R.steps.length - 1}` + (st.cell ? `: cell (${st.cell}) <- ${st.label}` : ": the catalog before any choice") +
    (st.wiped.length ? ` — catalog empty at ${st.wiped.map((c) => "(" + c + ")").join(" ")}` : last ? "" : "");
}

// ---- wiring ----------------------------------------------------------------------------
$("open-world").onclick = openWorld;
$("undo").onclick = undo;
$("world-download").onclick = worldDownload;
$("synthesize").onclick = () => startRun(runBody("synthesize"));
$("prove").onclick = () => startRun(runBody("prove"));
$("witness").onclick = () => startRun(runBody("witness"));
$("run-download").onclick = () => { if (S.run && S.run.id) location.href = `/api/run/${S.run.id}/download?format=${$("run-format").value}`; };
$("step-prev").onclick = () => { if (S.replay && S.step > 0) { S.step--; drawReplay(); } };
$("step-play").onclick = () => {
  if (!S.replay) return;
  S.step = 0; drawReplay();
  const t = setInterval(() => { if (S.step >= S.replay.steps.length - 1) { clearInterval(t); return; } S.step++; drawReplay(); }, 700);
};
$("step-next").onclick = () => { if (S.replay && S.step < S.replay.steps.length - 1) { S.step++; drawReplay(); } };
setupMap();
setup3d();
S.meshColors = () => V.colors || [];
S.chunkRect = chunkRect;
S.viewGlb = viewGlb; S.drawMap = drawMap; S.toScreen = toScreen; S.paint = paint; S.tab = tab;
init().catch((e) => status(e.message, true));
