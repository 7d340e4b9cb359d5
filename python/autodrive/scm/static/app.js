// The SCM web app: the live map (lanes, stop lines, signs, lights, cars as oriented footprints),
// the vehicle table, lights with their programs, the event log. Data: GET /api/map once, then
// the WebSocket /ws (10 Hz). Changes: PUT with the session's CSRF token (operators only).
"use strict";
const scm = { session: null, map: null, state: null, view: null, lastClick: null };
window.scm = scm;
const $ = (id) => document.getElementById(id);
const COLOURS = { RED: "#e22", YELLOW: "#fc0", GREEN: "#2d2", OFF: "#444", "": "#888" };

async function api(method, path, body) {
  const headers = { "Content-Type": "application/json" };
  if (scm.session) headers["X-CSRF-Token"] = scm.session.csrf;
  const r = await fetch(path, { method, headers, body: body ? JSON.stringify(body) : undefined,
                                credentials: "same-origin" });
  const data = await r.json().catch(() => ({}));
  if (!r.ok) {
    const d = data.detail;
    throw new Error(`${r.status}: ${typeof d === "string" ? d : JSON.stringify(d)}`);
  }
  return data;
}

function say(text) { $("message").textContent = text || ""; }

async function start() {
  try { scm.session = await api("GET", "/api/session"); } catch (e) { scm.session = null; }
  if (!scm.session) { $("login-box").hidden = false; $("app").hidden = true; return; }
  $("login-box").hidden = true; $("app").hidden = false; $("logout").hidden = false;
  $("who").textContent = `${scm.session.user} (${scm.session.role})`;
  scm.map = await api("GET", "/api/map");
  fitView();
  connect();
}

function connect() {
  const ws = new WebSocket(`${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/ws`);
  ws.onmessage = (ev) => { scm.state = JSON.parse(ev.data); render(); };
  ws.onclose = () => setTimeout(() => { if (scm.session) connect(); }, 1000);
}

function fitView() {
  const c = $("map"), m = scm.map;
  let xs = [], ys = [];
  for (const l of m.lanes) for (const [x, y] of l.points) { xs.push(x); ys.push(y); }
  const x0 = Math.min(...xs) - 0.4, x1 = Math.max(...xs) + 0.4;
  const y0 = Math.min(...ys) - 0.4, y1 = Math.max(...ys) + 0.4;
  const k = Math.min(c.width / (x1 - x0), c.height / (y1 - y0));
  scm.view = { k, x0, y1 };
}
// world [m] -> canvas [px]
function px(x, y) { const v = scm.view; return [(x - v.x0) * v.k, (v.y1 - y) * v.k]; }
scm.lightPixel = (id) => { const l = scm.map.lights.find((t) => t.id === id); return px(l.x_m, l.y_m); };

function render() { drawMap(); drawTables(); }

function drawMap() {
  const c = $("map"), g = c.getContext("2d"), m = scm.map, s = scm.state, k = scm.view.k;
  g.clearRect(0, 0, c.width, c.height);
  g.lineCap = "round"; g.lineJoin = "round";
  for (const l of m.lanes) {  // road surface: each lane as a band of its width
    g.strokeStyle = "#555"; g.lineWidth = 2 * l.half_width_m * k; g.beginPath();
    l.points.forEach(([x, y], i) => { const [u, v] = px(x, y); i ? g.lineTo(u, v) : g.moveTo(u, v); });
    g.stroke();
  }
  g.setLineDash([4, 4]);
  for (const l of m.lanes) {
    g.strokeStyle = "#ddd"; g.lineWidth = 1; g.beginPath();
    l.points.forEach(([x, y], i) => { const [u, v] = px(x, y); i ? g.lineTo(u, v) : g.moveTo(u, v); });
    g.stroke();
  }
  g.setLineDash([]);
  for (const sl of m.stop_lines) {
    g.strokeStyle = "#fff"; g.lineWidth = Math.max(2, 0.03 * k); g.beginPath();
    g.moveTo(...px(...sl.from)); g.lineTo(...px(...sl.to)); g.stroke();
  }
  g.font = "11px sans-serif";
  for (const sg of m.signs) {
    const [u, v] = px(sg.x_m, sg.y_m);
    g.fillStyle = sg.kind === "stop" ? "#c00" : "#fff"; g.strokeStyle = "#000";
    g.beginPath(); g.arc(u, v, 6, 0, 2 * Math.PI); g.fill(); g.stroke();
    g.fillStyle = "#000";
    const label = sg.kind + (sg.speed_limit_m_s ? ` ${sg.speed_limit_m_s} m/s` : "");
    g.fillText(label, u + 8, v - 4);
  }
  const lightState = {};
  if (s) for (const l of s.lights) lightState[l.id] = l.sim_state || l.state;
  for (const l of m.lights) {
    const [u, v] = px(l.x_m, l.y_m);
    g.fillStyle = "#111"; g.fillRect(u - 10, v - 10, 20, 20);
    g.fillStyle = COLOURS[lightState[l.id] || ""];
    g.beginPath(); g.arc(u, v, 8, 0, 2 * Math.PI); g.fill();
    g.fillStyle = "#000"; g.fillText(`L${l.id}`, u + 12, v + 4);
  }
  if (!s) return;
  const f = m.footprint;
  const labels = [];  // where names are written, so that the next one moves clear of them
  for (const car of s.vehicles) {
    if (car.age_s === null) continue;  // never seen: no place to draw it
    const [u, v] = px(car.x_m, car.y_m);
    g.save(); g.translate(u, v); g.rotate(-car.yaw_rad);
    g.fillStyle = car.status === "ok" ? "#17c" : "#999"; g.strokeStyle = "#000";
    const cx = f.centre_ahead_m * k, L = f.length_m * k, W = f.width_m * k;
    g.fillRect(cx - L / 2, -W / 2, L, W); g.strokeRect(cx - L / 2, -W / 2, L, W);
    g.fillStyle = "#fff"; g.beginPath();  // the nose
    g.moveTo(cx + L / 2, 0); g.lineTo(cx + L / 2 - 0.06 * k, W / 3); g.lineTo(cx + L / 2 - 0.06 * k, -W / 3);
    g.fill(); g.restore();
    g.fillStyle = "#000"; g.font = "bold 12px sans-serif";
    let lv = v - 10;
    while (labels.some(([a, b]) => Math.abs(a - (u + 10)) < 120 && Math.abs(b - lv) < 14)) lv -= 14;
    labels.push([u + 10, lv]);
    g.fillText(`${car.name} ${car.speed_m_s.toFixed(2)} m/s`, u + 10, lv);
  }
}

