// ExplainDrive passenger page: draws what the server streams over /ws, sends
// passenger input over the JSON API. Plain JS, no build step, no network besides this server.
"use strict";

const COLOURS = {
  fast: "rgba(217, 72, 59, 0.22)",
  comfort: "rgba(47, 127, 209, 0.22)",
  stop: "rgba(17, 24, 39, 0.22)",
  signal: { red: "#e11d1d", yellow: "#facc15", green: "#22c55e", off: "#4b5563" },
};
const KMH = 3.6; // [km/h per m/s]
const VIEW_SCALE = 3.2; // [px per m] on the road view
const MAX_RECORD_MS = 8000; // a request is a sentence or two

const $ = (id) => document.getElementById(id);
const ui = {
  status: $("status"), traffic: $("traffic"), seed: $("seed"), start: $("start"),
  pause: $("pause"), reset: $("reset"), speed: $("speed"), limit: $("limit"),
  command: $("command"), clock: $("clock"), road: $("road"), chart: $("chart"),
  sayForm: $("say-form"), sayInput: $("say-input"), record: $("record"),
  question: $("question"), questionBox: $("question-box"), yes: $("yes"), no: $("no"),
  message: $("message"), log: $("log"), explanations: $("explanations"),
  thinking: $("thinking"), models: $("models"),
};

const view = {
  scene: null, status: null, frame: null, history: [], explanations: [], log: [], ride: 0,
  centre: null,
};

// ------------------------------------------------------------------ server I/O
async function api(path, body) {
  const init = { method: "POST" };
  if (body instanceof FormData) {
    init.body = body;
  } else if (body !== undefined) {
    init.headers = { "Content-Type": "application/json" };
    init.body = JSON.stringify(body);
  }
  const res = await fetch(path, init);
  let data = null;
  try { data = await res.json(); } catch (_) { data = null; }
  if (!res.ok) {
    throw new Error(describeError(data) || `${res.status} ${res.statusText}`);
  }
  return data;
}

function describeError(data) {
  if (!data || data.detail === undefined) return null;
  if (typeof data.detail === "string") return data.detail;
  return data.detail.map((d) => `${(d.loc || []).slice(1).join(".")}: ${d.msg}`).join("; ");
}

function say(message, ok = false) {
  ui.message.textContent = message;
  ui.message.style.color = ok ? "#15803d" : "#b91c1c";
}

function connect() {
  const proto = location.protocol === "https:" ? "wss" : "ws";
  const ws = new WebSocket(`${proto}://${location.host}/ws`);
  ws.onmessage = (ev) => receive(JSON.parse(ev.data));
  ws.onclose = () => {
    ui.status.textContent = "disconnected";
    setTimeout(connect, 1000);
  };
}

function receive(msg) {
  if (msg.type === "snapshot") {
    view.history = msg.history;
    view.explanations = msg.explanations;
    view.log = msg.log;
    view.frame = msg.frame;
    view.ride = msg.status.ride;
    setStatus(msg.status);
    renderExplanations(true);
    renderLog(true);
  } else if (msg.type === "status") {
    if (msg.ride !== view.ride || msg.state === "idle") clearRide(msg.ride);
    setStatus(msg);
  } else if (msg.type === "frame") {
    if (msg.ride !== view.ride) clearRide(msg.ride);
    const last = view.history[view.history.length - 1];
    if (last && msg.t <= last.t) return; // already in the snapshot
    view.frame = msg;
    view.history.push({ t: msg.t, speed_mps: msg.speed_mps, limit_mps: msg.limit_mps, command: msg.command });
    view.explanations.push(...msg.explanations);
    view.log.push(...msg.passenger);
    if (msg.explanations.length) renderExplanations(false, msg.explanations);
    if (msg.passenger.length) renderLog(false, msg.passenger);
    setQuestion(msg.question);
    setThinking(msg.thinking || [], msg.models);
  }
  renderGauges();
  draw();
}

// While a language model works the car shows it is thinking; the counts say, per module,
// how often the model's own answer was used, fell back, was vetoed or came too late.
const MODULE_NAMES = { interpret: "understanding", decide: "deciding", explain: "explaining" };
function setThinking(modules, models) {
  ui.thinking.hidden = modules.length === 0;
  ui.thinking.textContent = modules.length
    ? `thinking… (${modules.map((m) => MODULE_NAMES[m] || m).join(", ")})` : "";
  if (!models) return;
  ui.models.textContent = Object.entries(models).map(([m, c]) =>
    `${MODULE_NAMES[m] || m}: used ${c.used}, fell back ${c.fallback}, vetoed ${c.vetoed}, late ${c.late}`
  ).join(" · ");
}

