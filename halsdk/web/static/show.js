// The Show page of the HAL workbench (halshow): a tree and a search over
// the instance, a detail view per item, live values of what is visible,
// the changes and halcmd's command line.  Plain JavaScript, no build step.
//
// Names are data: they reach the document through textContent and
// element attributes only, never as HTML.
"use strict";

const KINDS = [
  ["components", "component", "Components"], ["pins", "pin", "Pins"],
  ["params", "param", "Parameters"], ["signals", "signal", "Signals"],
  ["functions", "function", "Functions"], ["threads", "thread", "Threads"],
];
const VALUE_KINDS = new Set(["pin", "param", "signal"]);
const SEARCH_LIMIT = 500;
const WATCH_STORE = "halsdk-web-watch";

let tree = null;                 // the last /api/tree
let readOnly = false;
let socket = null;
let detailKey = null;            // "kind:name" of the detail view
const cells = new Map();         // key -> Set of value elements on the page
const visible = new Set();       // keys whose value cell is on screen
const values = new Map();        // key -> last value text
const opened = new Set();        // paths of the open tree groups

function el(tag, attrs, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (k === "class") e.className = v;
    else if (k.startsWith("on")) e.addEventListener(k.slice(2), v);
    else e.setAttribute(k, v);
  }
  for (const c of children) {
    if (c === null || c === undefined) continue;
    e.append(c instanceof Node ? c : document.createTextNode(String(c)));
  }
  return e;
}

// ------------------------------------------------------------ live values

const observer = new IntersectionObserver((entries) => {
  for (const entry of entries) {
    const key = entry.target.dataset.key;
    entry.target.dataset.seen = entry.isIntersecting ? "1" : "0";
    if (entry.isIntersecting) visible.add(key);
    else if (!anyVisible(key, entry.target)) visible.delete(key);
  }
  scheduleWatch();
});

function anyVisible(key, except) {
  for (const c of cells.get(key) || []) {
    if (c !== except && c.isConnected && c.dataset.seen === "1") return true;
  }
  return false;
}

function valueCell(key, text) {
  const span = el("span", {class: "value", "data-key": key});
  span.textContent = values.has(key) ? values.get(key) : (text ?? "");
  if (!cells.has(key)) cells.set(key, new Set());
  cells.get(key).add(span);
  observer.observe(span);
  return span;
}

function pruneCells() {
  for (const [key, set] of cells) {
    for (const c of set) {
      if (!c.isConnected) { set.delete(c); observer.unobserve(c); }
    }
    if (set.size === 0) { cells.delete(key); visible.delete(key); }
  }
}

let watchTimer = null;
function scheduleWatch() {
  if (watchTimer) return;
  watchTimer = setTimeout(() => { watchTimer = null; sendWatch(); }, 100);
}

function sendWatch() {
  pruneCells();
  const keys = new Set(visible);
  for (const k of watchList()) keys.add(k);
  if (detailKey && VALUE_KINDS.has(detailKey.split(":")[0])) keys.add(detailKey);
  if (socket && socket.readyState === WebSocket.OPEN) {
    socket.send(JSON.stringify({watch: [...keys]}));
  }
}

function showValue(key, text) {
  values.set(key, text);
  for (const c of cells.get(key) || []) {
    c.textContent = text === null ? "(gone)" : text;
  }
}

function connect() {
  const scheme = location.protocol === "https:" ? "wss:" : "ws:";
  socket = new WebSocket(`${scheme}//${location.host}/ws`);
  const link = document.getElementById("link");
  socket.onopen = () => {
    link.textContent = "live"; link.className = "badge"; sendWatch();
  };
  socket.onmessage = (event) => {
    const msg = JSON.parse(event.data);
    if (msg.values) {
      for (const [k, v] of Object.entries(msg.values)) showValue(k, v);
    }
    if (msg.tree) loadTree();
  };
  socket.onclose = () => {
    link.textContent = "disconnected"; link.className = "badge bad";
    setTimeout(connect, 1000);
  };
}

// ------------------------------------------------------------ the tree

