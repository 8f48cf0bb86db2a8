#pragma once
// A rectangular grid cloth for the simulator tests.

#include <random>

#include "clothcd/sim/cloth_model.hpp"

namespace clothcd::sim::test {

/// nx * ny quads of size (sx, sz) in the plane y = height, split into two triangles each; vertex
/// (i, j) is j * (nx + 1) + i.
inline ClothMeshInput grid_cloth(int nx, int ny, double sx, double sz, double height = 0.0) {
  ClothMeshInput in;
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i)
      in.positions.emplace_back(sx * i / nx, height, sz * j / ny);
  }
  auto id = [nx](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      // Alternate the diagonal so the mesh has no preferred direction.
      if ((i + j) % 2 == 0) {
        in.faces.push_back({id(i, j), id(i + 1, j + 1), id(i + 1, j)});
        in.faces.push_back({id(i, j), id(i, j + 1), id(i + 1, j + 1)});
      } else {
        in.faces.push_back({id(i, j), id(i, j + 1), id(i + 1, j)});
        in.faces.push_back({id(i + 1, j), id(i, j + 1), id(i + 1, j + 1)});
      }
    }
  }
  return in;
}

inline Vec3 random_vec(std::mt19937_64& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return {u(rng), u(rng), u(rng)};
}

}  // namespace clothcd::sim::test
