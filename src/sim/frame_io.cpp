// Atomic output files, the binary state, the manifest and the run loop with resume.
#include "clothcd/sim/frame_io.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <optional>
#include <stdexcept>

#include "clothcd/core/atomic_file.hpp"
#include "clothcd/core/error.hpp"

namespace clothcd::sim {
namespace {

constexpr char kStateMagic[8] = {'C', 'L', 'O', 'T', 'H', 'S', 'T', '1'};
constexpr const char* kLockName = ".lock";

std::string frame_name(int frame, const std::string& ext) {
  return fmt::format("frame_{:04d}.{}", frame, ext);
}
std::string state_name(int frame) {
  return fmt::format("state_{:04d}.bin", frame);
}

// The commit point of a frame (see run_simulation).
void write_manifest(const std::filesystem::path& path, const nlohmann::json& manifest) {
  write_file_atomic(path, manifest.dump(1) + '\n', Durability::Sync);
}

// What a killed run can leave: temporary files of the atomic writer (and the fixed `NAME.tmp` of
// earlier versions) for the frame, state and manifest files. Only called with the folder locked.
void remove_temporaries(const std::filesystem::path& folder) {
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(folder, ec)) {
    const std::string name = e.path().filename().string();
    const bool ours = name.starts_with("frame_") || name.starts_with("state_") ||
                      name.starts_with("manifest.json");
    if (ours && (is_atomic_write_temporary(name) || name.ends_with(".tmp"))) {
      std::error_code ignored;
      std::filesystem::remove(e.path(), ignored);
    }
  }
}

template <typename T>
void put(std::ostream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof v);
}

void put_vecs(std::ostream& out, const std::vector<Vec3>& xs) {
  out.write(reinterpret_cast<const char*>(xs.data()),
            static_cast<std::streamsize>(xs.size() * sizeof(Vec3)));
}

}  // namespace

OutputLock::OutputLock(std::filesystem::path folder) : folder_(std::move(folder)) {
  namespace fs = std::filesystem;
  std::error_code ec;
  created_ = !fs::exists(folder_, ec);
  fs::create_directories(folder_, ec);
  if (ec || !fs::is_directory(folder_)) {
    throw OutputError(fmt::format("cannot create output folder '{}': {}", folder_.string(),
                                  ec ? ec.message() : "a file of that name exists"));
  }
  const fs::path file = folder_ / kLockName;
  // Read-only: a descriptor open for writing would, among other things, keep the file system
  // from being remounted read-only while the run holds the lock.
  fd_ = ::open(file.c_str(), O_RDONLY | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    const int err = errno;
    if (created_) fs::remove(folder_, ec);  // still empty: the lock file is not there
    throw OutputError(fmt::format("cannot lock output folder '{}': cannot open '{}': {}",
                                  folder_.string(), file.string(), std::strerror(err)));
  }
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    // The holder wrote its process id into the file; a missing one is only left out.
    char text[32] = {};
    const ssize_t n = ::pread(fd_, text, sizeof text - 1, 0);
    const std::string pid = n > 0 ? fmt::format(" (process {})", std::string(text, n)) : "";
    release();
    if (err == EWOULDBLOCK) {
      throw std::runtime_error(fmt::format(
          "output folder '{}' is in use by another run{}: it holds the lock on '{}'; wait for it "
          "to finish or write to another folder",
          folder_.string(), pid, file.string()));
    }
    throw OutputError(fmt::format("cannot lock output folder '{}': flock on '{}': {}",
                                  folder_.string(), file.string(), std::strerror(err)));
  }
  locked_ = true;
  // The process id, for the message above. Writing it also finds an unwritable folder (read-only
  // file system) at once, not after the first frame has been computed.
  const std::string pid = std::to_string(static_cast<long>(::getpid()));
  const int w = ::open(file.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
  if (w < 0 || ::write(w, pid.data(), pid.size()) != static_cast<ssize_t>(pid.size())) {
    const int err = errno;
    if (w >= 0) ::close(w);
    release();
    throw OutputError(fmt::format("cannot write to output folder '{}': '{}': {}", folder_.string(),
                                  file.string(), std::strerror(err)));
  }
  ::close(w);
}

OutputLock::~OutputLock() {
  release();
}