function meta(kind, it) {
  if (kind === "pin") return `${it.type} ${it.dir}` + (it.signal ? ` ⇄ ${it.signal}` : "");
  if (kind === "param") return `${it.type} ${it.dir}`;
  if (kind === "signal") return `${it.type} ${it.writers}w ${it.readers}r`;
  if (kind === "function") return `${it.owner} users ${it.users}`;
  if (kind === "thread") return `${it.period} ns ${it.running ? "running" : "stopped"}`;
  if (kind === "component") return `${it.realtime ? "RT" : "User"} ${it.ready ? "ready" : ""}`;
  return "";
}

function row(kind, it, label) {
  const key = `${kind}:${it.name}`;
  const r = el("div", {class: "row", role: "treeitem", "data-item": key,
                       title: it.name, onclick: () => openDetail(kind, it.name)},
               el("span", {class: "name"}, label ?? it.name),
               el("span", {class: "meta"}, meta(kind, it)));
  if (VALUE_KINDS.has(kind)) r.append(valueCell(key, it.value));
  if (key === detailKey) r.classList.add("sel");
  return r;
}

// a group of the tree: names split at dots, its children made when opened
function group(kind, path, items, depth, label) {
  const d = el("details", {"data-path": path});
  d.append(el("summary", {}, `${label} (${items.length})`));
  const fill = () => {
    if (d.dataset.filled) return;
    d.dataset.filled = "1";
    const sub = new Map();
    const leaves = [];
    for (const it of items) {
      const parts = it.name.split(".");
      if (parts.length > depth + 1) {
        const head = parts.slice(0, depth + 1).join(".");
        if (!sub.has(head)) sub.set(head, []);
        sub.get(head).push(it);
      } else {
        leaves.push(it);
      }
    }
    for (const [head, list] of sub) {
      if (list.length === 1) leaves.push(list[0]);
      else d.append(group(kind, `${kind}/${head}`, list, depth + 1, head));
    }
    leaves.sort((a, b) => (a.name < b.name ? -1 : a.name > b.name ? 1 : 0));
    for (const it of leaves) d.append(row(kind, it));
  };
  d.addEventListener("toggle", () => {
    if (d.open) { opened.add(path); fill(); } else opened.delete(path);
    scheduleWatch();
  });
  if (opened.has(path)) { d.open = true; fill(); }
  return d;
}

function renderTree() {
  const box = document.getElementById("tree");
  const query = document.getElementById("search").value.trim();
  box.replaceChildren();
  if (!tree) return;
  if (query) {
    const match = matcher(query);
    let shown = 0, total = 0;
    for (const [list, kind, label] of KINDS) {
      const found = tree[list].filter((it) => match(it.name));
      total += found.length;
      if (!found.length) continue;
      box.append(el("div", {class: "more"}, `${label} (${found.length})`));
      for (const it of found) {
        if (shown >= SEARCH_LIMIT) break;
        box.append(row(kind, it));
        shown++;
      }
    }
    if (total > shown) box.append(el("div", {class: "more"}, `… ${total - shown} more: refine the search`));
    if (!total) box.append(el("p", {class: "hint"}, "nothing matches"));
  } else {
    for (const [list, kind, label] of KINDS) {
      box.append(group(kind, kind, tree[list], 0, label));
    }
  }
  scheduleWatch();
}

function matcher(query) {
  if (/[*?]/.test(query)) {
    const re = new RegExp("^" + query.replace(/[.+^${}()|[\]\\]/g, "\\$&")
      .replace(/\*/g, ".*").replace(/\?/g, ".") + "$", "i");
    return (name) => re.test(name);
  }
  const q = query.toLowerCase();
  return (name) => name.toLowerCase().includes(q);
}

async function api(path) {
  const r = await fetch(path, {credentials: "same-origin"});
  if (!r.ok) throw new Error(`${r.status} ${await r.text()}`);
  return r.json();
}

async function loadTree() {
  try {
    tree = await api("/api/tree");
  } catch (e) {
    say(String(e.message), true);
    return;
  }
  readOnly = tree.read_only;
  document.body.classList.toggle("readonly", readOnly);
  document.getElementById("readonly").hidden = !readOnly;
  document.getElementById("instance").textContent = `instance ${tree.instance}`;
  for (const [list, kind] of KINDS) {
    if (!VALUE_KINDS.has(kind)) continue;
    for (const it of tree[list]) values.set(`${kind}:${it.name}`, it.value);
  }
  renderTree();
  renderWatch();
  if (detailKey) {
    const i = detailKey.indexOf(":");
    openDetail(detailKey.slice(0, i), detailKey.slice(i + 1));
  }
}