function clearRide(ride) {
  view.ride = ride;
  view.history = []; view.explanations = []; view.log = []; view.frame = null;
  renderExplanations(true);
  renderLog(true);
}

// ------------------------------------------------------------------ panels
function setStatus(status) {
  view.status = status;
  const s = status.state;
  let text = s;
  if (status.settings) text += ` · traffic ${status.settings.traffic_level} · seed ${status.settings.seed}`;
  if (status.error) text += ` · ${status.error}`;
  ui.status.textContent = text;
  ui.status.className = `status ${s}`;
  ui.start.disabled = s === "running" || s === "paused" || s === "starting";
  ui.pause.disabled = !(s === "running" || s === "paused");
  ui.pause.textContent = s === "paused" ? "Resume" : "Pause";
  setQuestion(status.question);
}

function setQuestion(question) {
  const asking = Boolean(question);
  ui.question.textContent = asking ? question : "No question.";
  ui.questionBox.classList.toggle("asking", asking);
  ui.yes.disabled = !asking;
  ui.no.disabled = !asking;
}

function renderGauges() {
  const f = view.frame;
  ui.speed.textContent = f ? (f.speed_mps * KMH).toFixed(1) : "0.0";
  ui.limit.textContent = f ? Math.round(f.limit_mps * KMH).toString() : "–";
  const cmd = f ? f.command : (view.status && view.status.settings ? view.status.settings.command : null);
  ui.command.textContent = cmd || "–";
  ui.command.className = `badge ${cmd || ""}`;
  ui.command.dataset.command = cmd || "";
  ui.clock.textContent = f ? Math.round(f.t).toString() : "0";
}

// What the car says to a line it interpreted: its question for a command (or for a STOP it
// asks about), a promise to explain for a "why?", the answer for a yes or no.
function describeReading(e) {
  if (e.intent || e.ask) return `Car: ${e.confirmation}`;
  if (e.reading === "why") return `Car: ${e.confirmation}`;
  if (e.reading === "yes" || e.reading === "no") return `You answered ${e.reading}.`;
  return "Car: I did not understand that.";
}

function describeEvent(e) {
  switch (e.type) {
    case "line": return e.text ? `You: “${e.text}”` : "You: (recording)";
    case "transcript": return e.text ? `Heard: “${e.text}”` : "Heard nothing";
    case "interpretation": return describeReading(e);
    case "confirmed": return `Command ${e.from} → ${e.to}`;
    case "cancelled": return `Cancelled; keeping ${e.kept_command}`;
    case "rephrase": return `Car: ${e.message}`;
    case "superseded": return "The earlier question was replaced.";
    case "late": return `The ${e.module} module was late; keeping ${e.kept_command}`;
    case "error": return `The ${e.module} module failed; keeping ${e.kept_command}`;
    case "answer_ignored": return "No question was pending.";
    default: return e.type;
  }
}

function renderLog(full, added) {
  if (full) ui.log.replaceChildren();
  for (const e of full ? view.log : added) {
    if (e.type === "interpretation" && e.intent === null && e.error) continue;
    const li = document.createElement("li");
    const t = document.createElement("span");
    t.className = "t";
    t.textContent = `${Math.round(e.t)} s`;
    li.append(t, describeEvent(e));
    li.dataset.type = e.type;
    ui.log.append(li);
  }
  ui.log.scrollTop = ui.log.scrollHeight;
}

function renderExplanations(full, added) {
  if (full) {
    ui.explanations.replaceChildren();
    if (!view.explanations.length) {
      const p = document.createElement("p");
      p.className = "empty";
      p.textContent = "Explanations appear here when the car's behaviour differs from your request.";
      ui.explanations.append(p);
      return;
    }
  } else {
    const empty = ui.explanations.querySelector(".empty");
    if (empty) empty.remove();
  }
  for (const x of full ? view.explanations : added) {
    const div = document.createElement("div");
    div.className = "bubble";
    div.dataset.testid = "bubble";
    const t = document.createElement("span");
    t.className = "t";
    t.textContent = `${Math.round(x.t)} s${x.factor ? ` · ${x.factor.replace(/_/g, " ")}` : ""}`;
    div.append(t, x.text);
    ui.explanations.prepend(div);
  }
}

// ------------------------------------------------------------------ drawing
function fitCanvas(canvas) {
  const ratio = window.devicePixelRatio || 1;
  const w = canvas.clientWidth, h = canvas.clientHeight;
  if (canvas.width !== Math.round(w * ratio) || canvas.height !== Math.round(h * ratio)) {
    canvas.width = Math.round(w * ratio);
    canvas.height = Math.round(h * ratio);
  }
  const ctx = canvas.getContext("2d");
  ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
  return { ctx, w, h };
}

function draw() {
  drawRoad();
  drawChart();
}

