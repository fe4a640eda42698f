// The Latency page of the HAL workbench: start, reset and stop a latency
// test in the instance (its own threads latency-base and latency-servo),
// its figures and histograms pushed live by /ws/latency.  Names and
// messages reach the document as text only.
"use strict";

let socket = null;
let running = false;
let readOnly = false;

function el(tag, attrs, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  for (const c of children) {
    e.append(c instanceof Node ? c : document.createTextNode(String(c)));
  }
  return e;
}

function message(text, error) {
  const m = document.getElementById("message");
  m.textContent = text;
  m.className = error ? "error" : "";
}

// a figure in ns shown in µs
function us(ns, digits) {
  if (ns === null || ns === undefined) return "–";
  return (ns / 1000).toFixed(digits === undefined ? 1 : digits);
}

function period(ns) {
  return ns >= 1e6 && ns % 1e6 === 0 ? `${ns / 1e6} ms` : `${ns / 1000} µs`;
}

// ------------------------------------------------------------ the figures

function showState(st) {
  running = st.running;
  document.getElementById("start").disabled = running;
  document.getElementById("reset").disabled = !running;
  document.getElementById("stop").disabled = !running;
  for (const input of document.querySelectorAll("#settings input")) {
    input.disabled = running;
  }
  const status = document.getElementById("status");
  const sched = document.getElementById("sched");
  if (!running) {
    status.textContent = "No latency test is running.";
    sched.textContent = "";
    sched.className = "hint";
  } else {
    status.textContent = `Latency test running: threads ${st.threads.map((t) => t.thread).join(", ")}` +
      ` · ${st.sweeps} histogram readings` + (st.error ? ` · error: ${st.error}` : "");
    if (st.realtime === true) {
      sched.textContent = "Threads run with realtime scheduling (SCHED_FIFO).";
      sched.className = "rt";
    } else if (st.realtime === false) {
      sched.textContent = `Threads run WITHOUT realtime scheduling: ${st.note}`;
      sched.className = "nort";
    } else {
      sched.textContent = "Scheduling of the threads: not known.";
      sched.className = "hint";
    }
  }
  const body = document.querySelector("#figures tbody");
  body.replaceChildren(...st.threads.map((t) => el("tr", {"data-thread": t.thread},
    el("td", {}, t.thread), el("td", {}, period(t.period)),
    el("td", {class: "jitter"}, us(t.jitter)), el("td", {class: "min"}, us(t.min)),
    el("td", {class: "max"}, us(t.max)), el("td", {class: "avg"}, us(t.avg, 2)),
    el("td", {class: "sdev"}, us(t.sdev, 2)), el("td", {class: "last"}, us(t.last)),
    el("td", {class: "samples"}, t.samples === null ? "–" : String(t.samples)),
    el("td", {class: "overruns"}, String(t.overruns)))));
  showHistograms(st.threads);
}

// ------------------------------------------------------------ histograms

function showHistograms(threads) {
  const box = document.getElementById("histograms");
  const keep = new Set(threads.map((t) => t.thread));
  for (const div of [...box.children]) {
    if (!keep.has(div.dataset.thread)) div.remove();
  }
  for (const t of threads) {
    let div = [...box.children].find((d) => d.dataset.thread === t.thread);
    if (!div) {
      div = el("div", {class: "hist"}, el("h3", {}, t.thread),
        el("canvas", {width: "560", height: "260"}), el("div", {class: "hint caption"}));
      div.dataset.thread = t.thread;
      box.append(div);
    }
    const h = t.histogram;
    const canvas = div.querySelector("canvas");
    canvas.dataset.total = h ? String(h.total) : "0";
    canvas.dataset.filled = h ? String(h.counts.length) : "0";
    div.querySelector(".caption").textContent = h
      ? `${h.total} latencies · bins of ${h.binsize} ns · beyond ±${us((h.bins + 1) * h.binsize)} µs:` +
        ` ${h.below} below, ${h.above} above (red)`
      : "no histogram read yet";
    draw(canvas, h);
  }
}