// ------------------------------------------------------------ changes

function say(text, bad) {
  const m = document.getElementById("message");
  m.textContent = text;
  m.className = bad ? "error" : "";
}

async function post(path, body) {
  let r;
  try {
    r = await fetch(path, {method: "POST", credentials: "same-origin",
                           headers: {"Content-Type": "application/json"},
                           body: JSON.stringify(body)});
  } catch (e) {
    say(String(e), true);
    return null;
  }
  let data;
  try { data = await r.json(); } catch (e) { data = {ok: false, output: "", error: `${r.status}`}; }
  return data;
}

async function change(action, body) {
  const data = await post(`/api/${action}`, body);
  if (!data) return;
  say(((data.output || "") + (data.error || "")).trim() ||
      (data.ok ? `${action}: done` : `${action}: refused`), !data.ok);
  if (data.ok) loadTree();
}

function actionForm(label, fields, submit) {
  const inputs = fields.map(([name, placeholder, value]) =>
    el("input", {name, placeholder, "aria-label": placeholder, value: value ?? ""}));
  const f = el("form", {class: "act"}, ...inputs, el("button", {type: "submit"}, label));
  f.addEventListener("submit", (ev) => {
    ev.preventDefault();
    submit(Object.fromEntries(inputs.map((i) => [i.name, i.value])));
  });
  return f;
}

function itemLink(kind, name) {
  return el("a", {class: "item", onclick: () => openDetail(kind, name)}, name);
}

function kv(rows) {
  const t = el("table", {class: "kv"});
  for (const [k, v] of rows) {
    if (v === undefined || v === null || v === "") continue;
    t.append(el("tr", {}, el("td", {}, k), el("td", {}, v)));
  }
  return t;
}

function pinList(list) {
  if (!list || !list.length) return "—";
  const span = el("span", {});
  list.forEach((p, i) => {
    if (i) span.append(", ");
    span.append(itemLink("pin", p.name ?? p), p.owner ? ` (${p.dir}, ${p.owner})` : "");
  });
  return span;
}