void OutputLock::release() noexcept {
  namespace fs = std::filesystem;
  std::error_code ec;
  // A folder this lock created and nothing was written to is removed again: a run that fails
  // before its first frame leaves no output. (Not without the lock: another run may own it.)
  if (created_ && locked_) {
    bool only_lock = true;
    for (fs::directory_iterator it(folder_, ec), end; !ec && it != end; it.increment(ec)) {
      if (it->path().filename() != kLockName) only_lock = false;
    }
    if (!ec && only_lock) {
      fs::remove(folder_ / kLockName, ec);
      fs::remove(folder_, ec);
    }
  }
  if (fd_ >= 0) ::close(fd_);  // releases the flock
  fd_ = -1;
}

void write_mesh_atomic(const std::filesystem::path& path, const std::vector<Vec3>& x,
                       const std::vector<Face>& faces, const std::string& format) {
  const auto body = [&](std::ostream& out) {
    if (format == "ply") {
      out << "ply\nformat binary_little_endian 1.0\n"
          << "element vertex " << x.size() << "\nproperty float x\nproperty float y\n"
          << "property float z\nelement face " << faces.size()
          << "\nproperty list uchar int vertex_indices\nend_header\n";
      std::vector<char> buf;
      buf.reserve(x.size() * 12 + faces.size() * 13);
      auto append = [&buf](const void* p, std::size_t n) {
        buf.insert(buf.end(), static_cast<const char*>(p), static_cast<const char*>(p) + n);
      };
      static_assert(std::endian::native == std::endian::little, "PLY writer assumes little endian");
      for (const Vec3& p : x) {
        const float f[3] = {static_cast<float>(p.x()), static_cast<float>(p.y()),
                            static_cast<float>(p.z())};
        append(f, sizeof f);
      }
      for (const Face& f : faces) {
        const unsigned char three = 3;
        append(&three, 1);
        const std::int32_t idx[3] = {f[0], f[1], f[2]};
        append(idx, sizeof idx);
      }
      out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
    } else {
      std::string s;
      s.reserve(x.size() * 40 + faces.size() * 24);
      for (const Vec3& p : x)
        fmt::format_to(std::back_inserter(s), "v {:.9g} {:.9g} {:.9g}\n", p.x(), p.y(), p.z());
      for (const Face& f : faces) {
        fmt::format_to(std::back_inserter(s), "f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
      }
      out.write(s.data(), static_cast<std::streamsize>(s.size()));
    }
  };
  write_file_atomic(path, body, Durability::Sync);
}

void write_state_atomic(const std::filesystem::path& path, const ClothState& state, int frame) {
  const auto body = [&](std::ostream& out) {
    out.write(kStateMagic, sizeof kStateMagic);
    put(out, static_cast<std::int64_t>(state.x.size()));
    put(out, static_cast<std::int64_t>(frame));
    put(out, state.time);
    put_vecs(out, state.x);
    put_vecs(out, state.v);
    put_vecs(out, state.dv);
  };
  write_file_atomic(path, body, Durability::Sync);
}

ClothState read_state(const std::filesystem::path& path, int num_vertices, int& frame) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw input_error(path.string(), 0, "cannot open state file");
  char magic[8];
  std::int64_t n = 0, f = 0;
  ClothState s;
  in.read(magic, sizeof magic);
  in.read(reinterpret_cast<char*>(&n), sizeof n);
  in.read(reinterpret_cast<char*>(&f), sizeof f);
  in.read(reinterpret_cast<char*>(&s.time), sizeof s.time);
  if (!in || std::memcmp(magic, kStateMagic, sizeof magic) != 0) {
    throw input_error(path.string(), 0, "not a clothcd state file");
  }
  if (n != num_vertices) {
    throw input_error(
        path.string(), 0,
        fmt::format("state has {} vertices, the scene's cloth has {}", n, num_vertices));
  }
  for (std::vector<Vec3>* v : {&s.x, &s.v, &s.dv}) {
    v->resize(n);
    in.read(reinterpret_cast<char*>(v->data()), static_cast<std::streamsize>(n * sizeof(Vec3)));
  }
  if (!in) throw input_error(path.string(), 0, "state file is truncated");
  // A damaged or foreign state must not restart a run from garbage.
  if (f < 0 || f > 1000000000) {
    throw input_error(path.string(), 0, fmt::format("state frame {} is out of range", f));
  }
  if (!std::isfinite(s.time)) throw input_error(path.string(), 0, "state time is not finite");
  const char* names[] = {"position", "velocity", "warm start"};
  int k = 0;
  for (const std::vector<Vec3>* v : {&s.x, &s.v, &s.dv}) {
    for (std::size_t i = 0; i < v->size(); ++i) {
      if (!(*v)[i].allFinite()) {
        throw input_error(
            path.string(), 0,
            fmt::format("{} of vertex {} is not finite (expected finite numbers)", names[k], i));
      }
    }
    ++k;
  }
  frame = static_cast<int>(f);
  return s;
}