// bars per bin on a log count axis, the latencies beyond the last bins as
// red bars at the ends
function draw(canvas, h) {
  const g = canvas.getContext("2d");
  const W = canvas.width, H = canvas.height;
  const left = 44, right = 10, top = 10, bottom = 30;
  const pw = W - left - right, ph = H - top - bottom;
  g.clearRect(0, 0, W, H);
  g.fillStyle = "#fff";
  g.fillRect(0, 0, W, H);
  g.strokeStyle = "#999";
  g.strokeRect(left, top, pw, ph);
  if (!h) return;
  const span = h.bins + 2;                  // bins -N-1 .. N+1: the extras at the ends
  const slots = 2 * span + 1;
  const bw = pw / slots;
  let most = Math.max(1, h.below, h.above);
  for (const [, c] of h.counts) most = Math.max(most, c);
  const decades = Math.max(1, Math.ceil(Math.log10(most + 1)));
  const y = (c) => top + ph - ph * Math.log10(c + 1) / decades;
  // count axis: decades
  g.font = "11px system-ui, sans-serif";
  g.fillStyle = "#556";
  g.textAlign = "right";
  g.textBaseline = "middle";
  for (let d = 0; d <= decades; d++) {
    const yy = y(10 ** d - 1);
    g.strokeStyle = "#eee";
    g.beginPath(); g.moveTo(left, yy); g.lineTo(left + pw, yy); g.stroke();
    g.fillText(d === 0 ? "0" : `1e${d}`, left - 4, yy);
  }
  const x = (b) => left + (b + span) * bw;
  g.fillStyle = "#2a6fb0";
  for (const [b, c] of h.counts) {
    g.fillRect(x(b), y(c), Math.max(1, bw), top + ph - y(c));
  }
  g.fillStyle = "#c0202a";
  if (h.below) g.fillRect(x(-span), y(h.below), Math.max(2, bw), top + ph - y(h.below));
  if (h.above) g.fillRect(x(span), y(h.above), Math.max(2, bw), top + ph - y(h.above));
  // latency axis, in µs
  g.fillStyle = "#556";
  g.textAlign = "center";
  g.textBaseline = "top";
  const edge = (h.bins + 1) * h.binsize;
  for (const f of [-1, -0.5, 0, 0.5, 1]) {
    const b = f * (h.bins + 1);
    g.fillText(us(f * edge), x(b) + bw / 2, top + ph + 4);
  }
  g.fillText("latency (µs)", left + pw / 2, top + ph + 16);
}

// ------------------------------------------------------------ the controls

async function post(action, body) {
  try {
    const r = await fetch(`/api/latency/${action}`, {method: "POST",
      headers: {"Content-Type": "application/json"}, body: JSON.stringify(body || {})});
    const data = await r.json();
    if (!r.ok) {
      message(data.error || `${action}: ${r.status}`, true);
    } else {
      message(`${action}: done`, false);
    }
    if (data.state) showState(data.state);
  } catch (exc) {
    message(`${action}: ${exc}`, true);
  }
}

function settings() {
  const form = document.getElementById("settings");
  const v = (name) => Number(form.elements[name].value);
  return {base: Math.round(v("base") * 1000), servo: Math.round(v("servo") * 1000),
          base_binsize: Math.round(v("base_binsize")),
          servo_binsize: Math.round(v("servo_binsize")), bins: Math.round(v("bins")),
          realtime: form.elements.realtime.checked};
}

function connect() {
  const scheme = location.protocol === "https:" ? "wss:" : "ws:";
  socket = new WebSocket(`${scheme}//${location.host}/ws/latency`);
  const link = document.getElementById("link");
  socket.onopen = () => { link.textContent = "live"; link.className = "badge"; };
  socket.onmessage = (event) => {
    const msg = JSON.parse(event.data);
    if (msg.state) showState(msg.state);
  };
  socket.onclose = () => {
    link.textContent = "disconnected"; link.className = "badge bad";
    setTimeout(connect, 1000);
  };
}

async function init() {
  try {
    const info = await (await fetch("/api/info")).json();
    readOnly = info.read_only;
    document.body.classList.toggle("readonly", readOnly);
    document.getElementById("readonly").hidden = !readOnly;
    document.getElementById("instance").textContent = `instance ${info.instance}`;
  } catch (exc) {
    message(`cannot read the workbench: ${exc}`, true);
  }
  document.getElementById("settings").addEventListener("submit", (ev) => {
    ev.preventDefault();
    post("start", settings());
  });
  document.getElementById("reset").addEventListener("click", () => post("reset"));
  document.getElementById("stop").addEventListener("click", () => post("stop"));
  connect();
}

init();
