// A line search that never lets the cloth pass through itself, as intersection-free integrators
// run it: each iteration proposes a step dx, asks how far along x -> x + dx every pair of
// features stays apart (SelfDetector::earliest_impact), and moves a safe fraction of that way.
//
// The scene: a sheet folded over itself, its upper half pushed down through the lower half by a
// step of twice their distance. A full step would cross; the line search stops short of contact.

#include <clothcd/detect/detector.hpp>

#include <cmath>
#include <cstdio>
#include <vector>

int main() {
  // An n x n sheet over [0, 1] x [0, 1] at z = 0, and a copy at z = 0.1 (both in one mesh).
  const int n = 16;
  std::vector<clothcd::Face> faces;
  std::vector<Eigen::Vector3d> x;
  for (int layer = 0; layer < 2; ++layer) {
    const int base = static_cast<int>(x.size());
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; j <= n; ++j)
        x.emplace_back(double(i) / n, double(j) / n, 0.1 * layer + 0.01 * std::sin(7.0 * i / n));
    }
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        const int a = base + i * (n + 1) + j, b = a + n + 1;
        faces.push_back({a, b, b + 1});
        faces.push_back({a, b + 1, a + 1});
      }
    }
  }
  // The step every iteration proposes: the upper layer down by 0.2, the lower one still.
  std::vector<Eigen::Vector3d> dx(x.size(), Eigen::Vector3d::Zero());
  for (std::size_t v = x.size() / 2; v < x.size(); ++v)
    dx[v] = Eigen::Vector3d(0, 0, -0.2);

  clothcd::DetectOptions options;
  options.thickness = 1e-3;  // the smallest distance the integrator allows between features
  clothcd::SelfDetector detector(faces, static_cast<int>(x.size()), x, options);
  double gap = x[x.size() / 2].z() - x[0].z();
  for (int iteration = 0; iteration < 4; ++iteration) {
    std::vector<Eigen::Vector3d> target(x.size());
    for (std::size_t v = 0; v < x.size(); ++v)
      target[v] = x[v] + dx[v];
    const clothcd::EarliestImpact e = detector.earliest_impact(x, target);
    // Go most of the way to the first contact (all of it when there is none).
    const double alpha = e.kind == clothcd::EarliestImpact::Kind::None ? 1.0 : 0.8 * e.toi;
    for (std::size_t v = 0; v < x.size(); ++v)
      x[v] += alpha * dx[v];
    gap = x[x.size() / 2].z() - x[0].z();
    std::printf("iteration %d: toi %.6f (%s), step %.6f, gap %.6f\n", iteration, e.toi,
                e.kind == clothcd::EarliestImpact::Kind::None         ? "none"
                : e.kind == clothcd::EarliestImpact::Kind::VertexFace ? "vertex-face"
                                                                      : "edge-edge",
                alpha, gap);
  }
  // The layers came closer every iteration and never through each other.
  return gap > options.thickness ? 0 : 1;
}
