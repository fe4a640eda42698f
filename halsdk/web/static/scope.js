// The Scope page of the HAL workbench (halscope): up to 16 channels
// sampled in a realtime thread, triggered on the server, drawn on a
// canvas.  Plain JavaScript, no build step.
//
// Names are data: they reach the document through textContent, values
// and attributes only, never as HTML.
//
// What the page shows is also in window.scope (for tests and the
// console): the last screen (its samples, trigger index, sample time)
// and the last status.
"use strict";

const COLOURS = ["#ffd700", "#00e5ff", "#ff5fd2", "#7cff4f", "#ff8c3a", "#8fa8ff",
  "#ff4f4f", "#e0e0e0", "#c0ff00", "#00ffa8", "#ffb3b3", "#b388ff",
  "#ffe082", "#80deea", "#f48fb1", "#a5d6a7"];
const XDIV = 10, YDIV = 8;

const scope = window.scope = {
  session: null, readOnly: false, running: false, config: null,
  frame: null,          // {start, trigger, channels: [[...]], dt, names}
  status: null, cursorA: null, cursorB: null,
};
let socket = null;
let maxChannels = 16;

function $(id) { return document.getElementById(id); }

function el(tag, attrs, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (k === "class") e.className = v;
    else e.setAttribute(k, v);
  }
  for (const c of children) e.append(c instanceof Node ? c : document.createTextNode(String(c)));
  return e;
}

function say(text, error) {
  const m = $("message");
  m.textContent = text || "";
  m.className = error ? "error" : "";
}

// ------------------------------------------------------------ controls

function channelRows() {
  return [...document.querySelectorAll("#channels tbody tr")];
}

function buildChannels() {
  const body = document.querySelector("#channels tbody");
  for (let i = 0; i < maxChannels; i++) {
    const name = el("input", {class: "name", list: "names", "data-ch": i,
      "aria-label": `channel ${i + 1}`, autocomplete: "off"});
    const scale = el("input", {class: "num scale", type: "number", step: "any", value: "1",
      "aria-label": `channel ${i + 1} scale`});
    const offset = el("input", {class: "num offset", type: "number", step: "any", value: "0",
      "aria-label": `channel ${i + 1} offset`});
    const colour = el("input", {class: "colour", type: "color", value: COLOURS[i % COLOURS.length],
      "aria-label": `channel ${i + 1} colour`});
    name.addEventListener("change", updateTriggerChoices);
    for (const input of [scale, offset, colour]) input.addEventListener("input", draw);
    body.append(el("tr", {}, el("td", {}, String(i + 1)), el("td", {}, name),
      el("td", {}, scale), el("td", {}, offset), el("td", {}, colour)));
  }
}

function usedRows() {
  return channelRows().filter((r) => r.querySelector(".name").value.trim() !== "");
}

function updateTriggerChoices() {
  const select = $("trigger");
  const keep = select.value;
  select.replaceChildren(el("option", {value: "-1"}, "none"));
  channelRows().forEach((row, i) => {
    const name = row.querySelector(".name").value.trim();
    if (name) select.append(el("option", {value: String(i)}, `${i + 1}: ${name}`));
  });
  if ([...select.options].some((o) => o.value === keep)) select.value = keep;
}

function readConfig() {
  const rows = usedRows();
  const all = channelRows();
  const trigRow = Number($("trigger").value);
  const trigger = trigRow < 0 ? -1 : rows.indexOf(all[trigRow]);
  return {
    channels: rows.map((r) => r.querySelector(".name").value.trim()),
    thread: $("thread").value,
    mult: Number($("mult").value),
    length: Number($("length").value),
    mode: $("mode").value,
    trigger,
    edge: $("edge").value,
    level: Number($("level").value),
    position: Number($("position").value),
  };
}

function style(i) {
  // the look of used channel i
  const row = usedRows()[i];
  if (!row) return {scale: 1, offset: 0, colour: COLOURS[i % COLOURS.length]};
  const scale = Number(row.querySelector(".scale").value) || 1;
  return {scale, offset: Number(row.querySelector(".offset").value) || 0,
    colour: row.querySelector(".colour").value};
}

async function post(path, body) {
  const response = await fetch(path, {method: "POST", headers: {"Content-Type": "application/json"},
    body: JSON.stringify(body)});
  let data = {};
  try { data = await response.json(); } catch (e) { data = {error: response.statusText}; }
  return {status: response.status, data};
}

async function run() {
  if (!scope.session) return say("not connected", true);
  const config = readConfig();
  const {status, data} = await post("/api/scope/start", {session: scope.session, ...config});
  if (status !== 200) return say(data.error || `refused (${status})`, true);
  scope.config = {...config, dt: data.dt};
  scope.running = true;
  scope.frame = null;
  scope.roll = null;
  say(`running: ${config.channels.length} channel(s), one sample every ${fmtTime(data.dt)}`);
  draw();
}