function drawRoad() {
  const { ctx, w, h } = fitCanvas(ui.road);
  ctx.fillStyle = "#7a9a6a";
  ctx.fillRect(0, 0, w, h);
  if (!view.scene) return;
  const f = view.frame;
  const ego = f && f.scene.ego;
  if (ego) view.centre = [ego.x, ego.y];
  if (!view.centre) {
    const b = view.scene.bounds;
    view.centre = [(b[0] + b[2]) / 2, (b[1] + b[3]) / 2];
  }
  const [cx, cy] = view.centre;
  const s = VIEW_SCALE;
  const X = (x) => w / 2 + (x - cx) * s;
  const Y = (y) => h / 2 - (y - cy) * s;
  const path = (shape) => {
    ctx.beginPath();
    shape.forEach(([x, y], i) => (i ? ctx.lineTo(X(x), Y(y)) : ctx.moveTo(X(x), Y(y))));
  };
  ctx.lineCap = "butt";
  ctx.lineJoin = "round";
  for (const kind of ["sidewalk", "internal", "road"]) {
    for (const lane of view.scene.lanes) {
      if (lane.kind !== kind) continue;
      path(lane.shape);
      ctx.strokeStyle = kind === "sidewalk" ? "#cfcfc8" : "#4b5058";
      ctx.lineWidth = lane.width * s;
      ctx.stroke();
    }
  }
  ctx.setLineDash([0.5 * s, 0.5 * s]); // zebra bars
  for (const c of view.scene.crossings) {
    path(c.shape);
    ctx.strokeStyle = "#f8f8f8";
    ctx.lineWidth = c.width * s;
    ctx.stroke();
  }
  ctx.setLineDash([]);
  if (f) {
    for (const sig of f.scene.signals) {
      ctx.beginPath();
      ctx.arc(X(sig.x), Y(sig.y), 1.4 * s, 0, 2 * Math.PI);
      ctx.fillStyle = COLOURS.signal[sig.colour] || COLOURS.signal.off;
      ctx.fill();
      ctx.lineWidth = 1.5;
      ctx.strokeStyle = "#111";
      ctx.stroke();
    }
    for (const p of f.scene.persons) {
      ctx.beginPath();
      ctx.arc(X(p.x), Y(p.y), 0.6 * s, 0, 2 * Math.PI);
      ctx.fillStyle = "#f97316";
      ctx.fill();
      ctx.strokeStyle = "#7c2d12";
      ctx.lineWidth = 1;
      ctx.stroke();
    }
    for (const v of f.scene.vehicles) drawVehicle(ctx, X(v.x), Y(v.y), v, "#e5e7eb", s);
    if (ego) drawVehicle(ctx, X(ego.x), Y(ego.y), ego, "#1f6feb", s);
  }
  // scale bar
  ctx.fillStyle = "#fff";
  ctx.fillRect(w - 20 - 20 * s, h - 18, 20 * s, 3);
  ctx.font = "12px system-ui, sans-serif";
  ctx.fillText("20 m", w - 20 - 20 * s, h - 24);
}

function drawVehicle(ctx, x, y, v, colour, s) {
  // SUMO positions are the front bumper; angle is clockwise from north.
  ctx.save();
  ctx.translate(x, y);
  ctx.rotate((v.angle * Math.PI) / 180);
  ctx.fillStyle = colour;
  ctx.strokeStyle = "#111";
  ctx.lineWidth = 1;
  ctx.fillRect((-v.width / 2) * s, 0, v.width * s, v.length * s);
  ctx.strokeRect((-v.width / 2) * s, 0, v.width * s, v.length * s);
  ctx.fillStyle = "rgba(0,0,0,0.45)"; // windscreen marks the front
  ctx.fillRect((-v.width / 2 + 0.25) * s, 0.9 * s, (v.width - 0.5) * s, 0.5 * s);
  ctx.restore();
}

