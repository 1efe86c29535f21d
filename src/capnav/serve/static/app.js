// CapNav map page: asks the server, draws the answer over the map picture. No dependencies.
"use strict";
const SVG = "http://www.w3.org/2000/svg";
const $ = (id) => document.getElementById(id);
let info = null;      // /api/map
let objects = [];     // /api/objects
let robot = null;     // [x, y] world metres

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
    const o = ans.object;
    status.textContent = `"${ans.instruction}"`;
    $("chosen").hidden = false;
    $("chosen-id").textContent = o.id;
    $("chosen-cat").textContent = `(${o.category})`;
    $("chosen-caption").textContent = o.caption;
    $("chosen-why").textContent = ans.reason;
    const plan = ans.plan;
    $("chosen-goal").textContent = plan ? `Path: ${plan.length_m.toFixed(2)} m, ${plan.success ? "ends" : "does NOT end"} within reach (${plan.reason}).`
                                        : (ans.goal_note || "");
    const img = $("chosen-view");
    img.hidden = !o.views.length;
    if (o.views.length) img.src = `/api/objects/${o.id}/view.png`;
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
    b.textContent = `object ${r.id}`;
    const s = document.createElement("span");
    s.className = "score";
    s.textContent = ` (${r.score.toFixed(2)}) `;
    li.append(b, s, document.createTextNode(r.caption || r.category));
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
    const r = await fetch("/api/query", {method: "POST", headers: {"Content-Type": "application/json"},
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

async function init() {
  const [m, o] = await Promise.all([fetch("/api/map"), fetch("/api/objects")]);
  info = await m.json();
  objects = (await o.json()).objects;
  robot = info.default_robot;
  $("mapinfo").textContent = `${info.source || "map"}: ${info.objects} objects` +
    (info.captioned ? "" : " (not captioned: run capnav caption first)");
  drawObjects();
  $("ask").addEventListener("submit", ask);
  $("map").addEventListener("click", place);
  document.body.dataset.ready = "1";
}

init();