async function stop() {
  if (!scope.session) return;
  const {status, data} = await post("/api/scope/stop", {session: scope.session});
  if (status !== 200) return say(data.error || `refused (${status})`, true);
  scope.running = false;
  say("stopped");
}

// ------------------------------------------------------------ data

function onFrame(frame) {
  const cfg = scope.config;
  scope.frame = {...frame, dt: cfg.dt, names: cfg.channels};
  const plot = $("plot");
  plot.dataset.trigger = frame.trigger === null ? "" : String(frame.trigger);
  plot.dataset.start = String(frame.start);
  plot.dataset.frames = String((Number(plot.dataset.frames) || 0) + 1);
  draw();
}

function onRoll(roll) {
  const cfg = scope.config;
  if (!cfg) return;
  let r = scope.roll;
  if (!r || r.channels.length !== roll.channels.length) {
    r = scope.roll = {start: roll.start, channels: roll.channels.map(() => [])};
  }
  roll.channels.forEach((values, i) => { r.channels[i].push(...values); });
  const extra = r.channels[0].length - cfg.length;
  if (extra > 0) {
    r.channels.forEach((c) => c.splice(0, extra));
    r.start += extra;
  }
  scope.frame = {start: r.start, trigger: null, channels: r.channels, dt: cfg.dt,
    names: cfg.channels};
}

function onStatus(status) {
  scope.status = status;
  $("state").textContent = status.error ? "stopped" : status.state;
  $("state").className = "badge" + (status.error ? " bad" : "");
  $("samples").textContent = status.samples;
  $("frames").textContent = status.frames;
  $("lost").textContent = status.lost;
  $("overruns").textContent = status.overruns;
  $("lost").className = status.lost ? "bad" : "";
  $("rate").textContent = status.dt ? `${fmtNum(1 / status.dt)} Hz` : "–";
  if (status.error) { say(status.error, true); scope.running = false; }
}

function connect() {
  const scheme = location.protocol === "https:" ? "wss:" : "ws:";
  socket = new WebSocket(`${scheme}//${location.host}/ws/scope`);
  const link = $("link");
  socket.onmessage = (event) => {
    const msg = JSON.parse(event.data);
    if (msg.hello) {
      scope.session = msg.hello.session;
      link.textContent = "live"; link.className = "badge";
    }
    if (msg.error) say(msg.error, true);
    if (msg.frame) onFrame(msg.frame);
    if (msg.roll) onRoll(msg.roll);
    if (msg.status) onStatus(msg.status);
  };
  socket.onclose = () => {
    scope.session = null; scope.running = false;
    link.textContent = "disconnected"; link.className = "badge bad";
    setTimeout(connect, 1000);
  };
}

let drawPending = false;
function requestDraw() {
  if (drawPending) return;
  drawPending = true;
  requestAnimationFrame(() => { drawPending = false; draw(); });
}

// ------------------------------------------------------------ drawing

function view() {
  // the samples on screen: [first, count) of the frame
  const f = scope.frame;
  const n = f ? f.channels[0].length : (scope.config ? scope.config.length : 1000);
  const zoom = Number($("zoom").value) || 1;
  const count = Math.max(2, Math.floor(n / zoom));
  const pan = Number($("pan").value) / 1000;
  const first = Math.round((n - count) * pan);
  return {n, first, count};
}

function fmtNum(v) {
  if (!isFinite(v)) return String(v);
  const a = Math.abs(v);
  if (a !== 0 && (a >= 1e6 || a < 1e-3)) return v.toExponential(3);
  return String(Number(v.toPrecision(6)));
}

function fmtTime(s) {
  const a = Math.abs(s);
  if (a >= 1) return `${fmtNum(s)} s`;
  if (a >= 1e-3) return `${fmtNum(s * 1e3)} ms`;
  return `${fmtNum(s * 1e6)} µs`;
}