function drawChart() {
  const { ctx, w, h } = fitCanvas(ui.chart);
  ctx.clearRect(0, 0, w, h);
  const pad = { l: 42, r: 10, t: 10, b: 26 };
  const hist = view.history;
  const tMax = Math.max(60, hist.length ? hist[hist.length - 1].t : 0);
  let vMax = 10;
  for (const p of hist) vMax = Math.max(vMax, p.speed_mps * KMH, p.limit_mps * KMH);
  vMax = Math.ceil((vMax + 5) / 10) * 10;
  const X = (t) => pad.l + (t / tMax) * (w - pad.l - pad.r);
  const Y = (v) => h - pad.b - (v / vMax) * (h - pad.t - pad.b);
  // command bands: each step covers the second before its time stamp
  for (const p of hist) {
    ctx.fillStyle = COLOURS[p.command] || COLOURS.stop;
    ctx.fillRect(X(p.t - 1), pad.t, X(p.t) - X(p.t - 1) + 0.5, h - pad.t - pad.b);
  }
  ctx.strokeStyle = "#d1d5db";
  ctx.fillStyle = "#6b7280";
  ctx.lineWidth = 1;
  ctx.font = "11px system-ui, sans-serif";
  for (let v = 0; v <= vMax; v += 10) {
    ctx.beginPath(); ctx.moveTo(pad.l, Y(v)); ctx.lineTo(w - pad.r, Y(v)); ctx.stroke();
    ctx.fillText(String(v), 8, Y(v) + 4);
  }
  const tStep = tMax > 300 ? 60 : tMax > 120 ? 30 : 10;
  for (let t = 0; t <= tMax; t += tStep) ctx.fillText(`${t}`, X(t) - 6, h - 8);
  ctx.fillText("km/h", pad.l + 4, pad.t + 10);
  ctx.fillText("s", w - pad.r - 8, h - 8);
  const line = (key, colour, dash) => {
    ctx.beginPath();
    hist.forEach((p, i) => (i ? ctx.lineTo(X(p.t), Y(p[key] * KMH)) : ctx.moveTo(X(p.t), Y(p[key] * KMH))));
    ctx.strokeStyle = colour;
    ctx.lineWidth = 2;
    ctx.setLineDash(dash);
    ctx.stroke();
    ctx.setLineDash([]);
  };
  if (hist.length) {
    line("limit_mps", "#b91c1c", [6, 4]);
    line("speed_mps", "#111827", []);
  }
  ctx.fillStyle = "#d97706";
  for (const x of view.explanations) {
    const px = X(x.t);
    ctx.beginPath();
    ctx.moveTo(px - 5, pad.t); ctx.lineTo(px + 5, pad.t); ctx.lineTo(px, pad.t + 8);
    ctx.fill();
  }
}

// ------------------------------------------------------------------ controls
ui.start.closest("form").addEventListener("submit", async (ev) => {
  ev.preventDefault();
  const seed = Number(ui.seed.value);
  try {
    say("Starting the ride…", true);
    await api("/api/ride/start", { traffic_level: Number(ui.traffic.value), seed });
    say("");
  } catch (err) { say(err.message); }
});

ui.pause.addEventListener("click", async () => {
  const resume = view.status && view.status.state === "paused";
  try { await api(resume ? "/api/ride/resume" : "/api/ride/pause"); } catch (err) { say(err.message); }
});

ui.reset.addEventListener("click", async () => {
  try { await api("/api/ride/reset"); say(""); } catch (err) { say(err.message); }
});

ui.sayForm.addEventListener("submit", async (ev) => {
  ev.preventDefault();
  const text = ui.sayInput.value.trim();
  if (!text) { say("Type a request first."); return; }
  try {
    await api("/api/ride/say", { text });
    ui.sayInput.value = "";
    say("");
  } catch (err) { say(err.message); }
});

for (const [button, yes] of [[ui.yes, true], [ui.no, false]]) {
  button.addEventListener("click", async () => {
    try {
      await api("/api/ride/answer", { yes });
      setQuestion(null);
    } catch (err) { say(err.message); }
  });
}

let recorder = null;
ui.record.addEventListener("click", async () => {
  if (recorder && recorder.state === "recording") { recorder.stop(); return; }
  if (!navigator.mediaDevices || !window.MediaRecorder) {
    say("This browser cannot record audio here (a microphone needs localhost or https).");
    return;
  }
  let stream;
  try {
    stream = await navigator.mediaDevices.getUserMedia({ audio: true });
  } catch (err) { say(`No microphone: ${err.message}`); return; }
  const chunks = [];
  recorder = new MediaRecorder(stream);
  recorder.ondataavailable = (e) => { if (e.data.size) chunks.push(e.data); };
  recorder.onstop = async () => {
    stream.getTracks().forEach((t) => t.stop());
    ui.record.classList.remove("recording");
    ui.record.textContent = "● Record";
    const type = (recorder.mimeType || "audio/webm").split(";")[0];
    const form = new FormData();
    form.append("file", new Blob(chunks, { type }), "utterance");
    try {
      say("Transcribing…", true);
      await api("/api/ride/audio", form);
      say("");
    } catch (err) { say(err.message); }
  };
  recorder.start();
  ui.record.classList.add("recording");
  ui.record.textContent = "■ Stop";
  setTimeout(() => { if (recorder && recorder.state === "recording") recorder.stop(); }, MAX_RECORD_MS);
});

window.addEventListener("resize", draw);

fetch("/api/scene")
  .then((r) => r.json())
  .then((scene) => { view.scene = scene; draw(); })
  .catch((err) => say(`Could not load the road: ${err.message}`));
connect();
