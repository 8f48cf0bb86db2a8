// The page's data: its description (JSON) and the typed arrays of its data block, which the page
// holds gzip-compressed and base64-encoded (src/view/page_builder.cpp writes both).

const TYPES = { u8: Uint8Array, u16: Uint16Array, i32: Int32Array, u32: Uint32Array,
  f32: Float32Array };

export async function loadPageData() {
  const meta = JSON.parse(document.getElementById('clothcd-meta').textContent);
  const text = document.getElementById('clothcd-data').textContent.trim();
  const binary = atob(text);
  const packed = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; i++) packed[i] = binary.charCodeAt(i);
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

// Positions of every frame of a mesh: 16-bit values over the box origin + q * step, frame 0 as
// is and later frames as differences modulo 2^16, low bytes and high bytes stored apart
// (src/view/quantize.hpp).
export function decodeFrames(mesh, low, high) {
  const n3 = mesh.vertices * 3;
  const frames = low.length / n3;
  const q = new Uint16Array(n3);
  const out = [];
  const [ox, oy, oz] = mesh.origin;
  const [sx, sy, sz] = mesh.step;
  for (let k = 0; k < frames; k++) {
    const base = k * n3;
    const p = new Float32Array(n3);
    for (let i = 0; i < n3; i += 3) {
      q[i] = q[i] + (low[base + i] | (high[base + i] << 8));
      q[i + 1] = q[i + 1] + (low[base + i + 1] | (high[base + i + 1] << 8));
      q[i + 2] = q[i + 2] + (low[base + i + 2] | (high[base + i + 2] << 8));
      p[i] = ox + q[i] * sx;
      p[i + 1] = oy + q[i + 1] * sy;
      p[i + 2] = oz + q[i + 2] * sz;
    }
    out.push(p);
  }
  return out;
}