function draw() {
  const canvas = $("plot");
  const ctx = canvas.getContext("2d");
  const W = canvas.width, H = canvas.height;
  ctx.fillStyle = "#111";
  ctx.fillRect(0, 0, W, H);
  ctx.strokeStyle = "#333";
  ctx.lineWidth = 1;
  for (let i = 0; i <= XDIV; i++) line(ctx, i * W / XDIV, 0, i * W / XDIV, H);
  for (let i = 0; i <= YDIV; i++) line(ctx, 0, i * H / YDIV, W, i * H / YDIV);
  ctx.strokeStyle = "#555";
  line(ctx, 0, H / 2, W, H / 2);
  const f = scope.frame;
  const {first, count} = view();
  const x = (i) => (i - first) * W / (count - 1);
  const y = (v, s) => H / 2 - ((v - s.offset) / s.scale) * (H / YDIV);
  if (f) {
    f.channels.forEach((values, c) => {
      const s = style(c);
      ctx.strokeStyle = s.colour;
      ctx.lineWidth = 1.5;
      ctx.beginPath();
      const last = Math.min(values.length, first + count);
      for (let i = first; i < last; i++) {
        const px = x(i), py = y(values[i], s);
        if (i === first) ctx.moveTo(px, py); else ctx.lineTo(px, py);
      }
      ctx.stroke();
    });
    if (f.trigger !== null && f.trigger !== undefined) {
      ctx.strokeStyle = "#f44";
      ctx.setLineDash([4, 4]);
      line(ctx, x(f.trigger), 0, x(f.trigger), H);
      const cfg = scope.config;
      if (cfg && cfg.trigger >= 0) {
        const ly = y(cfg.level, style(cfg.trigger));
        line(ctx, 0, ly, W, ly);
      }
      ctx.setLineDash([]);
    }
  }
  for (const [name, at] of [["A", scope.cursorA], ["B", scope.cursorB]]) {
    if (at === null) continue;
    ctx.strokeStyle = "#fff";
    line(ctx, x(at), 0, x(at), H);
    ctx.fillStyle = "#fff";
    ctx.fillText(name, x(at) + 3, 12);
  }
  ctx.fillStyle = "#aaa";
  if (f) {
    const div = (count - 1) * f.dt / XDIV;
    ctx.fillText(`${fmtTime(div)}/div`, 6, H - 6);
  }
  showCursors();
}

function line(ctx, x0, y0, x1, y1) {
  ctx.beginPath(); ctx.moveTo(x0, y0); ctx.lineTo(x1, y1); ctx.stroke();
}

function showCursors() {
  const f = scope.frame;
  const out = $("cursors");
  if (!f || scope.cursorA === null) {
    out.textContent = "cursors: click A, shift-click B";
    return;
  }
  const a = scope.cursorA, b = scope.cursorB === null ? a : scope.cursorB;
  const parts = [`Δt ${fmtTime((b - a) * f.dt)}`];
  f.channels.forEach((values, c) => {
    if (a < values.length && b < values.length) {
      parts.push(`Δ${c + 1} ${fmtNum(values[b] - values[a])}`);
    }
  });
  out.textContent = parts.join("  ");
}

function onPlotClick(event) {
  if (!scope.frame) return;
  const canvas = $("plot");
  const rect = canvas.getBoundingClientRect();
  const {first, count, n} = view();
  const at = Math.min(n - 1, Math.max(0,
    first + Math.round((event.clientX - rect.left) / rect.width * (count - 1))));
  if (event.shiftKey) scope.cursorB = at; else scope.cursorA = at;
  draw();
}

// ------------------------------------------------------------ export

function download(blob, name) {
  const a = el("a", {href: URL.createObjectURL(blob), download: name});
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 10000);
}

function toCsv() {
  const f = scope.frame;
  if (!f) return "";
  const quote = (s) => `"${String(s).replace(/"/g, '""')}"`;
  const rows = [["time", ...f.names].map(quote).join(",")];
  const zero = f.trigger === null || f.trigger === undefined ? 0 : f.trigger;
  for (let i = 0; i < f.channels[0].length; i++) {
    rows.push([((i - zero) * f.dt).toPrecision(9), ...f.channels.map((c) => c[i])].join(","));
  }
  return rows.join("\n") + "\n";
}
scope.toCsv = toCsv;

// ------------------------------------------------------------ start

async function init() {
  buildChannels();
  $("run").addEventListener("click", run);
  $("stop").addEventListener("click", stop);
  $("zoom").addEventListener("change", draw);
  $("pan").addEventListener("input", draw);
  $("plot").addEventListener("click", onPlotClick);
  $("csv").addEventListener("click", () => {
    if (scope.frame) download(new Blob([toCsv()], {type: "text/csv"}), "scope.csv");
  });
  $("png").addEventListener("click", () => {
    $("plot").toBlob((blob) => { if (blob) download(blob, "scope.png"); }, "image/png");
  });
  $("plot").addEventListener("wheel", (event) => {
    event.preventDefault();
    const zoom = $("zoom");
    const i = zoom.selectedIndex + (event.deltaY < 0 ? 1 : -1);
    zoom.selectedIndex = Math.max(0, Math.min(zoom.options.length - 1, i));
    draw();
  }, {passive: false});
  setInterval(() => { if (scope.roll) requestDraw(); }, 50);
  const response = await fetch("/api/scope/sources");
  const src = await response.json();
  maxChannels = src.max_channels;
  scope.readOnly = src.read_only;
  document.body.classList.toggle("readonly", src.read_only);
  $("readonly").hidden = !src.read_only;
  for (const t of src.threads) {
    $("thread").append(el("option", {value: t.name}, `${t.name} (${fmtTime(t.period * 1e-9)})`));
  }
  const list = $("names");
  for (const name of [...src.pins, ...src.signals, ...src.params]) {
    list.append(el("option", {value: name}));
  }
  fetch("/api/info").then((r) => r.json()).then((info) => {
    $("instance").textContent = `instance ${info.instance}`;
  });
  draw();
  connect();
}

init();
