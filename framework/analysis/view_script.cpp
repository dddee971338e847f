// The style sheet and the script of gem view's page (view_page.cpp embeds both inline): a canvas
// player of the packed frames (view_pack.hpp), the run's time series under it, and the summary.
#include "framework/analysis/view_script.hpp"

namespace gem {

std::string_view viewStyle() {
  return R"CSS(
html, body { margin: 0; overflow-x: hidden; background: #f3f4f6; color: #1f2933; font: 13px/1.4 "DejaVu Sans", sans-serif; }
header { padding: 6px 12px; background: #1f2933; color: #f3f4f6; }
header h1 { font-size: 15px; margin: 0 0 2px 0; font-weight: 600; }
header .facts span { margin-right: 16px; white-space: nowrap; }
header .facts b { color: #ffe066; font-weight: 600; }
#bar { display: flex; flex-wrap: wrap; align-items: center; gap: 6px; padding: 4px 12px; background: #e4e7eb; }
#bar button { min-width: 32px; }
#seek { flex: 1 1 200px; }
#clock { font-variant-numeric: tabular-nums; min-width: 170px; }
#legend { display: flex; align-items: center; gap: 6px; padding: 2px 12px; min-height: 20px; }
#legend canvas { border: 1px solid #9aa5b1; }
#scale-lo, #scale-hi { white-space: nowrap; }
#view { display: block; cursor: grab; touch-action: none; }
#series { display: block; background: #ffffff; }
#tip { position: fixed; pointer-events: none; background: rgba(31, 41, 51, 0.92); color: #f3f4f6; padding: 4px 8px;
       border-radius: 3px; display: none; white-space: pre; font-size: 12px; }
.note { color: #7b8794; margin-left: 8px; }
)CSS";
}

std::string_view viewScript() {
  return R"JS(
"use strict";
// Any failure shows in the title, where a headless test (and a user's tab) can read it.
window.onerror = function (message, source, line) {
  document.title = "gem view: error " + message + " (line " + line + ")";
};
window.addEventListener("unhandledrejection", function (e) { document.title = "gem view: error " + e.reason; });

(function () {
  const D = JSON.parse(document.getElementById("gem-data").textContent);
  const kBackground = "#1b3a5c", kWall = "#8a8a8a", kVessel = "#d62828", kImpact = "#00e5ff";
  const kBuckets = 16;

  function bytes(b64) {
    if (Uint8Array.fromBase64) return Uint8Array.fromBase64(b64);  // native where the browser has it (Chromium 140+)
    const s = atob(b64), a = new Uint8Array(s.length);
    for (let i = 0; i < s.length; ++i) a[i] = s.charCodeAt(i);
    return a;
  }
  const f32 = (b) => new Float32Array(bytes(b).buffer);
  const f64 = (b) => new Float64Array(bytes(b).buffer);
  const u32 = (b) => new Uint32Array(bytes(b).buffer);

  // Shapes: decoded once. Frames: decoded when shown, a few kept (10^5 floes are 1.6 MB a frame).
  const S = D.shapes;
  const shape = { id: f64(S.id), kind: bytes(S.kind), piece: bytes(S.piece), thickness: f32(S.thickness), area: f32(S.area),
                  radius: f32(S.radius), start: u32(S.start), xy: f32(S.xy) };
  const lists = [];
  const frameCount = D.frames.time.length;
  const cache = new Map();
  function frameData(k) {
    let f = cache.get(k);
    if (f) return f;
    const l = D.frames.list[k];
    if (!lists[l]) lists[l] = u32(D.lists[l]);
    f = { time: D.frames.time[k], list: lists[l], poses: f32(D.frames.poses[k]) };
    if (cache.size > 6) cache.delete(cache.keys().next().value);
    cache.set(k, f);
    return f;
  }
  const kinds = ["floe", "vessel", "wall"];

  // Colour scales: a light ramp that stays visible on the dark water; ids get 16 distinct hues.
  const ramp = [[238, 244, 250], [158, 202, 225], [255, 224, 102], [255, 159, 28], [194, 24, 143]];
  function rampColour(u) {
    const x = Math.min(Math.max(u, 0), 1) * (ramp.length - 1), i = Math.min(Math.floor(x), ramp.length - 2), w = x - i;
    const c = ramp[i].map((v, j) => Math.round(v + (ramp[i + 1][j] - v) * w));
    return "rgb(" + c.join(",") + ")";
  }
  const rampColours = [];
  for (let b = 0; b < kBuckets; ++b) rampColours.push(rampColour((b + 0.5) / kBuckets));
  const idColours = [];
  for (let b = 0; b < kBuckets; ++b) idColours.push("hsl(" + Math.round((b * 360 * 7) / kBuckets) % 360 + ",70%," + (b % 2 ? 62 : 74) + "%)");
  // One thickness everywhere (the usual field) sits mid-scale; float rounding must not scatter it.
  const thicknessSpan = D.thickness[1] - D.thickness[0], thicknessUniform = thicknessSpan < 1e-6 * Math.max(1, D.thickness[1]);
  const thicknessBucket = (s) => thicknessUniform ? kBuckets >> 1 :
    Math.max(0, Math.min(kBuckets - 1, Math.floor(((shape.thickness[s] - D.thickness[0]) / thicknessSpan) * kBuckets)));
  const scales = {
    speed: { label: "speed", unit: "m/s", lo: 0, hi: D.speedScale, bucket: (s, sp) => Math.min(kBuckets - 1, Math.floor((sp / D.speedScale) * kBuckets)) | 0 },
    thickness: { label: "thickness", unit: "m", lo: D.thickness[0], hi: D.thickness[1],
                 bucket: thicknessBucket },
    id: { label: "id", bucket: (s) => ((shape.id[s] % kBuckets) + kBuckets) % kBuckets },
  };

  // Impacts sorted by time, found by binary search around each frame's time.
  const impacts = D.impacts ? { t: f32(D.impacts.t), x: f32(D.impacts.x), y: f32(D.impacts.y), fn: f32(D.impacts.fn) } : null;
  function lowerBound(a, v) {
    let lo = 0, hi = a.length;
    while (lo < hi) { const m = (lo + hi) >> 1; if (a[m] < v) lo = m + 1; else hi = m; }
    return lo;
  }

  const view = document.getElementById("view"), ctx = view.getContext("2d");
  const seriesCanvas = document.getElementById("series"), sctx = seriesCanvas.getContext("2d");
  const seek = document.getElementById("seek"), clock = document.getElementById("clock"), tip = document.getElementById("tip");
  const colourSelect = document.getElementById("colour"), fpsSelect = document.getElementById("fps");
  const playButton = document.getElementById("play");
  seek.max = String(frameCount - 1);

  let current = 0, playing = false, colourBy = "speed";
  let centreX = (D.bounds[0] + D.bounds[2]) / 2, centreY = (D.bounds[1] + D.bounds[3]) / 2, scale = 1;
  let cssWidth = 0, cssHeight = 0, dpr = 1;

  function fit() {
    const w = Math.max(D.bounds[2] - D.bounds[0], 1e-6), h = Math.max(D.bounds[3] - D.bounds[1], 1e-6);
    centreX = (D.bounds[0] + D.bounds[2]) / 2;
    centreY = (D.bounds[1] + D.bounds[3]) / 2;
    scale = 0.95 * Math.min(cssWidth / w, cssHeight / h);
  }
  function resize() {
    dpr = window.devicePixelRatio || 1;
    cssWidth = document.documentElement.clientWidth;
    const used = view.getBoundingClientRect().top + 3 * 64 + 8;
    cssHeight = Math.max(240, window.innerHeight - used);
    for (const [c, h] of [[view, cssHeight], [seriesCanvas, 3 * 64]]) {
      c.style.width = cssWidth + "px";
      c.style.height = h + "px";
      c.width = Math.round(cssWidth * dpr);
      c.height = Math.round(h * dpr);
    }
    drawSeriesBackground();
  }

  // One Path2D per colour bucket: 16 fills a frame, not one fillStyle change per floe.
  function draw() {
    const f = frameData(current);
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.fillStyle = kBackground;
    ctx.fillRect(0, 0, cssWidth, cssHeight);
    const paths = [];
    for (let b = 0; b < kBuckets; ++b) paths.push(new Path2D());
    const walls = new Path2D(), vessels = new Path2D(), pieces = new Path2D();
    const bucketOf = scales[colourBy].bucket;
    const halfW = cssWidth / 2, halfH = cssHeight / 2;
    const list = f.list, poses = f.poses;
    for (let i = 0; i < list.length; ++i) {
      const s = list[i], x = poses[4 * i], y = poses[4 * i + 1], a = poses[4 * i + 2];
      const sx = (x - centreX) * scale + halfW, sy = halfH - (y - centreY) * scale, r = shape.radius[s] * scale;
      if (sx + r < 0 || sy + r < 0 || sx - r > cssWidth || sy - r > cssHeight) continue;
      const kind = shape.kind[s];
      const path = kind === 2 ? walls : kind === 1 ? vessels : paths[bucketOf(s, poses[4 * i + 3])];
      if (r < 1.5) {  // a floe of a pixel or two: a square of its size is what the eye sees, at a sixth of the cost
        const side = Math.max(1.2, 1.6 * r);
        path.rect(sx - side / 2, sy - side / 2, side, side);
        continue;
      }
      const c = Math.cos(a) * scale, sn = Math.sin(a) * scale, from = shape.start[s], to = shape.start[s + 1];
      const add = (p) => {
        for (let k = from; k < to; ++k) {
          const lx = shape.xy[2 * k], ly = shape.xy[2 * k + 1];
          const px = sx + c * lx - sn * ly, py = sy - (sn * lx + c * ly);
          if (k === from) p.moveTo(px, py); else p.lineTo(px, py);
        }
        p.closePath();
      };
      add(path);
      if (shape.piece[s] && kind === 0) add(pieces);
    }
    ctx.fillStyle = kWall;
    ctx.fill(walls);
    const colours = colourBy === "id" ? idColours : rampColours;
    for (let b = 0; b < kBuckets; ++b) { ctx.fillStyle = colours[b]; ctx.fill(paths[b]); }
    ctx.lineWidth = 1.2;
    ctx.strokeStyle = "#101820";
    ctx.stroke(pieces);
    ctx.fillStyle = kVessel;
    ctx.fill(vessels);
    ctx.strokeStyle = "#ffffff";
    ctx.lineWidth = 1.5;
    ctx.stroke(vessels);
    drawImpacts(f);
    ctx.fillStyle = "#f3f4f6";
    ctx.font = "12px 'DejaVu Sans', sans-serif";
    ctx.fillText("t = " + f.time.toFixed(2) + " s   frame " + current + " / " + (frameCount - 1) + "   " + list.length + " bodies", 8, 16);
    seek.value = String(current);
    clock.textContent = "t = " + f.time.toFixed(2) + " s, frame " + current + " of " + (frameCount - 1) +
      (D.every > 1 ? " (frames.ice frame " + D.frames.source[current] + ")" : "");
    drawSeries(f.time);
    document.title = "gem view: frame " + current + " drawn";
  }

  // The impacts logged since the previous frame (or within one frame interval of this one).
  function drawImpacts(f) {
    if (!impacts || !impacts.t.length) return;
    const previous = current > 0 ? D.frames.time[current - 1] : f.time - (frameCount > 1 ? D.frames.time[1] - D.frames.time[0] : 1);
    const from = lowerBound(impacts.t, previous + 1e-9), to = lowerBound(impacts.t, f.time + 1e-9);
    ctx.strokeStyle = kImpact;
    ctx.lineWidth = 2;
    ctx.beginPath();
    for (let k = from; k < to; ++k) {
      const sx = (impacts.x[k] - centreX) * scale + cssWidth / 2, sy = cssHeight / 2 - (impacts.y[k] - centreY) * scale;
      ctx.moveTo(sx + 5, sy);
      ctx.arc(sx, sy, 5, 0, 2 * Math.PI);
    }
    ctx.stroke();
  }

  // The time series: three bands drawn once per size into an offscreen canvas; a frame adds its cursor.
  const kSeries = [["ship_speed", "ship speed", "m/s", "#1f77b4"], ["net_thrust", "net thrust", "N", "#2ca02c"],
                   ["ice_force_x", "ice force x", "N", "#d62728"]];
  const series = D.series ? { t: f32(D.series.t) } : null;
  if (series) for (const [key] of kSeries) series[key] = f32(D.series[key]);
  const seriesLayer = document.createElement("canvas");
  let tMin = 0, tMax = 1;
  function timeToX(t) { return 60 + ((t - tMin) / Math.max(tMax - tMin, 1e-9)) * (cssWidth - 70); }
  function drawSeriesBackground() {
    seriesLayer.width = seriesCanvas.width;
    seriesLayer.height = seriesCanvas.height;
    const g = seriesLayer.getContext("2d");
    g.setTransform(dpr, 0, 0, dpr, 0, 0);
    g.fillStyle = "#ffffff";
    g.fillRect(0, 0, cssWidth, 3 * 64);
    g.font = "11px 'DejaVu Sans', sans-serif";
    if (!series || !series.t.length) {
      g.fillStyle = "#7b8794";
      g.fillText("no timeseries.csv in the run folder", 12, 20);
      return;
    }
    tMin = Math.min(series.t[0], D.frames.time[0]);
    tMax = Math.max(series.t[series.t.length - 1], D.frames.time[frameCount - 1]);
    kSeries.forEach(([key, label, unit, colour], band) => {
      const v = series[key], top = band * 64 + 6, height = 52;
      let lo = Infinity, hi = -Infinity;
      for (let i = 0; i < v.length; ++i) if (Number.isFinite(v[i])) { lo = Math.min(lo, v[i]); hi = Math.max(hi, v[i]); }
      g.fillStyle = "#52606d";
      g.fillText(label + " (" + unit + ")", 64, top + 10);
      if (!(lo <= hi)) { g.fillText("no values", 200, top + 10); return; }
      if (hi === lo) { hi += 1; lo -= 1; }
      g.fillText(hi.toPrecision(3), 4, top + 10);
      g.fillText(lo.toPrecision(3), 4, top + height);
      g.strokeStyle = "#e4e7eb";
      g.strokeRect(60, top, cssWidth - 70, height);
      g.strokeStyle = colour;
      g.lineWidth = 1;
      g.beginPath();
      let pen = false;
      for (let i = 0; i < v.length; ++i) {
        if (!Number.isFinite(v[i])) { pen = false; continue; }
        const x = timeToX(series.t[i]), y = top + height - ((v[i] - lo) / (hi - lo)) * height;
        if (pen) g.lineTo(x, y); else g.moveTo(x, y);
        pen = true;
      }
      g.stroke();
    });
  }
  function drawSeries(time) {
    sctx.setTransform(1, 0, 0, 1, 0, 0);
    sctx.drawImage(seriesLayer, 0, 0);
    if (!series || !series.t.length) return;
    sctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    sctx.strokeStyle = "#1f2933";
    sctx.lineWidth = 1;
    sctx.beginPath();
    sctx.moveTo(timeToX(time), 0);
    sctx.lineTo(timeToX(time), 3 * 64);
    sctx.stroke();
  }

  // The colour bar (speed, thickness) or a note (id), beside the kind swatches.
  function drawLegend() {
    const bar = document.getElementById("bar-scale"), g = bar.getContext("2d"), sc = scales[colourBy];
    const colours = colourBy === "id" ? idColours : rampColours;
    for (let b = 0; b < kBuckets; ++b) { g.fillStyle = colours[b]; g.fillRect((b * bar.width) / kBuckets, 0, bar.width / kBuckets + 1, bar.height); }
    document.getElementById("scale-lo").textContent = sc.unit ? sc.lo.toPrecision(3) + " " + sc.unit : "";
    document.getElementById("scale-hi").textContent = sc.unit ? sc.hi.toPrecision(3) + " " + sc.unit + (colourBy === "speed" ? " and above" : "") : "id mod 16";
  }

  function show(k) {
    current = Math.min(Math.max(0, k | 0), frameCount - 1);
    draw();
  }
  function setPlaying(on) {
    const was = playing;
    playing = on && frameCount > 1;
    playButton.textContent = playing ? "pause" : "play";
    // One animation loop at a time: a second would double the speed.
    if (playing && !was) { lastTick = performance.now(); requestAnimationFrame(tick); }
  }
  let lastTick = 0;
  function tick(now) {
    if (!playing) return;
    if (now - lastTick >= 1000 / Number(fpsSelect.value)) {
      lastTick = now;
      if (current + 1 >= frameCount) { setPlaying(false); return; }
      show(current + 1);
    }
    requestAnimationFrame(tick);
  }

  playButton.onclick = () => { if (!playing && current + 1 >= frameCount) show(0); setPlaying(!playing); };
  document.getElementById("back").onclick = () => { setPlaying(false); show(current - 1); };
  document.getElementById("forward").onclick = () => { setPlaying(false); show(current + 1); };
  document.getElementById("fit").onclick = () => { fit(); draw(); };
  seek.oninput = () => { setPlaying(false); show(Number(seek.value)); };
  colourSelect.onchange = () => { colourBy = colourSelect.value; drawLegend(); draw(); };
  window.addEventListener("keydown", (e) => {
    // A focused slider or list takes its own keys, and space clicks a focused button itself:
    // handling those here too would step or toggle twice.
    if (e.target.tagName === "SELECT" || e.target.tagName === "INPUT" || (e.target.tagName === "BUTTON" && e.key === " ")) return;
    if (e.key === " ") { e.preventDefault(); playButton.onclick(); }
    else if (e.key === "ArrowLeft") { setPlaying(false); show(current - 1); }
    else if (e.key === "ArrowRight") { setPlaying(false); show(current + 1); }
  });

  // Zoom about the pointer (wheel), pan by dragging, hover for a body's facts.
  view.addEventListener("wheel", (e) => {
    e.preventDefault();
    const r = view.getBoundingClientRect(), mx = e.clientX - r.left, my = e.clientY - r.top;
    const wx = centreX + (mx - cssWidth / 2) / scale, wy = centreY - (my - cssHeight / 2) / scale;
    scale *= Math.exp(-e.deltaY * 0.0015);
    centreX = wx - (mx - cssWidth / 2) / scale;
    centreY = wy + (my - cssHeight / 2) / scale;
    draw();
  }, { passive: false });
  let drag = null;
  view.addEventListener("pointerdown", (e) => { drag = { x: e.clientX, y: e.clientY, cx: centreX, cy: centreY }; view.setPointerCapture(e.pointerId); view.style.cursor = "grabbing"; });
  view.addEventListener("pointerup", () => { drag = null; view.style.cursor = "grab"; });
  view.addEventListener("pointerleave", () => { tip.style.display = "none"; });
  view.addEventListener("pointermove", (e) => {
    if (drag) {
      centreX = drag.cx - (e.clientX - drag.x) / scale;
      centreY = drag.cy + (e.clientY - drag.y) / scale;
      draw();
      return;
    }
    const r = view.getBoundingClientRect();
    const wx = centreX + (e.clientX - r.left - cssWidth / 2) / scale, wy = centreY - (e.clientY - r.top - cssHeight / 2) / scale;
    showFacts(wx, wy, e.clientX, e.clientY);
  });
  // The tip beside the pointer (clientX, clientY) with the facts of the body at world point (wx, wy).
  function showFacts(wx, wy, clientX, clientY) {
    const hit = bodyAt(wx, wy);
    if (hit < 0) { tip.style.display = "none"; return; }
    const f = frameData(current), s = f.list[hit], kind = shape.kind[s];
    const mass = shape.area[s] * shape.thickness[s] * D.rhoIce;
    tip.textContent = kinds[kind] + " " + shape.id[s] + (shape.piece[s] ? " (broken piece)" : "") +
      (kind === 0 ? "\nmass " + (mass / 1000).toPrecision(4) + " t\nthickness " + shape.thickness[s].toPrecision(3) + " m" : "") +
      "\nspeed " + f.poses[4 * hit + 3].toPrecision(3) + " m/s";
    tip.style.left = clientX + 14 + "px";
    tip.style.top = clientY + 14 + "px";
    tip.style.display = "block";
  }
  // The body under a world point: bounding circle first, then the polygon in the shape's frame.
  function bodyAt(wx, wy) {
    const f = frameData(current), list = f.list, poses = f.poses;
    for (let i = list.length - 1; i >= 0; --i) {
      const s = list[i], dx = wx - poses[4 * i], dy = wy - poses[4 * i + 1], r = shape.radius[s];
      if (dx * dx + dy * dy > r * r) continue;
      const c = Math.cos(-poses[4 * i + 2]), sn = Math.sin(-poses[4 * i + 2]), lx = c * dx - sn * dy, ly = sn * dx + c * dy;
      let inside = false;
      for (let k = shape.start[s], j = shape.start[s + 1] - 1; k < shape.start[s + 1]; j = k++) {
        const xi = shape.xy[2 * k], yi = shape.xy[2 * k + 1], xj = shape.xy[2 * j], yj = shape.xy[2 * j + 1];
        if (yi > ly !== yj > ly && lx < ((xj - xi) * (ly - yi)) / (yj - yi) + xi) inside = !inside;
      }
      if (inside) return i;
    }
    return -1;
  }

  // #frame=K (negative: from the end) opens paused at K, with #hover=X,Y the facts of the body at
  // world point X,Y; #color=speed|thickness|id; #fps=N; #play=0 keeps a page without frame paused.
  function applyHash() {
    const p = new URLSearchParams(location.hash.slice(1));
    const colour = p.get("color") || p.get("colour");
    if (colour && scales[colour]) { colourBy = colour; colourSelect.value = colour; }
    if (p.get("fps")) fpsSelect.value = p.get("fps");
    drawLegend();
    if (p.has("frame")) {
      const k = p.get("frame") === "last" ? frameCount - 1 : Number(p.get("frame"));
      setPlaying(false);
      show(k < 0 ? frameCount + k : k);
      // hover=X,Y (world, m): the facts of the body there, as if the pointer were on it.
      const at = (p.get("hover") || "").split(",").map(Number);
      if (at.length === 2 && at.every(Number.isFinite)) {
        const r = view.getBoundingClientRect();
        showFacts(at[0], at[1], r.left + (at[0] - centreX) * scale + cssWidth / 2, r.top + cssHeight / 2 - (at[1] - centreY) * scale);
      }
    } else {
      show(current);
      if (p.get("play") !== "0") setPlaying(true);
    }
  }
  window.addEventListener("hashchange", applyHash);
  window.addEventListener("resize", () => { resize(); draw(); });
  resize();
  fit();
  applyHash();
})();
)JS";
}

}  // namespace gem
