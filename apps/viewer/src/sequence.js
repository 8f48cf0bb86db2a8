// A simulation: the cloth and the body frame by frame, play / pause, a frame slider, colouring
// by strain, contact or nothing, and the manifest's figures of the frame.
import { decodeFrames } from './data.js';
import { boxOf, FaceMesh, SmoothMesh } from './view3d.js';
import { BODY, CLOTH, CONTACT, SLIVER, STRAIN_TOP, faceStrain, strainColour } from './colours.js';
import { el, legend, rgbCss, table } from './ui.js';

const FRAME_FIGURES = [
  ['time', 'time (s)'], ['substeps', 'substeps'], ['halvings', 'halvings'],
  ['pcg_iterations', 'PCG iterations'], ['proximity_pairs', 'proximity pairs'],
  ['ccd_hits', 'CCD hits'], ['zones', 'impact zones'], ['unresolved_ccd_hits', 'unresolved hits'],
  ['self_intersections', 'self intersections'], ['body_intersections', 'body intersections'],
  ['max_stretch', 'max stretch'], ['seconds', 'seconds'], ['collision_seconds', 'collision s'],
];

export class SequenceViewer {
  constructor(view, { meta, arrays }, params, report) {
    this.view = view;
    this.meta = meta;
    this.arrays = arrays;
    this.report = report;
    const cm = meta.meshes.cloth;
    this.cloth = decodeFrames(cm, arrays.cloth_low, arrays.cloth_high);
    this.clothMesh = new FaceMesh(arrays.cloth_faces);
    view.scene.add(this.clothMesh.object);
    if (meta.meshes.body) {
      this.body = decodeFrames(meta.meshes.body, arrays.body_low, arrays.body_high);
      this.bodyMesh = new SmoothMesh(arrays.body_faces, meta.meshes.body.vertices, BODY);
      view.scene.add(this.bodyMesh.object);
    }
    this.frames = meta.frames;
    this.index = 0;
    this.playing = false;
    this.colour = params.get('colour') || (meta.strain ? 'strain' : 'none');
    if (!this.colourModes().includes(this.colour)) this.colour = 'none';
    this.buildPanel();
    this.show(Math.min(Math.max(parseInt(params.get('frame') || '0', 10) || 0, 0),
      this.frames.length - 1));
    const box = boxOf(this.cloth[this.index]);
    if (this.body) box.union(boxOf(this.body[this.index]));
    view.fit(box);
  }

  colourModes() {
    const modes = ['none'];
    if (this.meta.strain) modes.push('strain');
    if (this.meta.contact) modes.push('contact');
    return modes;
  }

  buildPanel() {
    const m = this.meta;
    document.getElementById('title').textContent = m.run.scene || 'simulation';
    const c = document.getElementById('controls');
    this.playButton = el('button', { id: 'play', onclick: () => this.toggle() }, 'play');
    this.slider = el('input', { id: 'frame', type: 'range', min: 0, max: this.frames.length - 1,
      value: 0, oninput: (e) => { this.pause(); this.show(+e.target.value); } });
    this.counter = el('span', { id: 'frame-counter' });
    const colour = el('select', { id: 'colour', onchange: (e) => { this.colour = e.target.value;
      this.paint(); this.view.render(); this.report(); } });
    for (const mode of this.colourModes()) {
      const o = el('option', { value: mode }, `colour: ${mode}`);
      if (mode === this.colour) o.selected = true;
      colour.append(o);
    }
    const speed = el('select', { id: 'speed', onchange: (e) => { this.fps = +e.target.value; } });
    for (const fps of [5, 12, 25, 50]) {
      const o = el('option', { value: fps }, `${fps} frames/s`);
      if (fps === 25) o.selected = true;
      speed.append(o);
    }
    this.fps = 25;
    c.append(el('div', { class: 'row' }, this.playButton, this.counter),
      el('div', { class: 'row' }, this.slider),
      el('div', { class: 'row' }, colour, speed));
    if (this.bodyMesh) {
      const box = el('input', { type: 'checkbox', id: 'show-body', checked: '',
        onchange: (e) => { this.bodyMesh.object.visible = e.target.checked; this.view.render(); } });
      c.append(el('div', { class: 'row' }, el('label', {}, box, ' body')));
    }
    this.legend = el('div');
    c.append(this.legend);
    c.append(el('h2', { text: 'frame' }));
    this.figures = el('div', { id: 'figures' });
    c.append(this.figures);
    c.append(el('h2', { text: 'run' }));
    const r = m.run;
    c.append(table([
      ['vertices', r.vertices], ['faces', r.faces], ['frame dt (s)', r.frame_dt],
      ['complete frames', r.complete_frames], ['frames on this page', this.frames.length],
      ['collisions', r.collisions], ['thickness (m)', r.thickness], ['slivers', r.slivers],
      ['stitches', r.stitches], ['contact distance (m)', m.contact_distance],
    ].filter(([, v]) => v !== undefined)));
    for (const n of m.notes || []) c.append(el('p', { class: 'note', text: n }));
    c.append(el('p', { text: 'Drag to orbit, right-drag to pan, wheel to zoom.' }));
  }