async function openDetail(kind, name) {
  detailKey = `${kind}:${name}`;
  for (const r of document.querySelectorAll(".row.sel")) r.classList.remove("sel");
  for (const r of document.querySelectorAll(".row")) {
    if (r.dataset.item === detailKey) r.classList.add("sel");
  }
  let d;
  try {
    d = await api(`/api/item?kind=${encodeURIComponent(kind)}&name=${encodeURIComponent(name)}`);
  } catch (e) {
    say(String(e.message), true);
    return;
  }
  const box = document.getElementById("detail");
  box.replaceChildren(el("h2", {}, `${kind} `, el("code", {}, name)));
  if (!d.exists) {
    box.append(el("p", {class: "hint"}, "no longer exists"));
    sendWatch();
    return;
  }
  const key = `${kind}:${name}`;
  const rows = [];
  if (VALUE_KINDS.has(kind)) rows.push(["value", valueCell(key, d.value)]);
  rows.push(["type", d.type], ["direction", d.dir]);
  if (d.owner) rows.push(["owner", itemLink("component", d.owner)]);
  if (d.alias_of) rows.push(["alias of", d.alias_of]);
  if (kind === "pin") rows.push(["signal", d.signal ? itemLink("signal", d.signal) : "—"]);
  if (d.writers) rows.push(["writers", pinList(d.writers)], ["readers", pinList(d.readers)],
                           ["bidirectional", d.bidirs.length ? pinList(d.bidirs) : ""]);
  if (kind === "component") {
    rows.push(["id", d.id], ["realtime", String(d.realtime)], ["ready", String(d.ready)],
              ["pid", d.pid], ["alive", String(d.alive)], ["pins", pinList(d.pins)],
              ["params", links("param", d.params)], ["functions", links("function", d.functions)]);
  }
  if (kind === "function") {
    rows.push(["users", d.users], ["realtime", String(d.realtime)],
              ["threads", links("thread", d.threads)], ["time / max", `${d.time} / ${d.tmax}`]);
  }
  if (kind === "thread") {
    rows.push(["period", `${d.period} ns`], ["running", String(d.running)],
              ["functions", links("function", d.functions)], ["cycles", d.cycles],
              ["overruns", d.overruns], ["time / max", `${d.time} / ${d.tmax}`]);
  }
  box.append(kv(rows));
  if (VALUE_KINDS.has(kind)) {
    box.append(el("button", {type: "button", onclick: () => addWatch(key)}, "watch"));
  }
  if ((kind === "pin" && d.dir !== "OUT") || (kind === "param" && d.dir !== "RO")) {
    box.append(actionForm("setp", [["value", "new value"]],
                          (v) => change("setp", {name, value: v.value})));
  }
  if (kind === "pin") {
    box.append(actionForm("net", [["signal", "signal name", d.signal || ""]],
                          (v) => change("net", {signal: v.signal, pins: [name]})));
    if (d.signal) {
      box.append(actionForm("unlinkp", [], () => change("unlinkp", {pin: name})));
    }
  }
  if (kind === "signal") {
    box.append(actionForm("sets", [["value", "new value"]],
                          (v) => change("sets", {name, value: v.value})));
    box.append(actionForm("net (add a pin)", [["pin", "pin name"]],
                          (v) => change("net", {signal: name, pins: [v.pin]})));
  }
  if (kind === "function") {
    box.append(actionForm("addf", [["thread", "thread"], ["position", "position (optional)"]],
                          (v) => change("addf", {function: name, thread: v.thread,
                                                 position: v.position})));
    for (const t of d.threads) {
      box.append(actionForm(`delf from ${t}`, [], () => change("delf", {function: name, thread: t})));
    }
  }
  if (kind === "thread") {
    box.append(actionForm("addf", [["function", "function"], ["position", "position (optional)"]],
                          (v) => change("addf", {function: v.function, thread: name,
                                                 position: v.position})));
  }
  sendWatch();
}

function links(kind, names) {
  if (!names || !names.length) return "—";
  const span = el("span", {});
  names.forEach((n, i) => { if (i) span.append(", "); span.append(itemLink(kind, n)); });
  return span;
}

// ------------------------------------------------------------ watch list

function watchList() {
  try {
    const list = JSON.parse(localStorage.getItem(WATCH_STORE) || "[]");
    return Array.isArray(list) ? list.filter((k) => typeof k === "string") : [];
  } catch (e) {
    return [];
  }
}

function addWatch(key) {
  const list = watchList();
  if (!list.includes(key)) list.push(key);
  localStorage.setItem(WATCH_STORE, JSON.stringify(list));
  renderWatch();
}

function removeWatch(key) {
  localStorage.setItem(WATCH_STORE, JSON.stringify(watchList().filter((k) => k !== key)));
  renderWatch();
}

function renderWatch() {
  const box = document.getElementById("watch");
  const list = watchList();
  box.replaceChildren();
  if (!list.length) {
    box.append(el("p", {class: "hint"}, "Add items with “watch” in their detail view."));
  }
  for (const key of list) {
    const i = key.indexOf(":");
    const kind = key.slice(0, i), name = key.slice(i + 1);
    box.append(el("div", {class: "row", "data-item": key},
                  el("span", {class: "name", onclick: () => openDetail(kind, name)}, `${kind} ${name}`),
                  valueCell(key, values.get(key)),
                  el("button", {type: "button", onclick: (ev) => { ev.stopPropagation(); removeWatch(key); }},
                     "remove")));
  }
  sendWatch();
}

// ------------------------------------------------------------ halcmd

async function runCommand(ev) {
  ev.preventDefault();
  const line = document.getElementById("cmdline").value;
  if (!line.trim()) return;
  const out = document.getElementById("cmdout");
  const data = await post("/api/command", {line});
  if (!data) return;
  out.textContent = (data.output || "") + (data.error || "");
  out.className = data.ok ? "" : "error";
  if (data.ok) loadTree();
}

document.addEventListener("DOMContentLoaded", () => {
  document.getElementById("search").addEventListener("input", renderTree);
  document.getElementById("cmdform").addEventListener("submit", runCommand);
  loadTree();
  connect();
});
