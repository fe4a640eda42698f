// The Machine page of the HAL workbench: the state, the DRO, homing,
// jogging, MDI, the program, the overrides, the error channel and a 2-D
// backplot (XY) of the program and of the tool path.  The status comes
// over /ws/machine 20 times a second; every command is a POST to
// /api/machine/<action>.  Text reaches the document via textContent only.
"use strict";

let status = null;          // the last status pushed
let readOnly = false;
let previewVersion = -1;
let preview = {paths: [], file: "", error: ""};
const trail = [];           // the tool path: [x, y] machine coordinates
const MAX_TRAIL = 50000;
let droAxes = "";
let jogAxes = "";
let lastFile = null;

function $(id) { return document.getElementById(id); }

function el(tag, attrs, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (k === "class") e.className = v; else e.setAttribute(k, v);
  }
  for (const c of children) {
    e.append(c instanceof Node ? c : document.createTextNode(String(c)));
  }
  return e;
}

function say(text, bad) {
  const box = $("answer");
  box.textContent = text;
  box.className = bad ? "error" : "";
}

async function command(action, body) {
  let r;
  try {
    r = await fetch(`/api/machine/${action}`, {
      method: "POST", headers: {"Content-Type": "application/json"},
      body: JSON.stringify(body || {}), credentials: "same-origin"});
  } catch (e) {
    say(`${action}: the workbench does not answer`, true);
    return false;
  }
  let answer = {};
  try { answer = await r.json(); } catch (e) { answer = {}; }
  if (!r.ok || !answer.ok) {
    say(String(answer.error || `${action}: HTTP ${r.status}`).trim(), true);
    return false;
  }
  say("", false);
  return true;
}

// ---------------------------------------------------------------- status

function fmt(v) { return Number(v).toFixed(3); }

function buildDro(st) {
  const body = $("dro").querySelector("tbody");
  body.replaceChildren();
  [...st.axes].forEach((axis, i) => {
    const home = el("button", {type: "button", class: "home-joint"}, "Home");
    home.addEventListener("click", () => command("home", {joint: i}));
    body.append(el("tr", {"data-axis": axis},
      el("th", {}, axis), el("td", {class: "work"}, ""),
      el("td", {class: "machine"}, ""), el("td", {class: "homed"}, ""),
      el("td", {class: "change"}, home)));
  });
  droAxes = st.axes;
}

function buildJog(st) {
  const box = $("jog-buttons");
  box.replaceChildren();
  for (const axis of st.axes) {
    for (const sign of [-1, 1]) {
      const b = el("button", {type: "button", "data-axis": axis,
        "data-dir": String(sign), class: "jog"},
        `${axis}${sign < 0 ? "−" : "+"}`);
      b.addEventListener("pointerdown", (ev) => jogStart(ev, axis, sign));
      for (const end of ["pointerup", "pointerleave", "pointercancel"]) {
        b.addEventListener(end, () => jogEnd(axis));
      }
      box.append(b);
    }
  }
  jogAxes = st.axes;
}

let jogging = null;

function jogStart(ev, axis, sign) {
  ev.preventDefault();
  const speed = Math.abs(Number($("jog-speed").value) || 0) / 60;
  const step = $("jog-step").value;
  if (step) {
    command("jog", {axis, velocity: sign * speed, distance: Number(step)});
    return;
  }
  jogging = axis;
  command("jog", {axis, velocity: sign * speed});
}

function jogEnd(axis) {
  if (jogging !== axis) return;
  jogging = null;
  command("jog-stop", {axis});
}

