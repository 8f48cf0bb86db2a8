// The 3D view: renderer, orbit camera, lights, and meshes drawn face by face (each corner its own
// vertex, so a colour can belong to a face) or, for the body, shared-vertex and smooth.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

export class View3D {
  constructor(container, { keepPixels = false } = {}) {
    this.container = container;
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: keepPixels });
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.renderer.setClearColor(0x20232a);
    container.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(35, 1, 0.001, 1000);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.enableDamping = false;
    this.controls.addEventListener('change', () => this.render());
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x303040, 1.0));
    const sun = new THREE.DirectionalLight(0xffffff, 1.1);
    // The light and its target follow the camera: it shines along the view from above right, so
    // the side in view is always lit.
    sun.position.set(1, 2, 0);
    sun.target.position.set(0, 0, -3);
    this.camera.add(sun, sun.target);
    this.scene.add(this.camera);
    this.frameCount = 0;
    window.addEventListener('resize', () => this.resize());
    this.resize();
  }

  resize() {
    const w = this.container.clientWidth || 1;
    const h = this.container.clientHeight || 1;
    this.renderer.setSize(w, h);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.render();
  }

  render() {
    this.renderer.render(this.scene, this.camera);
    this.frameCount++;
  }

  // Looks at the box from the front (+z, y up) and a little above and to the side (a flat sheet
  // is not seen edge-on), at a distance that shows all of it.
  fit(box, direction = new THREE.Vector3(0.35, 0.45, 1)) {
    const sphere = box.getBoundingSphere(new THREE.Sphere());
    const r = Math.max(sphere.radius, 1e-6);
    this.camera.position.copy(this.controls.target).add(direction);
    this.focus(sphere.center, r * 1.1);
  }

  // Points the camera at `center` from its current direction, `radius` filling the view.
  focus(center, radius) {
    const dir = this.camera.position.clone().sub(this.controls.target);
    if (dir.lengthSq() === 0) dir.set(0, 0, 1);
    dir.normalize();
    const dist = radius / Math.sin((this.camera.fov * Math.PI) / 360);
    this.controls.target.copy(center);
    this.camera.position.copy(center).addScaledVector(dir, dist);
    this.camera.near = dist / 1000;
    this.camera.far = dist * 100;
    this.camera.updateProjectionMatrix();
    this.controls.update();
    this.render();
  }
}

// A triangle mesh drawn per face: update(positions) and setFaceColours / setCornerColours.
export class FaceMesh {
  constructor(faces, { opacity = 1 } = {}) {
    this.faces = faces;
    const m = faces.length / 3;
    this.geometry = new THREE.BufferGeometry();
    this.position = new THREE.BufferAttribute(new Float32Array(m * 9), 3);
    this.colour = new THREE.BufferAttribute(new Float32Array(m * 9), 3);
    this.position.setUsage(THREE.DynamicDrawUsage);
    this.colour.setUsage(THREE.DynamicDrawUsage);
    this.geometry.setAttribute('position', this.position);
    this.geometry.setAttribute('color', this.colour);
    this.material = new THREE.MeshLambertMaterial({ vertexColors: true, side: THREE.DoubleSide,
      transparent: opacity < 1, opacity });
    this.object = new THREE.Mesh(this.geometry, this.material);
  }

  update(positions) {
    const f = this.faces;
    const out = this.position.array;
    for (let c = 0; c < f.length; c++) {
      const v = f[c] * 3;
      out[c * 3] = positions[v];
      out[c * 3 + 1] = positions[v + 1];
      out[c * 3 + 2] = positions[v + 2];
    }
    this.position.needsUpdate = true;
    this.geometry.computeVertexNormals();
    this.geometry.computeBoundingSphere();
  }

  // rgbOfFace(face, out3) fills the face's colour.
  setFaceColours(rgbOfFace) {
    const out = this.colour.array;
    const rgb = [0, 0, 0];
    for (let t = 0; t < this.faces.length / 3; t++) {
      rgbOfFace(t, rgb);
      for (let c = 0; c < 3; c++) {
        out[t * 9 + c * 3] = rgb[0];
        out[t * 9 + c * 3 + 1] = rgb[1];
        out[t * 9 + c * 3 + 2] = rgb[2];
      }
    }
    this.colour.needsUpdate = true;
  }

  // rgbOfVertex(vertex, out3) fills the colour of every corner at that vertex.
  setCornerColours(rgbOfVertex) {
    const out = this.colour.array;
    const rgb = [0, 0, 0];
    for (let c = 0; c < this.faces.length; c++) {
      rgbOfVertex(this.faces[c], rgb);
      out[c * 3] = rgb[0];
      out[c * 3 + 1] = rgb[1];
      out[c * 3 + 2] = rgb[2];
    }
    this.colour.needsUpdate = true;
  }
}

// A mesh of shared vertices with smooth normals and one colour (the body).
export class SmoothMesh {
  constructor(faces, vertices, colour) {
    this.geometry = new THREE.BufferGeometry();
    this.position = new THREE.BufferAttribute(new Float32Array(vertices * 3), 3);
    this.position.setUsage(THREE.DynamicDrawUsage);
    this.geometry.setAttribute('position', this.position);
    this.geometry.setIndex(new THREE.BufferAttribute(faces, 1));
    this.material = new THREE.MeshLambertMaterial({ color: colour, side: THREE.DoubleSide });
    this.object = new THREE.Mesh(this.geometry, this.material);
  }

  update(positions) {
    this.position.array.set(positions);
    this.position.needsUpdate = true;
    this.geometry.computeVertexNormals();
    this.geometry.computeBoundingSphere();
  }
}

export function boxOf(positions) {
  const box = new THREE.Box3();
  const p = new THREE.Vector3();
  for (let i = 0; i < positions.length; i += 3) box.expandByPoint(p.fromArray(positions, i));
  return box;
}