function cell(tr, text, cls) { const td = tr.insertCell(); td.textContent = text; if (cls) td.className = cls; return td; }
const fmt = (x, n = 2) => (x === null || x === undefined || x < 0 ? "-" : Number(x).toFixed(n));

function drawTables() {
  const s = scm.state, op = scm.session.role === "operator";
  const vb = $("vehicles").tBodies[0]; vb.innerHTML = "";
  for (const c of s.vehicles) {
    const tr = vb.insertRow(); tr.dataset.name = c.name;
    if (c.age_s === null) {  // a car the SCM was told of but has never seen: no made-up 0, 0
      cell(tr, c.name); const td = cell(tr, "not seen yet", "unseen"); td.colSpan = 8;
      continue;
    }
    cell(tr, c.name); cell(tr, c.x_m.toFixed(3)); cell(tr, c.y_m.toFixed(3)); cell(tr, c.speed_m_s.toFixed(2));
    cell(tr, c.source); cell(tr, c.status); cell(tr, c.lane);
    cell(tr, c.next_light >= 0 ? `L${c.next_light}` : "-"); cell(tr, fmt(c.stop_line_m));
  }
  const jd = $("junctions");
  if (!jd.dataset.built) {
    jd.dataset.built = "1";
    for (const j of s.junctions) {
      const div = document.createElement("div");
      const t = (scm.map.junctions || []).find((x) => x.name === j.name);
      const where = t ? `, the map's ${t.type} tile at (${t.centre_m.map((x) => x.toFixed(1)).join(", ")}) m` : "";
      div.innerHTML = `<label for="mode-${j.name}">junction <b>${j.name}</b>${where}, lights
        ${j.lights.map((i) => `L${i}`).join(", ")}: mode</label>
        <select id="mode-${j.name}" ${op ? "" : "disabled"}><option>fixed</option><option>actuated</option><option>manual</option></select>`;
      jd.appendChild(div);
      div.querySelector("select").onchange = (ev) => act("PUT", `/api/junctions/${j.name}/mode`, { mode: ev.target.value });
    }
  }
  for (const j of s.junctions) { const sel = $(`mode-${j.name}`); if (sel && document.activeElement !== sel) sel.value = j.mode; }
  const lb = $("lights").tBodies[0];
  for (const l of s.lights) {
    let tr = $(`light-row-${l.id}`);
    if (!tr) {
      tr = lb.insertRow(); tr.id = `light-row-${l.id}`;
      for (let i = 0; i < 6; i++) tr.insertCell();
      tr.cells[0].textContent = `L${l.id}`;
      for (const st of ["RED", "GREEN", "OFF"]) {
        const b = document.createElement("button"); b.textContent = st; b.id = `light-${l.id}-${st.toLowerCase()}`;
        b.disabled = !op; b.onclick = () => setLight(l.id, st); tr.cells[4].appendChild(b);
      }
      tr.cells[5].innerHTML = ["offset", "green", "yellow", "red"].map((n) =>
        `<label class="prog" for="prog-${l.id}-${n}">${n}</label><input class="prog" id="prog-${l.id}-${n}" aria-label="L${l.id} ${n} [s]" ${op ? "" : "disabled"}>`).join(" ")
        + ` <button id="prog-${l.id}-save" ${op ? "" : "disabled"}>save</button>`;
      $(`prog-${l.id}-save`).onclick = () => saveProgram(l.id);
      fillProgram(l);
    }
    tr.cells[1].textContent = l.state; tr.cells[1].className = `st-${l.state}`;
    tr.cells[2].textContent = l.sim_state; tr.cells[2].className = `st-${l.sim_state}`;
    tr.cells[3].textContent = fmt(l.time_left_s, 1);
  }
  drawEvents(s.events);
}

