// The page's data: its description (JSON) and the typed arrays of its data block, which the page
// holds gzip-compressed and base64-encoded (src/view/page_builder.cpp writes both).

const TYPES = { u8: Uint8Array, u16: Uint16Array, i32: Int32Array, u32: Uint32Array,
  f32: Float32Array };

export async function loadPageData() {
  const meta = JSON.parse(document.getElementById('clothcd-meta').textContent);
  const text = document.getElementById('clothcd-data').textContent.trim();
  let packed;
  if (typeof Uint8Array.fromBase64 === 'function') {
    packed = Uint8Array.fromBase64(text);  // native, where the browser has it
  } else {
    const binary = atob(text);
    packed = new Uint8Array(binary.length);
    for (let i = 0; i < binary.length; i++) packed[i] = binary.charCodeAt(i);
  }
  const stream = new Blob([packed]).stream().pipeThrough(new DecompressionStream('gzip'));
  const block = await new Response(stream).arrayBuffer();
  if (block.byteLength !== meta.data_bytes) {
    throw new Error(`data block has ${block.byteLength} bytes, expected ${meta.data_bytes}`);
  }
  const arrays = {};
  for (const [name, b] of Object.entries(meta.buffers)) {
    arrays[name] = new TYPES[b.type](block, b.offset, b.count);
  }
  return { meta, arrays, packedBytes: packed.length };
}

// Positions of every frame of a mesh: 16-bit values q over the box (x = origin + q * step);
// frame 0 as is, frame 1 as its difference from frame 0, later frames as their difference from
// q[k-1] + (q[k-1] - q[k-2]), zigzag-coded, modulo 2^16, low and high bytes stored apart
// (src/view/quantize.hpp).
export function decodeFrames(mesh, low, high) {
  const n3 = mesh.vertices * 3;
  const frames = low.length / n3;
  const q = new Uint16Array(n3);
  const velocity = new Uint16Array(n3);
  const out = [];
  const origin = mesh.origin;
  const step = mesh.step;
  for (let k = 0; k < frames; k++) {
    const base = k * n3;
    const p = new Float32Array(n3);
    for (let i = 0; i < n3; i++) {
      const code = low[base + i] | (high[base + i] << 8);
      if (k === 0) {
        q[i] = code;
      } else {
        velocity[i] += (code & 1) ? -(code >>> 1) - 1 : code >>> 1;  // wraps modulo 2^16
        q[i] += velocity[i];
      }
      const a = i % 3;
      p[i] = origin[a] + q[i] * step[a];
    }
    out.push(p);
  }
  return out;
}
