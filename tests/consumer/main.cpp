// A downstream program that uses the installed clothcd package: one self-collision detection
// step through clothcd::clothcd and one simulated frame through clothcd::simulator.
#include <clothcd/cone.hpp>
#include <clothcd/detect/detector.hpp>
#include <clothcd/research/detector.hpp>
#include <clothcd/research/names.hpp>
#include <clothcd/sim/scene.hpp>
#include <clothcd/sim/simulation.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

namespace {

// A small triangle falls through a large one: its three vertices hit it at t = 0.5.
int detect_step() {
  const std::vector<clothcd::Face> faces = {{0, 1, 2}, {3, 4, 5}};
  clothcd::Positions x0(6, 3);
  x0 << 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,  //
      0.2, 0.01, 0.2, 0.3, 0.01, 0.2, 0.2, 0.01, 0.3;
  clothcd::Positions x1 = x0;
  x1.bottomRows(3).col(1).array() -= 0.02;
  clothcd::research::DetectOptions options;
  options.culling = clothcd::Culling::Sound;
  // The research options by name: sound culling checked against unculled detection.
  options.research.verify = true;
  if (clothcd::research::culling_rule(options) != clothcd::research::parse_culling_rule("SOUND")) {
    return 1;
  }
  clothcd::research::SelfDetector detector(faces, 6, x0, options);
  const clothcd::research::DetectResult r = detector.detect(x0, x1);
  const clothcd::research::Verification& v = r.verification;
  std::printf("detect: %zu VF, %zu EE collisions, verified %d, missed %zu\n", r.vf.size(),
              r.ee.size(), int(v.ran), v.missed_vf.size() + v.missed_ee.size());
  return r.vf.size() == 3 && v.ran && v.missed_vf.empty() && v.missed_ee.empty() ? 0 : 1;
}

// A 10 x 10 cloth dropping onto a sphere, one frame.
int simulate_frame() {
  const std::filesystem::path scene =
      std::filesystem::temp_directory_path() / "clothcd_consumer.json";
  std::ofstream(scene) << R"({
    "name": "consumer", "frames": 1, "frame_dt": 0.04,
    "cloth": {"grid": {"origin": [-0.5, 0.3, -0.5], "u": [1, 0, 0], "v": [0, 0, 1],
                       "resolution": [10, 10]}},
    "material": {"area_density": 0.15, "stretch_stiffness": 260, "poisson": 0.25,
                 "bending_stiffness": 1e-7, "friction": 0.4},
    "body": {"type": "sphere", "center": [0, 0, 0], "radius": 0.25, "subdivisions": 2},
    "collisions": {"self": true, "body": true, "thickness": 0.001, "ccd_thickness": 1e-5}
  })";
  clothcd::sim::Simulation sim(clothcd::sim::load_scene(scene));
  const clothcd::sim::FrameStats s = sim.advance_frame();
  std::filesystem::remove(scene);
  std::printf("simulate: frame %d, %d substeps, finite %d\n", s.frame, s.substeps, int(s.finite));
  return s.frame == 1 && s.finite ? 0 : 1;
}

}  // namespace

int main() {
  const clothcd::NormalCone a{Eigen::Vector3d::UnitZ(), 0.1};
  const clothcd::NormalCone b{Eigen::Vector3d(0, 1, 1).normalized(), 0.2};
  const auto m = clothcd::merge_tight(a, b);
  std::printf("merged half-angle %.6f saturated %d\n", m.half_angle, int(m.saturated()));
  if (m.saturated()) return 1;
  return detect_step() + simulate_frame();
}