  toggle() { if (this.playing) this.pause(); else this.play(); }

  play() {
    if (this.frames.length < 2) return;
    this.playing = true;
    this.playButton.textContent = 'pause';
    let last = performance.now();
    const tick = (now) => {
      if (!this.playing) return;
      if (now - last >= 1000 / this.fps) {
        last = now;
        this.show((this.index + 1) % this.frames.length);
      }
      requestAnimationFrame(tick);
    };
    requestAnimationFrame(tick);
    this.report();
  }

  pause() {
    this.playing = false;
    this.playButton.textContent = 'play';
    this.report();
  }

  show(i) {
    this.index = i;
    this.clothMesh.update(this.cloth[i]);
    if (this.bodyMesh) this.bodyMesh.update(this.body[i]);
    this.paint();
    this.slider.value = i;
    const f = this.frames[i];
    this.counter.textContent = `frame ${f.frame} (${i + 1} / ${this.frames.length})`;
    this.figures.replaceChildren(table(FRAME_FIGURES.filter(([k]) => k in f)
      .map(([k, label]) => [label, f[k]])));
    this.view.render();
    this.report();
  }

  paint() {
    const i = this.index;
    if (this.colour === 'strain') {
      const p = this.cloth[i];
      const faces = this.arrays.cloth_faces;
      const rest = this.arrays.rest;
      const active = this.arrays.membrane_active;
      this.clothMesh.setFaceColours((t, rgb) => {
        if (!active[t]) { rgb[0] = SLIVER[0]; rgb[1] = SLIVER[1]; rgb[2] = SLIVER[2]; return; }
        strainColour(faceStrain(p, faces, rest, t), rgb);
      });
      const mid = [0, 0, 0], top = [0, 0, 0];
      strainColour(STRAIN_TOP / 3, mid);
      strainColour(STRAIN_TOP, top);
      this.legend.replaceChildren(legend([[rgbCss(CLOTH), '0'],
        [rgbCss(mid), `${Math.round(100 * STRAIN_TOP / 3)}%`],
        [rgbCss(top), `${Math.round(100 * STRAIN_TOP)}%+ stretch`],
        [rgbCss(SLIVER), 'sliver']]));
    } else if (this.colour === 'contact') {
      const n = this.meta.meshes.cloth.vertices;
      const row = (n + 7) >> 3;
      const bits = this.arrays.contact.subarray(i * row, (i + 1) * row);
      this.clothMesh.setCornerColours((v, rgb) => {
        const c = (bits[v >> 3] >> (v & 7)) & 1 ? CONTACT : CLOTH;
        rgb[0] = c[0]; rgb[1] = c[1]; rgb[2] = c[2];
      });
      this.legend.replaceChildren(legend([[rgbCss(CONTACT),
        `within ${this.meta.contact_distance} m of the body or another part`]]));
    } else {
      this.clothMesh.setFaceColours((t, rgb) => { rgb[0] = CLOTH[0]; rgb[1] = CLOTH[1]; rgb[2] = CLOTH[2]; });
      this.legend.replaceChildren();
    }
  }

  // The largest strain of each frame, over the faces with a membrane (what the manifest's
  // max_stretch reports, here from the page's quantised positions).
  maxStrains() {
    const faces = this.arrays.cloth_faces, rest = this.arrays.rest;
    const active = this.arrays.membrane_active;
    return this.cloth.map((p) => {
      let top = 0;
      for (let t = 0; t < active.length; t++) {
        if (active[t]) top = Math.max(top, faceStrain(p, faces, rest, t));
      }
      return top;
    });
  }

  state() {
    return { frame: this.frames[this.index].frame, index: this.index, playing: this.playing,
      colour: this.colour, frames: this.frames.length };
  }
}
