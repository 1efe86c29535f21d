// CapNav map page: asks the server, draws the answer over the map picture. No dependencies.
"use strict";
const SVG = "http://www.w3.org/2000/svg";
const $ = (id) => document.getElementById(id);
let info = null;      // /api/map
let objects = [];     // /api/objects
let robot = null;     // [x, y] world metres
let base = "/api";    // the chosen map's routes: /api (the first map) or /api/maps/NAME
let shown = [];       // object URLs of fetched pictures, revoked when replaced

// A server off loopback needs its bearer token: open the page as /#token=TOKEN.
const token = (() => {
  const m = location.hash.match(/token=([^&]+)/);
  if (m) sessionStorage.setItem("capnav-token", decodeURIComponent(m[1]));
  return sessionStorage.getItem("capnav-token");
})();

function get(path, opts = {}) {
  const headers = Object.assign({}, opts.headers || {});
  if (token) headers.Authorization = "Bearer " + token;
  return fetch(path, Object.assign({}, opts, {headers: headers}));
}

async function picture(img, path) {  // <img> src through fetch, so the token goes with it
  const r = await get(path);
  if (!r.ok) { img.hidden = true; return; }
  const url = URL.createObjectURL(await r.blob());
  shown.push(url);
  img.src = url;
}

function px(x, y) {  // world (m) -> picture pixels (north up)
  const p = info.picture;
  return [(x - p.x0) * p.pixels_per_metre, p.height - (y - p.y0) * p.pixels_per_metre];
}

function el(name, attrs, parent) {
  const e = document.createElementNS(SVG, name);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  parent.appendChild(e);
  return e;
}

function drawObjects() {
  const svg = $("overlay");
  svg.replaceChildren();
  svg.setAttribute("width", info.picture.width);
  svg.setAttribute("height", info.picture.height);
  for (const o of objects) {
    const [u0, v1] = px(o.min[0], o.min[1]);
    const [u1, v0] = px(o.max[0], o.max[1]);
    el("rect", {x: u0, y: v0, width: u1 - u0, height: v1 - v0, class: "obj", id: "obj-" + o.id,
                "data-id": o.id}, svg);
  }
  el("g", {id: "plan"}, svg);
  el("g", {id: "robot-mark"}, svg);
  drawRobot();
}

function drawRobot() {
  const g = $("robot-mark");
  g.replaceChildren();
  $("robot").textContent = robot ? `x ${robot[0].toFixed(2)}, y ${robot[1].toFixed(2)} m` : "none";
  if (!robot) return;
  const [u, v] = px(robot[0], robot[1]);
  el("circle", {cx: u, cy: v, r: 7, class: "robot"}, g);
}

function clearAnswer() {
  for (const r of document.querySelectorAll("svg .obj")) r.classList.remove("chosen", "runner");
  $("plan").replaceChildren();
  $("chosen").hidden = true;
  $("runners").replaceChildren();
  $("runners-title").hidden = true;
}

