// A detection step: the mesh between its two frames (t slider), the faces of every hit
// highlighted, a list of the hits; choosing one moves the camera to it and draws its features.
import * as THREE from 'three';
import { boxOf, FaceMesh } from './view3d.js';
import { BOTH_HIT, CLOTH, EE_HIT, VF_HIT } from './colours.js';
import { el, legend, rgbCss, table } from './ui.js';

const PAGE = 200;  // hits listed at once

export class DetectionViewer {
  constructor(view, { meta, arrays }, params, report) {
    this.view = view;
    this.meta = meta;
    this.a = arrays;
    this.report = report;
    this.t = 0;
    this.selected = -1;
    this.kindFilter = 'all';
    this.page = 0;
    this.positions = new Float32Array(arrays.t0.length);
    this.mesh = new FaceMesh(arrays.faces);
    view.scene.add(this.mesh.object);
    const flags = arrays.hit_faces;
    this.mesh.setFaceColours((f, rgb) => {
      const c = flags[f] === 3 ? BOTH_HIT : flags[f] === 2 ? EE_HIT : flags[f] === 1 ? VF_HIT : CLOTH;
      rgb[0] = c[0]; rgb[1] = c[1]; rgb[2] = c[2];
    });
    this.marker = new THREE.LineSegments(new THREE.BufferGeometry(),
      new THREE.LineBasicMaterial({ color: 0xffff00, depthTest: false }));
    this.marker.renderOrder = 1;
    this.point = new THREE.Points(new THREE.BufferGeometry(),
      new THREE.PointsMaterial({ color: 0xffff00, size: 8, sizeAttenuation: false, depthTest: false }));
    this.point.renderOrder = 1;
    view.scene.add(this.marker, this.point);
    this.buildPanel();
    this.setT(0);
    view.fit(boxOf(arrays.t0));
    if (params.has('hit')) this.select(parseInt(params.get('hit'), 10) || 0);
  }

  buildPanel() {
    const m = this.meta;
    document.getElementById('title').textContent = `${m.t0} → ${m.t1}`;
    const c = document.getElementById('controls');
    this.tLabel = el('span', { id: 't-label' });
    this.slider = el('input', { id: 't', type: 'range', min: 0, max: 1000, value: 0,
      oninput: (e) => this.setT(+e.target.value / 1000) });
    c.append(el('div', { class: 'row' }, el('span', { text: 't' }), this.slider, this.tLabel));
    const kinds = this.a.hit_kind;
    let vf = 0;
    for (let i = 0; i < kinds.length; i++) if (kinds[i] === 0) vf++;
    this.counts = { vf, ee: kinds.length - vf };
    c.append(legend([[rgbCss(VF_HIT), 'VF'], [rgbCss(EE_HIT), 'EE'], [rgbCss(BOTH_HIT), 'both']]));
    c.append(el('h2', { text: `hits (${kinds.length.toLocaleString('en-US')})` }));
    const filter = el('select', { id: 'hit-kind', onchange: (e) => { this.kindFilter = e.target.value;
      this.page = 0; this.fillList(); } });
    for (const [k, label] of [['all', 'all'], ['vf', `VF (${vf})`], ['ee', `EE (${this.counts.ee})`]]) {
      filter.append(el('option', { value: k }, label));
    }
    this.pageLabel = el('span');
    c.append(el('div', { class: 'row' }, filter,
      el('button', { onclick: () => { this.page = Math.max(0, this.page - 1); this.fillList(); } }, '◀'),
      this.pageLabel,
      el('button', { onclick: () => { this.page++; this.fillList(); } }, '▶')));
    this.list = el('ul', { id: 'hits' });
    c.append(this.list);
    this.info = el('div', { id: 'hit-info' });
    c.append(this.info);
    c.append(el('h2', { text: 'step' }));
    const s = m.stats || {};
    const rows = [['vertices', m.vertices], ['faces', m.faces], ['result', m.result]];
    for (const k of ['vf_collisions', 'ee_collisions', 'triangle_pairs', 'box_tests', 'nodes_culled',
      'cone_tests', 'contour_tests', 'vf_tests', 'ee_tests', 'time_traverse', 'time_narrow']) {
      if (k in s) rows.push([k.replaceAll('_', ' '), s[k]]);
    }
    for (const k of ['missed_vf', 'missed_ee']) if (k in m) rows.push([k.replace('_', ' '), m[k]]);
    c.append(table(rows));
    c.append(el('p', { text: 'The result lists no culled nodes, only how many (nodes culled).' }));
    c.append(el('p', { text: 'Drag to orbit, right-drag to pan, wheel to zoom.' }));
    this.fillList();
  }

