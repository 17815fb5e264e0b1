// The 3-D replay page's player (ballenv.viewer3d inlines it, with three.js and the data).
// Data: the JSON in #data (arrays as base64 little-endian float32 / uint32); SI units.
import * as THREE from "three";

const D = JSON.parse(document.getElementById("data").textContent);
function bytes(s) { const b = atob(s); const u = new Uint8Array(b.length); for (let i = 0; i < b.length; i++) u[i] = b.charCodeAt(i); return u.buffer; }
const T = new Float32Array(bytes(D.t)), X = new Float32Array(bytes(D.x)), P = new Float32Array(bytes(D.p));
const TRI = new Uint32Array(bytes(D.triangles));
const nF = D.nFrames, nS = D.nShells, nV = D.nVertices, per = nS * nV * 3;
const status = document.getElementById("status"), scrub = document.getElementById("scrub");
document.getElementById("info").textContent = D.info;
scrub.max = nF - 1;

// the colour map of gauge pressure (low to high) and its range (Pa)
const STOPS = D.colormap.map(c => new THREE.Color(c));
let pmin = Infinity, pmax = -Infinity;
for (const v of P) { pmin = Math.min(pmin, v); pmax = Math.max(pmax, v); }
if (pmax - pmin < 1) { pmax += 1; pmin -= 1; }
function pressureColour(p, out) {
  const s = Math.min(1, Math.max(0, (p - pmin) / (pmax - pmin))) * (STOPS.length - 1);
  const i = Math.min(STOPS.length - 2, Math.floor(s));
  return out.copy(STOPS[i]).lerp(STOPS[i + 1], s - i);
}
document.getElementById("legend-bar").style.background = "linear-gradient(to right," + D.colormap.join(",") + ")";
document.getElementById("legend-lo").textContent = (pmin / 1e3).toFixed(1) + " kPa";
document.getElementById("legend-hi").textContent = (pmax / 1e3).toFixed(1) + " kPa";

// the bounds of every vertex over the records: the camera's target and distance
const lo = new THREE.Vector3(Infinity, Infinity, Infinity), hi = new THREE.Vector3(-Infinity, -Infinity, -Infinity);
for (let i = 0; i < X.length; i += 3) {
  lo.x = Math.min(lo.x, X[i]); lo.y = Math.min(lo.y, X[i + 1]); lo.z = Math.min(lo.z, X[i + 2]);
  hi.x = Math.max(hi.x, X[i]); hi.y = Math.max(hi.y, X[i + 1]); hi.z = Math.max(hi.z, X[i + 2]);
}
const centre = lo.clone().add(hi).multiplyScalar(0.5);
const R = Math.max(...D.radius);
const extent = Math.max(hi.clone().sub(lo).length(), 4 * R);
const up = new THREE.Vector3(...D.up);