function showStatus(st) {
  status = st;
  const missing = !st.connected;
  $("nomachine").hidden = !missing;
  $("panel").classList.toggle("off", missing);
  if (missing) {
    $("nomachine-why").textContent = st.why ? `(${st.why})` : "";
    return;
  }
  if (st.axes !== droAxes) buildDro(st);
  if (st.axes !== jogAxes) buildJog(st);
  $("state").textContent = st.state;
  $("mode").textContent = st.mode;
  $("interp").textContent = st.paused ? `${st.interp} (paused)` : st.interp;
  $("estop").textContent = st.estop ? "Reset E-stop" : "E-stop";
  $("estop").classList.toggle("active", st.estop);
  $("power").textContent = st.enabled ? "Power off" : "Power on";
  $("power").disabled = st.estop;
  const rows = $("dro").querySelectorAll("tbody tr");
  rows.forEach((row, i) => {
    row.querySelector(".work").textContent = fmt(st.work[i]);
    row.querySelector(".machine").textContent = fmt(st.machine[i]);
    const j = st.joints[i];
    row.querySelector(".homed").textContent =
      j ? (j.homed ? "✓" : j.homing ? "homing…" : "—") : "";
  });
  $("mdi-last").textContent = st.mdi || "";
  $("program-file").textContent = st.file || "—";
  $("program-line").textContent = String(st.line);
  $("velocity").textContent = fmt(st.velocity);
  $("tool").textContent = String(st.tool);
  const feed = Math.round(st.feedrate * 100);
  $("feed-value").textContent = `${feed} %`;
  if (document.activeElement !== $("feed")) $("feed").value = feed;
  if (st.spindle) {
    const so = Math.round(st.spindle.override * 100);
    $("spindle-value").textContent = `${so} %`;
    $("spindle-speed").textContent = String(Math.round(st.spindle.speed));
    if (document.activeElement !== $("spindle")) $("spindle").value = so;
  }
  if (st.file !== lastFile && st.file && !$("program-path").value) {
    $("program-path").value = st.file;
  }
  lastFile = st.file;
  const last = trail[trail.length - 1];
  const [x, y] = st.xy;
  if (!last || Math.abs(last[0] - x) > 1e-4 || Math.abs(last[1] - y) > 1e-4) {
    trail.push([x, y]);
    if (trail.length > MAX_TRAIL) trail.splice(0, trail.length - MAX_TRAIL);
  }
  if (st.preview !== previewVersion) loadPreview(st.preview);
  draw();
}

function showMessages(list) {
  const box = $("messages");
  for (const m of list) {
    const when = new Date(m.time * 1000).toLocaleTimeString();
    box.append(el("li", {class: m.kind}, `${when} ${m.kind}: ${m.text}`));
  }
  while (box.children.length > 200) box.firstChild.remove();
  box.scrollTop = box.scrollHeight;
}

async function loadPreview(version) {
  previewVersion = version;
  try {
    const r = await fetch("/api/machine/preview", {credentials: "same-origin"});
    preview = await r.json();
  } catch (e) {
    return;
  }
  $("preview-error").textContent = preview.error || "";
  draw();
}

// ---------------------------------------------------------------- backplot

function bounds() {
  let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
  const take = (x, y) => {
    x0 = Math.min(x0, x); x1 = Math.max(x1, x);
    y0 = Math.min(y0, y); y1 = Math.max(y1, y);
  };
  for (const p of preview.paths || []) {
    for (let i = 0; i < p.points.length; i += 2) take(p.points[i], p.points[i + 1]);
  }
  for (const [x, y] of trail) take(x, y);
  if (status && status.connected) take(status.xy[0], status.xy[1]);
  if (!isFinite(x0)) { x0 = -10; y0 = -10; x1 = 10; y1 = 10; }
  const pad = Math.max(x1 - x0, y1 - y0, 10) * 0.08;
  return [x0 - pad, y0 - pad, x1 + pad, y1 + pad];
}