function show(ans) {
  clearAnswer();
  const status = $("status");
  status.className = "";
  if (!ans.found) {
    status.textContent = ans.reason;
  } else {
    const o = ans.chosen || ans.object;
    status.textContent = `"${ans.instruction}"`;
    $("chosen").hidden = false;
    $("chosen-id").textContent = o.id;
    $("chosen-cat").textContent = `(${o.category})`;
    $("chosen-caption").textContent = o.caption;
    $("chosen-why").textContent = ans.reason;
    const plan = ans.plan;
    const note = ans.robot_note ? `Robot: ${ans.robot_note}. ` : "";
    $("chosen-goal").textContent = note + (plan ? `Path: ${plan.length_m.toFixed(2)} m, ${plan.success ? "ends" : "does NOT end"} within reach (${plan.reason}).`
                                                : (ans.plan_note || ans.goal_note || ""));
    const img = $("chosen-view");
    img.hidden = !o.views.length;
    if (o.views.length) picture(img, `${base}/objects/${o.id}/view.png`);
    $(`obj-${o.id}`)?.classList.add("chosen");
    if (plan && plan.poses.length > 1) {
      const pts = plan.poses.map((p) => px(p[0], p[1]).join(",")).join(" ");
      el("polyline", {points: pts, class: "path"}, $("plan"));
      const last = plan.poses[plan.poses.length - 1];
      const [u, v] = px(last[0], last[1]);
      el("circle", {cx: u, cy: v, r: 6, class: "goal"}, $("plan"));
    }
  }
  const list = $("runners");
  for (const r of ans.runners_up) {
    const li = document.createElement("li");
    li.id = "runner-" + r.id;
    const b = document.createElement("b");
    b.textContent = `object ${r.id} (${r.category})`;
    const s = document.createElement("span");
    s.className = "score";
    const sim = r.terms && r.terms.similarity;  // the caption's cosine similarity, labelled
    s.textContent = sim === undefined ? " " : ` caption similarity ${sim.toFixed(2)} `;
    const why = document.createElement("div");
    why.className = "why";
    why.textContent = r.why ? `Not chosen: ${r.why}` : "";
    li.append(b, s, document.createTextNode(r.caption || r.category), why);
    list.appendChild(li);
    $(`obj-${r.id}`)?.classList.add("runner");
  }
  $("runners-title").hidden = ans.runners_up.length === 0;
}

async function ask(ev) {
  ev.preventDefault();
  const text = $("q").value;
  const k = parseInt($("k").value, 10);
  const status = $("status");
  status.className = "";
  status.textContent = "asking…";
  const body = {text: text, k: Number.isFinite(k) ? k : 5};
  if (robot) body.robot = robot;
  try {
    const r = await get(`${base}/query`, {method: "POST", headers: {"Content-Type": "application/json"},
                                          body: JSON.stringify(body)});
    const data = await r.json();
    if (!r.ok) {
      clearAnswer();
      status.className = "error";
      status.textContent = `error: ${data.error || r.status}`;
      return;
    }
    show(data);
  } catch (e) {
    status.className = "error";
    status.textContent = `error: ${e}`;
  }
}

function place(ev) {
  if (!info) return;
  const rect = $("mapimg").getBoundingClientRect();
  const p = info.picture;
  const u = (ev.clientX - rect.left) * p.width / rect.width;
  const v = (ev.clientY - rect.top) * p.height / rect.height;
  robot = [p.x0 + u / p.pixels_per_metre, p.y0 + (p.height - v) / p.pixels_per_metre];
  drawRobot();
}

async function load() {  // the chosen map: its picture, objects and default robot
  const [m, o] = await Promise.all([get(`${base}/map`), get(`${base}/objects`)]);
  if (!m.ok) {
    $("mapinfo").textContent = `error: ${(await m.json()).error || m.status}`;
    return;
  }
  info = await m.json();
  objects = (await o.json()).objects;
  robot = info.default_robot;
  for (const u of shown.splice(0)) URL.revokeObjectURL(u);
  await picture($("mapimg"), `${base}/map.png`);
  $("mapinfo").textContent = `${info.source || "map"}: ${info.objects} objects` +
    (info.captioned ? "" : " (not captioned: run capnav caption first)");
  drawObjects();
  clearAnswer();
  $("status").textContent = "";
}

async function init() {
  const r = await get("/api/maps");
  if (r.ok) {
    const maps = await r.json();
    const sel = $("mapsel");
    for (const m of maps.maps) {
      const opt = document.createElement("option");
      opt.value = m.name;
      opt.textContent = `${m.name} (${m.objects} objects)`;
      sel.appendChild(opt);
    }
    sel.hidden = maps.maps.length < 2;
    sel.addEventListener("change", async () => {
      base = `/api/maps/${encodeURIComponent(sel.value)}`;
      await load();
    });
  }
  $("ask").addEventListener("submit", ask);
  $("map").addEventListener("click", place);
  await load();
  document.body.dataset.ready = "1";
}

init();