namespace {

nlohmann::json to_json(const FrameStats& s) {
  return {{"frame", s.frame},
          {"time", s.time},
          {"substeps", s.substeps},
          {"solves", s.solves},
          {"pcg_iterations", s.pcg_iterations},
          {"max_pcg_iterations", s.max_pcg_iterations},
          {"halvings", s.halvings},
          {"pcg_converged", s.pcg_converged},
          {"pcg_tolerance", s.pcg_tolerance},
          {"seconds", s.seconds},
          {"collision_seconds", s.collision.seconds},
          {"max_stretch", s.max_stretch},
          {"strain",
           {{"median", s.strain.median},
            {"p90", s.strain.p90},
            {"p99", s.strain.p99},
            {"p999", s.strain.p999},
            {"max", s.strain.max},
            {"over_10", s.strain.over_10},
            {"max_face", s.strain.max_face},
            {"max_site", strain_site_name(s.strain.max_site)}}},
          {"strain_limit",
           {{"sweeps", s.strain_limit.sweeps},
            {"projections", s.strain_limit.projections},
            {"residual", s.strain_limit.residual}}},
          {"strain_seconds", s.strain_seconds},
          {"body_displacement", s.body_displacement},
          {"finite", s.finite},
          {"proximity_pairs", s.collision.proximity_pairs},
          {"ccd_hits", s.collision.ccd_hits},
          {"ccd_passes", s.collision.ccd_passes},
          {"zones", s.collision.zones},
          {"largest_zone", s.collision.largest_zone},
          {"zone_rounds", s.collision.zone_rounds},
          {"unresolved_ccd_hits", s.collision.unresolved},
          {"excluded_ccd_hits", s.collision.excluded},
          // null when not counted (a non-finite state or counting switched off)
          {"self_intersections",
           s.self_intersections >= 0 ? nlohmann::json(s.self_intersections) : nlohmann::json()},
          {"body_intersections",
           s.body_intersections >= 0 ? nlohmann::json(s.body_intersections) : nlohmann::json()},
          {"intersection_seconds", s.intersection_seconds},
          {"self_ccd",
           {{"calls", s.self_ccd.calls},
            {"triangle_pairs", s.self_ccd.triangle_pairs},
            {"nodes_culled", s.self_ccd.nodes_culled},
            {"refit_s", s.self_ccd.refit_s},
            {"traversal_s", s.self_ccd.traversal_s},
            {"narrow_s", s.self_ccd.narrow_s}}},
          {"self_proximity",
           {{"calls", s.self_proximity.calls},
            {"reused_pairs", s.self_proximity.reused_pairs},
            {"pairs", s.self_proximity.pairs},
            {"query_s", s.self_proximity.query_s}}},
          {"collision_parts",
           {{"setup_s", s.collision_parts.setup_s},
            {"crossings_s", s.collision_parts.crossings_s},
            {"proximity_s", s.collision_parts.proximity_s},
            {"response_s", s.collision_parts.response_s},
            {"ccd_self_s", s.collision_parts.ccd_self_s},
            {"ccd_body_s", s.collision_parts.ccd_body_s},
            {"ccd_hits_s", s.collision_parts.ccd_hits_s},
            {"zones_s", s.collision_parts.zones_s}}}};
}

}  // namespace

std::string frame_stats_json(const FrameStats& s) {
  return to_json(s).dump();
}