const cv = document.getElementById("scene");
const renderer = new THREE.WebGLRenderer({ canvas: cv, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
renderer.setSize(cv.width, cv.height, false);
const scene = new THREE.Scene();
scene.background = new THREE.Color(D.background);
const camera = new THREE.PerspectiveCamera(40, cv.width / cv.height, extent * 1e-2, extent * 50);
camera.up.copy(up);
const side = Math.abs(up.x) < 0.9 ? new THREE.Vector3(1, 0, 0) : new THREE.Vector3(0, 1, 0);
const away = new THREE.Vector3().crossVectors(up, side).normalize();
camera.position.copy(centre).addScaledVector(away, -1.5 * extent).addScaledVector(side, 0.4 * extent).addScaledVector(up, 0.8 * extent);
const controls = new THREE.OrbitControls(camera, cv);
controls.target.copy(centre);
controls.update();
scene.add(new THREE.HemisphereLight(0xffffff, 0x666655, 1.6));
// a light from above that casts the balls' shadows on the grounds (a cue of height)
const sun = new THREE.DirectionalLight(0xffffff, 1.8);
sun.position.copy(centre).addScaledVector(up, 2 * extent).addScaledVector(away, -0.5 * extent).addScaledVector(side, 0.3 * extent);
sun.target.position.copy(centre);
sun.castShadow = true;
sun.shadow.mapSize.set(2048, 2048);
Object.assign(sun.shadow.camera, { left: -1.5 * extent, right: 1.5 * extent, top: 1.5 * extent, bottom: -1.5 * extent, near: 0.01 * extent, far: 5 * extent });
renderer.shadowMap.enabled = true;
scene.add(sun, sun.target);

// a quaternion turning +y (three.js's plane and cylinder axis after the rotations below) to n
function turnYTo(n) { return new THREE.Quaternion().setFromUnitVectors(new THREE.Vector3(0, 1, 0), new THREE.Vector3(...n).normalize()); }
const size = 8 * extent;
// the grounds' grid: a texture of one cell (lines at its edges) repeated every gridStep m
function gridTexture() {
  const c = document.createElement("canvas"); c.width = c.height = 128;
  const g = c.getContext("2d");
  g.fillStyle = D.ground; g.fillRect(0, 0, 128, 128);
  g.strokeStyle = D.gridLine; g.lineWidth = 3; g.strokeRect(0, 0, 128, 128);
  const tex = new THREE.CanvasTexture(c);
  tex.wrapS = tex.wrapT = THREE.RepeatWrapping;
  tex.repeat.set(size / D.gridStep, size / D.gridStep);
  tex.anisotropy = renderer.capabilities.getMaxAnisotropy();
  tex.colorSpace = THREE.SRGBColorSpace;
  return tex;
}
for (const g of D.grounds) {
  const plane = new THREE.Mesh(new THREE.PlaneGeometry(size, size).rotateX(-Math.PI / 2),
    new THREE.MeshStandardMaterial({ map: gridTexture(), roughness: 0.95, side: THREE.DoubleSide }));
  plane.receiveShadow = true;
  plane.quaternion.copy(turnYTo(g.normal));
  const n = new THREE.Vector3(...g.normal);
  plane.position.copy(centre).addScaledVector(n, g.height - n.dot(centre));
  scene.add(plane);
}
for (const d of D.drums) {
  const drum = new THREE.Mesh(new THREE.CylinderGeometry(d.radius, d.radius, size / 4, 64, 1, true),
    new THREE.MeshStandardMaterial({ color: D.ground, roughness: 0.9, side: THREE.DoubleSide, transparent: true, opacity: 0.35 }));
  drum.quaternion.copy(turnYTo(d.axis));
  drum.position.set(...d.centre);
  scene.add(drum);
}

// one mesh per shell: positions and colours rewritten each frame
const shells = [];
for (let s = 0; s < nS; s++) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute("position", new THREE.BufferAttribute(new Float32Array(nV * 3), 3));
  geometry.setAttribute("color", new THREE.BufferAttribute(new Float32Array(nV * 3), 3));
  geometry.setIndex(new THREE.BufferAttribute(TRI, 1));
  const mesh = new THREE.Mesh(geometry, new THREE.MeshStandardMaterial({ vertexColors: true, roughness: 0.55, metalness: 0.0 }));
  mesh.castShadow = true;
  scene.add(mesh);
  shells.push(mesh);
}
const follow = document.getElementById("follow");
follow.checked = extent > 12 * R;
const colour = new THREE.Color();
let frame = 0;
function showShells(k) {
  const mid = new THREE.Vector3();
  for (let s = 0; s < nS; s++) {
    const g = shells[s].geometry, pos = g.attributes.position.array, col = g.attributes.color.array;
    pos.set(X.subarray(k * per + s * nV * 3, k * per + (s + 1) * nV * 3));
    pressureColour(P[k * nS + s], colour);
    for (let i = 0; i < nV; i++) { col[3 * i] = colour.r; col[3 * i + 1] = colour.g; col[3 * i + 2] = colour.b; mid.x += pos[3 * i]; mid.y += pos[3 * i + 1]; mid.z += pos[3 * i + 2]; }
    g.attributes.position.needsUpdate = true; g.attributes.color.needsUpdate = true;
    g.computeVertexNormals(); g.computeBoundingSphere();
  }
  return mid.multiplyScalar(1 / (nS * nV));
}
function draw(k) {
  frame = k;
  const mid = showShells(k);
  if (follow.checked) { camera.position.add(mid.clone().sub(controls.target)); controls.target.copy(mid); controls.update(); }
  renderer.render(scene, camera);
  const ps = []; for (let s = 0; s < nS; s++) ps.push((P[k * nS + s] / 1e3).toFixed(1));
  document.getElementById("readout").textContent = "t = " + T[k].toFixed(4) + " s   p = " + ps.join(", ") + " kPa";
  scrub.value = k;
  status.dataset.frame = k; status.dataset.t = T[k];
  status.textContent = "frame " + k + "/" + (nF - 1) + "  t = " + T[k].toFixed(4) + " s";
  drawPlot(k);
}
controls.addEventListener("change", () => renderer.render(scene, camera));

// gauge pressure over time, a cursor at the shown record (2-D canvas)
const pv = document.getElementById("plot"), pctx = pv.getContext("2d");
function tx(t) { return 50 + (pv.width - 60) * (t - T[0]) / Math.max(T[nF - 1] - T[0], 1e-12); }
function py(p) { return pv.height - 20 - (pv.height - 35) * (p - pmin) / (pmax - pmin); }
function drawPlot(k) {
  pctx.fillStyle = "#fff"; pctx.fillRect(0, 0, pv.width, pv.height);
  pctx.strokeStyle = "#999"; pctx.strokeRect(50, 15, pv.width - 60, pv.height - 35);
  for (let s = 0; s < nS; s++) {
    pctx.strokeStyle = D.lines[s % D.lines.length]; pctx.lineWidth = 1.2; pctx.beginPath();
    for (let i = 0; i < nF; i++) { const a = tx(T[i]), b = py(P[i * nS + s]); i ? pctx.lineTo(a, b) : pctx.moveTo(a, b); }
    pctx.stroke();
  }
  pctx.strokeStyle = "#000"; pctx.beginPath(); pctx.moveTo(tx(T[k]), 15); pctx.lineTo(tx(T[k]), pv.height - 20); pctx.stroke();
  pctx.fillStyle = "#222"; pctx.font = "11px sans-serif";
  pctx.fillText((pmax / 1e3).toFixed(1) + " kPa", 2, 20); pctx.fillText((pmin / 1e3).toFixed(1) + " kPa", 2, pv.height - 20);
  pctx.fillText("gauge pressure over time (" + T[0].toFixed(2) + " - " + T[nF - 1].toFixed(2) + " s)", 60, pv.height - 5);
}

// playback at speed x real time, following the recorded times
let playing = false, simTime = T[0], speed = 0.25, last = null;
function seek(t) { let a = 0, b = nF - 1; while (a < b) { const c = (a + b + 1) >> 1; if (T[c] <= t) a = c; else b = c - 1; } return a; }
function tick(now) {
  if (!playing) { last = null; return; }
  if (last !== null) { simTime += speed * (now - last) / 1000; if (simTime > T[nF - 1]) simTime = T[0]; draw(seek(simTime)); }
  last = now; requestAnimationFrame(tick);
}
const btn = document.getElementById("play");
function play() { if (!playing) { playing = true; btn.textContent = "pause"; simTime = T[frame]; requestAnimationFrame(tick); } }
function pause() { playing = false; btn.textContent = "play"; }
function setFrame(k) { draw(Math.max(0, Math.min(nF - 1, k | 0))); }
btn.onclick = () => playing ? pause() : play();
scrub.oninput = () => { pause(); setFrame(+scrub.value); };
document.getElementById("speed").onchange = e => { speed = +e.target.value; };
document.getElementById("back").onclick = () => { pause(); setFrame(frame - 1); };
document.getElementById("fwd").onclick = () => { pause(); setFrame(frame + 1); };
follow.onchange = () => draw(frame);
pv.onclick = e => { pause(); const r = pv.getBoundingClientRect(); draw(seek(T[0] + (e.clientX - r.left - 50) / (pv.width - 60) * (T[nF - 1] - T[0]))); };
document.addEventListener("keydown", e => {
  if (e.target && e.target.tagName === "SELECT") return;
  if (e.key === " ") { e.preventDefault(); playing ? pause() : play(); }
  else if (e.key === "ArrowRight") { pause(); setFrame(frame + 1); }
  else if (e.key === "ArrowLeft") { pause(); setFrame(frame - 1); }
});
window.ballViewer = { setFrame, play, pause, get frame() { return frame; }, nFrames: nF };
const h = /frame=(\d+)/.exec(location.hash);
setFrame(h ? +h[1] : 0);