  matching() {
    if (this.kindFilter === 'all') return null;
    const want = this.kindFilter === 'vf' ? 0 : 1;
    const ids = [];
    const kinds = this.a.hit_kind;
    for (let i = 0; i < kinds.length; i++) if (kinds[i] === want) ids.push(i);
    return ids;
  }

  fillList() {
    const ids = this.matching();
    const total = ids ? ids.length : this.a.hit_kind.length;
    const pages = Math.max(1, Math.ceil(total / PAGE));
    this.page = Math.min(this.page, pages - 1);
    this.pageLabel.textContent = `${this.page + 1} / ${pages}`;
    const items = [];
    for (let k = this.page * PAGE; k < Math.min(total, (this.page + 1) * PAGE); k++) {
      const i = ids ? ids[k] : k;
      const li = el('li', { 'data-hit': i, onclick: () => this.select(i) }, this.describe(i));
      if (i === this.selected) li.classList.add('selected');
      items.push(li);
    }
    this.list.replaceChildren(...items);
  }

  describe(i) {
    const v = this.a.hit_vertices.subarray(4 * i, 4 * i + 4);
    const t = this.a.hit_toi[i].toFixed(4);
    return this.a.hit_kind[i] === 0 ? `#${i} VF  v${v[0]} – f(${v[1]}, ${v[2]}, ${v[3]})  t ${t}`
      : `#${i} EE  (${v[0]}, ${v[1]}) – (${v[2]}, ${v[3]})  t ${t}`;
  }

  setT(t) {
    this.t = t;
    const a = this.a.t0, b = this.a.t1, p = this.positions;
    for (let i = 0; i < p.length; i++) p[i] = a[i] + (b[i] - a[i]) * t;
    this.mesh.update(p);
    this.slider.value = Math.round(t * 1000);
    this.tLabel.textContent = t.toFixed(3);
    this.drawMarker();
    this.view.render();
    this.report();
  }

  // The selected hit's features at the current t: the face's outline and its vertex, or the two
  // edges.
  drawMarker() {
    if (this.selected < 0) return;
    const v = this.a.hit_vertices.subarray(4 * this.selected, 4 * this.selected + 4);
    const p = this.positions;
    const at = (k) => [p[3 * k], p[3 * k + 1], p[3 * k + 2]];
    let lines;
    let points;
    if (this.a.hit_kind[this.selected] === 0) {
      lines = [v[1], v[2], v[2], v[3], v[3], v[1]].flatMap(at);
      points = at(v[0]);
    } else {
      lines = [v[0], v[1], v[2], v[3]].flatMap(at);
      points = [v[0], v[1], v[2], v[3]].flatMap(at);
    }
    this.marker.geometry.setAttribute('position', new THREE.Float32BufferAttribute(lines, 3));
    this.point.geometry.setAttribute('position', new THREE.Float32BufferAttribute(points, 3));
    this.marker.geometry.computeBoundingSphere();
    this.point.geometry.computeBoundingSphere();
  }

  select(i) {
    if (!(i >= 0 && i < this.a.hit_kind.length)) return;
    this.selected = i;
    for (const li of this.list.querySelectorAll('li')) {
      li.classList.toggle('selected', +li.dataset.hit === i);
    }
    this.setT(this.a.hit_toi[i]);
    const v = [...this.a.hit_vertices.subarray(4 * i, 4 * i + 4)];
    const box = new THREE.Box3();
    const q = new THREE.Vector3();
    for (const k of v) box.expandByPoint(q.fromArray(this.positions, 3 * k));
    const size = box.getSize(new THREE.Vector3()).length();
    const whole = boxOf(this.a.t0).getSize(new THREE.Vector3()).length();
    // Close enough to see the features, far enough to see the faces around them.
    this.view.focus(box.getCenter(new THREE.Vector3()), Math.max(size * 4, whole * 0.01));
    this.info.replaceChildren(el('p', { id: 'selected-hit', text: `selected: ${this.describe(i)}` }));
    this.report();
  }

  state() {
    return { t: this.t, selectedHit: this.selected, hits: this.a.hit_kind.length,
      vf: this.counts.vf, ee: this.counts.ee,
      target: this.view.controls.target.toArray() };
  }
}
