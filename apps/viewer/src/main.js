// The viewer page of `clothcd view`. Hash parameters: frame=N, colour=none|strain|contact
// (simulations), hit=K (detections), and test, which plays the page's own check: it plays a few
// frames or selects the first hit from the list, counts the cloth's pixels, and reports all of it
// as JSON in #clothcd-state (what tests read with a headless browser).
import { loadPageData } from './data.js';
import { View3D } from './view3d.js';
import { SequenceViewer } from './sequence.js';
import { DetectionViewer } from './detection.js';

const params = new URLSearchParams(location.hash.slice(1));
const testing = params.has('test');
const state = { ready: false };

function report(extra = {}) {
  Object.assign(state, extra);
  if (viewer) Object.assign(state, viewer.state());
  document.getElementById('clothcd-state').textContent = JSON.stringify(state);
}

let viewer = null;
let view = null;

// Pixels of the canvas whose colour is the cloth's blue hue (b clearly above r and g).
function clothPixels() {
  const gl = view.renderer.getContext();
  const w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
  const px = new Uint8Array(w * h * 4);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
  let n = 0;
  for (let i = 0; i < px.length; i += 4) {
    if (px[i + 2] > px[i] + 30 && px[i + 2] > px[i + 1] + 10) n++;
  }
  return { clothPixels: n, pixels: w * h };
}

const nextFrame = () => new Promise((r) => requestAnimationFrame(() => r()));

async function selfTest() {
  view.render();
  const seen = clothPixels();
  report({ ...seen });
  if (viewer instanceof SequenceViewer) {
    if (viewer.meta.strain) report({ maxStrain: viewer.maxStrains() });
    const start = viewer.index;
    document.getElementById('play').click();
    const deadline = performance.now() + 20000;
    while (viewer.index === start && viewer.frames.length > 1 && performance.now() < deadline) {
      await nextFrame();
    }
    document.getElementById('play').click();
    report({ playedFrom: start, playedTo: viewer.index });
  } else {
    const item = document.querySelector('#hits li');
    if (item) item.click();
    await nextFrame();
    const sel = document.getElementById('selected-hit');
    report({ listedHit: item ? +item.dataset.hit : -1, selectedText: sel ? sel.textContent : '' });
  }
  report({ done: true });
}

async function main() {
  const started = performance.now();
  try {
    const data = await loadPageData();
    const decoded = performance.now();
    document.title = data.meta.title;
    view = new View3D(document.getElementById('view'), { keepPixels: testing });
    const Kind = data.meta.kind === 'detection' ? DetectionViewer : SequenceViewer;
    viewer = new Kind(view, data, params, () => report());
    report({ ready: true, kind: data.meta.kind, decodeMs: Math.round(decoded - started),
      loadMs: Math.round(performance.now() - started) });
    if (testing) await selfTest();
  } catch (e) {
    const box = document.getElementById('error');
    box.style.display = 'block';
    box.textContent = `clothcd view: ${e && e.message ? e.message : e}`;
    report({ error: String(e && e.message ? e.message : e), done: true });
    throw e;
  }
}

main();