std::vector<FrameStats> run_simulation(Simulation& sim, const RunOptions& opt) {
  namespace fs = std::filesystem;
  const Scene& scene = sim.scene();
  const int total = opt.frames >= 0 ? opt.frames : scene.frames;
  const std::string ext = scene.output_format;
  const auto& faces = sim.model().topology().faces();
  const int n = sim.model().num_vertices();
  if (opt.resume_at >= 0 && !(opt.resume && fs::exists(opt.out / "manifest.json"))) {
    throw input_error((opt.out / "manifest.json").string(), 0,
                      fmt::format("cannot resume at frame {}: no run to resume", opt.resume_at));
  }
  std::optional<OutputLock> own_lock;
  if (opt.lock == nullptr) {
    own_lock.emplace(opt.out);
  } else if (opt.lock->folder() != opt.out) {
    throw std::invalid_argument(
        fmt::format("run_simulation: the lock is on '{}', the output is '{}'",
                    opt.lock->folder().string(), opt.out.string()));
  }
  std::error_code ec;
  remove_temporaries(opt.out);
  const fs::path manifest_path = opt.out / "manifest.json";
  nlohmann::json manifest;
  int done = 0;
  if (opt.resume && fs::exists(manifest_path)) {
    std::ifstream in(manifest_path);
    std::string state_file;
    try {
      manifest = nlohmann::json::parse(in);
      done = manifest.at("complete_frames").get<int>();
      // Read here so that a manifest lacking them is an InputError naming it, not a bare
      // json exception.
      state_file = manifest.at("state_file").get<std::string>();
      if (!manifest.at("frames").is_array()) {
        throw input_error(manifest_path.string(), 0, "'frames' is not an array");
      }
      for (const auto& f : manifest.at("frames"))
        (void)f.at("frame").get<int>();
      if (manifest.at("vertices").get<int>() != n ||
          manifest.at("scene").get<std::string>() != scene.name) {
        throw input_error(manifest_path.string(), 0,
                          fmt::format("made by another scene or cloth ('{}', {} vertices), not by "
                                      "'{}' ({} vertices)",
                                      manifest.at("scene").get<std::string>(),
                                      manifest.at("vertices").get<int>(), scene.name, n));
      }
    } catch (const nlohmann::json::exception& e) {
      throw input_error(manifest_path.string(), 0,
                        fmt::format("unreadable manifest: {}", e.what()));
    }
    if (opt.resume_at >= 0 && opt.resume_at != done) {
      if (opt.resume_at > done) {
        throw input_error(manifest_path.string(), 0,
                          fmt::format("cannot resume at frame {}: the run has {} complete frames",
                                      opt.resume_at, done));
      }
      state_file = state_name(opt.resume_at);
      if (!fs::exists(opt.out / state_file)) {
        throw input_error((opt.out / state_file).string(), 0,
                          fmt::format("no state kept for frame {} (run with --keep-states N for "
                                      "every N-th frame's state)",
                                      opt.resume_at));
      }
      done = opt.resume_at;
    }
    int state_frame = -1;
    ClothState st = read_state(opt.out / state_file, n, state_frame);
    if (state_frame != done) {
      throw input_error(
          manifest_path.string(), 0,
          fmt::format("state file is for frame {}, manifest says {}", state_frame, done));
    }
    sim.set_state(std::move(st), done);
    auto& frames = manifest["frames"];
    while (!frames.empty() && frames.back().at("frame").get<int>() > done)
      frames.erase(frames.size() - 1);
    if (const int last = manifest["complete_frames"].get<int>(); last != done) {
      // The manifest commits the earlier frame first; the later files are then stale.
      manifest["complete_frames"] = done;
      manifest["state_file"] = state_file;
      write_manifest(manifest_path, manifest);
      for (int k = done + 1; k <= last; ++k) {
        fs::remove(opt.out / frame_name(k, ext), ec);
        fs::remove(opt.out / state_name(k), ec);
      }
    }
  } else {
    manifest = {{"format_version", 1},
                {"scene", scene.name},
                {"scene_file", fs::absolute(scene.file).string()},
                {"vertices", n},
                {"faces", faces.size()},
                {"frame_dt", scene.frame_dt},
                {"mesh_format", ext},
                {"slivers", sim.model().num_slivers()},
                {"strain_limit",
                 {{"stretch", scene.material.strain_limit},
                  {"compression", scene.material.compression_limit},
                  {"sweeps", scene.solver.strain_sweeps},
                  {"ccd_passes", scene.solver.strain_ccd_passes},
                  {"ccd_sweeps", scene.solver.strain_ccd_sweeps}}},
                {"stitches", sim.model().stitches().size()},
                {"collisions", scene.collisions},
                {"solver",
                 {{"pcg_max_iterations", scene.solver.pcg_max_iterations},
                  {"pcg_tolerance", scene.solver.pcg_tolerance},
                  {"release_tolerance", scene.solver.release_tolerance},
                  {"fast_pcg_tolerance", scene.solver.fast_pcg_tolerance},
                  {"coarse_aggregate", scene.solver.coarse_aggregate},
                  {"halve_residual", scene.solver.halve_residual},
                  {"max_halvings", scene.solver.max_halvings},
                  {"halve_unresolved", scene.solver.halve_unresolved}}},
                {"substeps",
                 {{"min", scene.substeps.min},
                  {"max", scene.substeps.max},
                  {"displacement", scene.substeps.displacement},
                  {"cloth_displacement", scene.substeps.cloth_displacement},
                  {"cloth_speed_quantile", scene.substeps.cloth_speed_quantile}}},
                {"frames", nlohmann::json::array()}};
    if (scene.collisions) {
      const ContactOptions& c = scene.contact;
      manifest["contact"] = {{"self", c.self},
                             {"body", c.body},
                             {"thickness", c.thickness},
                             {"ccd_thickness", c.ccd_thickness},
                             {"ccd_iterations", c.ccd_iterations},
                             {"zone_rounds", c.zone_rounds},
                             {"repulsion_fraction", c.repulsion_fraction},
                             {"repulsion_sweeps", c.repulsion_sweeps},
                             {"pointwise_repulsion", c.pointwise_repulsion},
                             {"body_constraints", c.body_constraints},
                             {"coupled_contacts", c.coupled_contacts},
                             {"untangle_step", c.untangle_step},
                             {"zone_motion", c.affine_zones ? "affine" : "rigid"},
                             {"friction", c.friction}};
    }
    if (const CrossingRepair& r = sim.initial_repair(); r.pairs_before > 0) {
      manifest["initial_repair"] = {{"self_pairs_before", r.pairs_before},
                                    {"self_pairs_after", r.pairs_after},
                                    {"vertices_moved", r.moves},
                                    {"largest_move", r.largest_move}};
    }
    if (scene.count_intersections) {
      const IntersectionCount ic = sim.count_intersections();
      manifest["initial_self_intersections"] = ic.self;
      manifest["initial_body_intersections"] = ic.body;
    }
    write_mesh_atomic(opt.out / frame_name(0, ext), sim.state().x, faces, ext);
    const std::string sname = state_name(0);
    write_state_atomic(opt.out / sname, sim.state(), 0);
    manifest["complete_frames"] = 0;
    manifest["state_file"] = sname;
    write_manifest(manifest_path, manifest);
  }
  std::vector<FrameStats> out;
  while (sim.frame() < total) {
    const FrameStats fst = sim.advance_frame();
    const int k = fst.frame;
    write_mesh_atomic(opt.out / frame_name(k, ext), sim.state().x, faces, ext);
    const std::string old_state = manifest["state_file"].get<std::string>();
    const int old_frame = manifest["complete_frames"].get<int>();
    const std::string sname = state_name(k);
    write_state_atomic(opt.out / sname, sim.state(), k);
    manifest["frames"].push_back(to_json(fst));
    manifest["complete_frames"] = k;
    manifest["state_file"] = sname;
    write_manifest(manifest_path, manifest);
    const bool keep = (opt.keep_states > 0 && old_frame % opt.keep_states == 0) ||
                      old_frame == opt.resume_at;    // the kept state a replay started from
    if (!keep) fs::remove(opt.out / old_state, ec);  // the manifest no longer points at it
    out.push_back(fst);
    if (opt.on_frame) opt.on_frame(fst, total);
    if (!fst.finite) {
      throw std::runtime_error(
          fmt::format("frame {}: the state is not finite (NaN or inf); "
                      "stopped, see {}",
                      k, manifest_path.string()));
    }
  }
  return out;
}

}  // namespace clothcd::sim