// Programmed changes (a light's program, actuation, the server) are the background of a town:
// one line per light with their count and the latest; what people did comes first, one each.
const AUTOMATIC = new Set(["program", "actuated", "server"]);
function detailText(d) {
  return Object.entries(d || {}).map(([k, v]) => `${k} ${typeof v === "object" ? JSON.stringify(v) : v}`).join(", ");
}
function drawEvents(events) {
  const ev = $("events"); ev.innerHTML = "";
  const when = (e) => new Date(e.utime / 1000).toLocaleTimeString();
  const people = events.filter((e) => !AUTOMATIC.has(e.actor)).reverse();
  const auto = {};
  for (const e of events.filter((x) => AUTOMATIC.has(x.actor))) {
    const k = `${e.actor} ${e.kind} ${e.subject}`;
    auto[k] = { n: (auto[k] ? auto[k].n : 0) + 1, last: e };
  }
  const list = (title, items) => {
    const h = document.createElement("h3"); h.textContent = title; ev.appendChild(h);
    const ol = document.createElement("ol"); ev.appendChild(ol);
    for (const [text, cls] of items) { const li = document.createElement("li"); li.textContent = text; if (cls) li.className = cls; ol.appendChild(li); }
  };
  list("Operators' actions", people.map((e) => [`${when(e)} ${e.actor} ${e.kind} ${e.subject}: ${detailText(e.detail)}`, "operator"]));
  list("Programmed changes", Object.entries(auto).sort((a, b) => b[1].last.utime - a[1].last.utime).map(([k, g]) =>
    [`${k}: ${g.n} change${g.n > 1 ? "s" : ""}, last ${when(g.last)} (${detailText(g.last.detail)})`, ""]));
}

function fillProgram(l) {
  const get = (st) => l.program.phases.filter((p) => p.state === st).reduce((a, p) => a + p.duration_s, 0);
  $(`prog-${l.id}-offset`).value = l.program.offset_s; $(`prog-${l.id}-green`).value = get("GREEN");
  $(`prog-${l.id}-yellow`).value = get("YELLOW"); $(`prog-${l.id}-red`).value = get("RED");
}

async function act(method, path, body) {
  try { const r = await api(method, path, body); say(r.plan || ""); return r; } catch (e) { say(e.message); return null; }
}

function setLight(id, state) {
  scm.lastClick = { light: id, state, t_ms: Date.now() };
  return act("PUT", `/api/lights/${id}/state`, { state });
}

function saveProgram(id) {
  const v = (n) => Number($(`prog-${id}-${n}`).value);
  return act("PUT", `/api/lights/${id}/program`, { offset_s: v("offset"), phases: [
    { state: "GREEN", duration_s: v("green") }, { state: "YELLOW", duration_s: v("yellow") },
    { state: "RED", duration_s: v("red") }] });
}

$("map").addEventListener("click", (ev) => {
  if (!scm.map || !scm.state) return;
  const r = ev.target.getBoundingClientRect(), u = ev.clientX - r.left, v = ev.clientY - r.top;
  for (const l of scm.map.lights) {
    const [lu, lv] = px(l.x_m, l.y_m);
    if (Math.hypot(lu - u, lv - v) <= 14) {
      const now = scm.state.lights.find((x) => x.id === l.id);
      setLight(l.id, now && (now.state === "GREEN" || now.target === "GREEN") ? "RED" : "GREEN");
      return;
    }
  }
});

$("login-form").addEventListener("submit", async (ev) => {
  ev.preventDefault();
  try {
    await api("POST", "/api/login", { name: $("login-name").value, password: $("login-password").value });
    $("login-error").textContent = ""; await start();
  } catch (e) { $("login-error").textContent = e.message; }
});
$("logout").addEventListener("click", async () => { await api("POST", "/api/logout"); scm.session = null; location.reload(); });
start();
