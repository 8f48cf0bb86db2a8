// Colours of the cloth: plain, by membrane strain, by contact.

export const CLOTH = [0.35, 0.55, 0.9];
export const BODY = 0xd9ccbf;
export const SLIVER = [0.55, 0.55, 0.55];
export const CONTACT = [1.0, 0.45, 0.1];
export const VF_HIT = [0.95, 0.15, 0.15];
export const EE_HIT = [1.0, 0.6, 0.1];
export const BOTH_HIT = [0.9, 0.2, 0.8];
export const STRAIN_TOP = 0.3;  // strain at the red end of the scale

// Largest principal stretch minus one, sigma_max(F) - 1, as the simulator's max_stretch:
// F = [x1 - x0, x2 - x0] times the rest inverse B (rows g1, g2: rest[4t .. 4t + 3]).
export function faceStrain(p, faces, rest, t) {
  const a = faces[3 * t] * 3, b = faces[3 * t + 1] * 3, c = faces[3 * t + 2] * 3;
  const e1x = p[b] - p[a], e1y = p[b + 1] - p[a + 1], e1z = p[b + 2] - p[a + 2];
  const e2x = p[c] - p[a], e2y = p[c + 1] - p[a + 1], e2z = p[c + 2] - p[a + 2];
  const b00 = rest[4 * t], b01 = rest[4 * t + 1], b10 = rest[4 * t + 2], b11 = rest[4 * t + 3];
  // F = D B with D = [e1 e2] (3 x 2): column j of F is e1 B[0][j] + e2 B[1][j].
  const f0x = e1x * b00 + e2x * b10, f0y = e1y * b00 + e2y * b10, f0z = e1z * b00 + e2z * b10;
  const f1x = e1x * b01 + e2x * b11, f1y = e1y * b01 + e2y * b11, f1z = e1z * b01 + e2z * b11;
  const c00 = f0x * f0x + f0y * f0y + f0z * f0z;
  const c11 = f1x * f1x + f1y * f1y + f1z * f1z;
  const c01 = f0x * f1x + f0y * f1y + f0z * f1z;
  const half = 0.5 * (c00 + c11);
  const disc = Math.sqrt(Math.max(0, half * half - (c00 * c11 - c01 * c01)));
  return Math.sqrt(half + disc) - 1;
}

// Blue (no stretch or compressed) through yellow (STRAIN_TOP / 3) to red (STRAIN_TOP and more).
export function strainColour(s, out) {
  const u = Math.min(Math.max(s / STRAIN_TOP, 0), 1);
  const knee = 1 / 3;
  if (u < knee) {
    const w = u / knee;
    out[0] = CLOTH[0] + (1.0 - CLOTH[0]) * w;
    out[1] = CLOTH[1] + (0.9 - CLOTH[1]) * w;
    out[2] = CLOTH[2] + (0.2 - CLOTH[2]) * w;
  } else {
    const w = (u - knee) / (1 - knee);
    out[0] = 1.0;
    out[1] = 0.9 - 0.75 * w;
    out[2] = 0.2 - 0.1 * w;
  }
}
