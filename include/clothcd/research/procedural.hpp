#pragma once
/// @file
/// The research module's test scenes: small procedural meshes with one linear motion each, built
/// so that the motion produces collisions that the culling modes treat differently
/// (docs/detect.md):
/// - stacked sheets: two disconnected sheets with parallel normals pass through each other; the
///   paper's cone-only rule culls the pair, the connectivity gate does not;
/// - winding strip: a connected strip that winds more than once around an axis with all its
///   normals near the axis (docs/algorithms.md 1.1); the gated cone rule culls it, the contour test
///   does not;
/// - crumpled sheet: a sheet folding onto itself under a random smooth displacement;
/// - twisted strip: a twisted strip coiled so that its ends cross.

#include <cstdint>
#include <string>
#include <vector>

#include "clothcd/detect/detector.hpp"

namespace clothcd::research {

struct ProceduralScene {
  std::string name;
  std::vector<Face> faces;
  int num_vertices = 0;
  Positions v_t0, v_t1;  ///< the step (n x 3)
};

/// Two n x n sheets 0.1 apart moving through each other.
[[nodiscard]] ProceduralScene stacked_sheets(int n = 12);
/// An annular strip over 2 pi + 1 radians, `segments` quads long and `rings` quads wide, whose
/// overlapping ends pass through each other.
[[nodiscard]] ProceduralScene winding_strip(int segments = 96, int rings = 3);
/// An n x n sheet crumpled by a random smooth displacement of the given seed.
[[nodiscard]] ProceduralScene crumpled_sheet(int n, std::uint64_t seed);
/// A strip `segments` x `width` quads, twisted and coiled so that its ends cross.
[[nodiscard]] ProceduralScene twisted_strip(int segments = 80, int width = 4);

/// `positions` plus a smooth displacement field: per coordinate, a sum of three plane waves of
/// the given wavelength (random directions and phases from `seed`), scaled so that no coordinate
/// moves by more than `amplitude`. Neighbouring vertices move almost alike, so a mesh keeps its
/// shape (e.g. a draped garment stepped to a nearby pose). Deterministic for a seed.
[[nodiscard]] Positions smooth_perturbation(const Positions& positions, double amplitude,
                                            double wavelength, std::uint64_t seed);

}  // namespace clothcd::research