function draw() {
  const canvas = $("backplot");
  const ctx = canvas.getContext("2d");
  const w = canvas.width, h = canvas.height;
  ctx.fillStyle = "#10161c";
  ctx.fillRect(0, 0, w, h);
  const [x0, y0, x1, y1] = bounds();
  const scale = Math.min(w / (x1 - x0), h / (y1 - y0));
  const ox = (w - (x1 - x0) * scale) / 2, oy = (h - (y1 - y0) * scale) / 2;
  const px = (x) => ox + (x - x0) * scale;
  const py = (y) => h - (oy + (y - y0) * scale);
  // the machine origin's axes
  ctx.strokeStyle = "#34414e";
  ctx.lineWidth = 1;
  ctx.beginPath();
  ctx.moveTo(px(0), 0); ctx.lineTo(px(0), h);
  ctx.moveTo(0, py(0)); ctx.lineTo(w, py(0));
  ctx.stroke();
  for (const p of preview.paths || []) {
    ctx.strokeStyle = p.kind === "rapid" ? "#d9c24a" : "#eef2f5";
    ctx.setLineDash(p.kind === "rapid" ? [4, 4] : []);
    ctx.beginPath();
    for (let i = 0; i < p.points.length; i += 2) {
      const f = i === 0 ? "moveTo" : "lineTo";
      ctx[f](px(p.points[i]), py(p.points[i + 1]));
    }
    ctx.stroke();
  }
  ctx.setLineDash([]);
  if (trail.length > 1) {
    ctx.strokeStyle = "#e0533d";
    ctx.lineWidth = 2;
    ctx.beginPath();
    trail.forEach(([x, y], i) => ctx[i ? "lineTo" : "moveTo"](px(x), py(y)));
    ctx.stroke();
  }
  if (status && status.connected) {
    const [x, y] = status.xy;
    ctx.strokeStyle = "#5fd35f";
    ctx.lineWidth = 2;
    ctx.beginPath();
    ctx.arc(px(x), py(y), 6, 0, 2 * Math.PI);
    ctx.moveTo(px(x) - 10, py(y)); ctx.lineTo(px(x) + 10, py(y));
    ctx.moveTo(px(x), py(y) - 10); ctx.lineTo(px(x), py(y) + 10);
    ctx.stroke();
  }
  ctx.fillStyle = "#8fa1b3";
  ctx.font = "12px ui-monospace, monospace";
  ctx.fillText(`X ${fmt(x0)} … ${fmt(x1)}   Y ${fmt(y0)} … ${fmt(y1)}`, 8, h - 8);
}

// ---------------------------------------------------------------- wiring

function wire() {
  $("estop").addEventListener("click", () =>
    command(status && status.estop ? "estop-reset" : "estop"));
  $("power").addEventListener("click", () =>
    command(status && status.enabled ? "off" : "on"));
  $("home-all").addEventListener("click", () => command("home", {joint: -1}));
  $("unhome-all").addEventListener("click", () => command("unhome", {joint: -1}));
  $("mdi").addEventListener("submit", async (ev) => {
    ev.preventDefault();
    const line = $("mdi-line").value.trim();
    if (line && await command("mdi", {line})) $("mdi-line").value = "";
  });
  $("program").addEventListener("submit", (ev) => {
    ev.preventDefault();
    const path = $("program-path").value.trim();
    if (path) command("open", {path});
  });
  for (const [id, action] of [["program-run", "run"], ["program-pause", "pause"],
    ["program-resume", "resume"], ["program-step", "step"],
    ["program-abort", "abort"]]) {
    $(id).addEventListener("click", () => command(action));
  }
  $("feed").addEventListener("change", () =>
    command("feed", {scale: Number($("feed").value) / 100}));
  $("spindle").addEventListener("change", () =>
    command("spindle-override", {scale: Number($("spindle").value) / 100}));
  $("clear-trail").addEventListener("click", () => { trail.length = 0; draw(); });
}

async function loadInfo() {
  try {
    const r = await fetch("/api/info", {credentials: "same-origin"});
    const info = await r.json();
    readOnly = info.read_only;
    document.body.classList.toggle("readonly", readOnly);
    $("readonly").hidden = !readOnly;
    $("instance").textContent = `instance ${info.instance}`;
  } catch (e) {
    say("the workbench does not answer", true);
  }
}

function connect() {
  const scheme = location.protocol === "https:" ? "wss:" : "ws:";
  const socket = new WebSocket(`${scheme}//${location.host}/ws/machine`);
  const link = $("link");
  socket.onopen = () => { link.textContent = "live"; link.className = "badge"; };
  socket.onmessage = (event) => {
    const msg = JSON.parse(event.data);
    if (msg.messages) showMessages(msg.messages);
    if (msg.status) showStatus(msg.status);
  };
  socket.onclose = () => {
    link.textContent = "disconnected"; link.className = "badge bad";
    setTimeout(connect, 1000);
  };
}

wire();
loadInfo();
draw();
connect();
