// Scene JSON: parsing with strict validation (unknown keys, types, files), data-root expansion.
#include "clothcd/sim/scene.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <numbers>
#include <set>

#include "clothcd/core/error.hpp"
#include "clothcd/detect/names.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/sim/sewing.hpp"
#include "sim/scene_json.hpp"

namespace clothcd::sim {
namespace {

using nlohmann::json;

/// A JSON object being read: remembers the keys it was asked for, so unknown ones are errors.
class ObjectReader {
 public:
  ObjectReader(const json& j, std::string path, const std::filesystem::path& file)
      : j_(j), path_(std::move(path)), file_(file) {
    if (!j.is_object()) fail(path_, "expected an object");
  }

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw input_error(file_.string(), 0, fmt::format("'{}': {}", key, what));
  }
  std::string key(const std::string& k) const { return path_.empty() ? k : path_ + "." + k; }
  bool has(const std::string& k) {
    known_.insert(k);
    return j_.contains(k);
  }
  const json& get(const std::string& k) {
    if (!has(k)) fail(key(k), "missing");
    return j_.at(k);
  }
  double number(const std::string& k, double def, double lo = -INFINITY, double hi = INFINITY) {
    if (!has(k)) return def;
    const json& v = j_.at(k);
    if (!v.is_number()) fail(key(k), fmt::format("expected a number, got {}", v.dump()));
    const double d = v.get<double>();
    if (!(d >= lo && d <= hi)) fail(key(k), fmt::format("{} is outside [{}, {}]", d, lo, hi));
    return d;
  }
  int integer(const std::string& k, int def, int lo = 0, int hi = 1 << 30) {
    if (!has(k)) return def;
    const json& v = j_.at(k);
    if (!v.is_number_integer()) fail(key(k), fmt::format("expected an integer, got {}", v.dump()));
    const long long d = v.get<long long>();
    if (d < lo || d > hi) fail(key(k), fmt::format("{} is outside [{}, {}]", d, lo, hi));
    return static_cast<int>(d);
  }
  bool boolean(const std::string& k, bool def) {
    if (!has(k)) return def;
    const json& v = j_.at(k);
    if (!v.is_boolean()) fail(key(k), fmt::format("expected true or false, got {}", v.dump()));
    return v.get<bool>();
  }
  std::string string(const std::string& k, const std::string& def,
                     std::set<std::string> allowed = {}) {
    if (!has(k)) {
      if (def.empty() && allowed.empty()) fail(key(k), "missing");
      return def;
    }
    const json& v = j_.at(k);
    if (!v.is_string()) fail(key(k), fmt::format("expected a string, got {}", v.dump()));
    std::string s = v.get<std::string>();
    if (!allowed.empty() && !allowed.contains(s)) {
      fail(key(k), fmt::format("'{}' is not one of {}", s, fmt::join(allowed, ", ")));
    }
    return s;
  }
  Vec3 vec3(const std::string& k, const Vec3& def) {
    if (!has(k)) return def;
    const json& v = j_.at(k);
    if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() ||
        !v[2].is_number()) {
      fail(key(k), fmt::format("expected an array of 3 numbers, got {}", v.dump()));
    }
    return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
  }
  ObjectReader object(const std::string& k) { return ObjectReader(get(k), key(k), file_); }
  /// Throws on keys nobody asked for.
  void finish() const {
    for (const auto& [k, v] : j_.items()) {
      if (!known_.contains(k)) fail(key(k), "unknown key");
    }
  }
  const std::filesystem::path& file() const { return file_; }

 private:
  const json& j_;
  std::string path_;
  const std::filesystem::path& file_;
  std::set<std::string> known_;
};

std::string expand(std::string s, const std::filesystem::path& scene_file) {
  const std::string var = "${CLOTHCD_DATA}";
  for (std::size_t p = s.find(var); p != std::string::npos; p = s.find(var)) {
    s.replace(p, var.size(), data_root_for(scene_file).string());
  }
  return s;
}

std::filesystem::path resolve_path(ObjectReader& r, const std::string& k, bool must_exist = true) {
  const std::string raw = r.string(k, "");
  std::filesystem::path p = expand(raw, r.file());
  if (p.is_relative()) p = r.file().parent_path() / p;
  if (must_exist && !std::filesystem::exists(p)) {
    r.fail(r.key(k), fmt::format("file '{}' not found (from '{}'; set CLOTHCD_DATA to the shared "
                                 "data folder)",
                                 p.string(), raw));
  }
  return p;
}

struct GridInfo {
  int nu = 0, nv = 0;
};

GridInfo read_grid(ObjectReader g, ClothMeshInput& cloth) {
  const Vec3 origin = g.vec3("origin", Vec3::Zero());
  const Vec3 u = g.vec3("u", Vec3(1, 0, 0));
  const Vec3 v = g.vec3("v", Vec3(0, 0, 1));
  const json& res = g.get("resolution");
  // Each side is bounded before the product, which could otherwise overflow (and before get<int>,
  // which would narrow 2^32 + 1 to 1).
  auto side_ok = [](const json& x) {
    if (x.is_number_unsigned()) return x.get<std::uint64_t>() - 1 < 4'000'000;
    return x.is_number_integer() && x.get<std::int64_t>() >= 1 &&
           x.get<std::int64_t>() <= 4'000'000;
  };
  if (!res.is_array() || res.size() != 2 || !side_ok(res[0]) || !side_ok(res[1]) ||
      res[0].get<long long>() * res[1].get<long long>() > 4'000'000) {
    g.fail(g.key("resolution"), "expected [nu, nv], two positive integers (nu * nv <= 4e6)");
  }
  if (u.cross(v).norm() == 0.0) g.fail(g.key("u"), "u and v must span a plane");
  g.finish();
  GridInfo gi{res[0].get<int>(), res[1].get<int>()};
  for (int j = 0; j <= gi.nv; ++j) {
    for (int i = 0; i <= gi.nu; ++i) {
      cloth.positions.push_back(origin + u * (double(i) / gi.nu) + v * (double(j) / gi.nv));
    }
  }
  auto id = [&](int i, int j) { return j * (gi.nu + 1) + i; };
  for (int j = 0; j < gi.nv; ++j) {
    for (int i = 0; i < gi.nu; ++i) {
      if ((i + j) % 2 == 0) {
        cloth.faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        cloth.faces.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      } else {
        cloth.faces.push_back({id(i, j), id(i + 1, j), id(i, j + 1)});
        cloth.faces.push_back({id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      }
    }
  }
  return gi;
}

void read_obj_cloth(ObjectReader& c, ClothMeshInput& cloth) {
  const std::filesystem::path obj_path = resolve_path(c, "obj");
  TriangleMesh obj = read_obj(obj_path);
  const int nv = c.integer("vertices", obj.num_vertices(), 3, obj.num_vertices());
  obj.vertices.resize(nv);
  int nf = 0;
  while (nf < obj.num_faces() && obj.faces[nf][0] < nv && obj.faces[nf][1] < nv &&
         obj.faces[nf][2] < nv) {
    ++nf;
  }
  if (c.has("faces")) {
    const int want = c.integer("faces", nf, 1);
    if (want > nf) {
      c.fail(c.key("faces"), fmt::format("{}: only the first {} faces use vertices below {}",
                                         obj_path.string(), nf, nv));
    }
    nf = want;
  }
  obj.faces.resize(nf);
  const Vec3 t = c.vec3("translate", Vec3::Zero());
  for (Vec3& p : obj.vertices)
    p += t;
  cloth.positions = std::move(obj.vertices);
  cloth.faces = std::move(obj.faces);

  const std::string rest = c.string("rest", "initial", {"initial", "pattern"});
  const std::string stitches = c.string("stitches", "none", {"none", "pattern", "recover"});
  ObjContents pattern;
  if (rest == "pattern" || stitches == "pattern") {
    const std::filesystem::path pp = resolve_path(c, "pattern");
    pattern = read_obj_with_stitches(pp);
    if (pattern.mesh.num_vertices() != nv) {
      c.fail(c.key("pattern"), fmt::format("{} has {} vertices, the cloth has {}", pp.string(),
                                           pattern.mesh.num_vertices(), nv));
    }
    if (rest == "pattern") {
      if (pattern.mesh.faces.size() != cloth.faces.size()) {
        c.fail(c.key("pattern"), fmt::format("{} has {} faces, the cloth has {}", pp.string(),
                                             pattern.mesh.faces.size(), cloth.faces.size()));
      }
      cloth.pattern.assign(nv, Vec2::Zero());
      std::vector<bool> seen(nv, false);
      for (std::size_t f = 0; f < pattern.mesh.faces.size(); ++f) {
        for (int k = 0; k < 3; ++k) {
          const int v = pattern.mesh.faces[f][k], vt = pattern.face_texcoords[f][k];
          if (vt < 0 || v != cloth.faces[f][k]) {
            c.fail(c.key("pattern"), fmt::format("{}: face {} must match the cloth's face and "
                                                 "carry texture coordinates",
                                                 pp.string(), f + 1));
          }
          cloth.pattern[v] = pattern.texcoords[vt];
          seen[v] = true;
        }
      }
    }
    if (stitches == "pattern") {
      if (pattern.stitches.empty()) c.fail(c.key("pattern"), pp.string() + " has no stitch lines");
      for (const clothcd::Stitch& st : pattern.stitches)
        cloth.stitches.push_back({st.i, st.j, st.k, st.r});
    }
  }
  const double recover = c.number("recover_distance", 1e-3, 0.0, 0.1);
  if (stitches == "recover")
    cloth.stitches = recover_stitches(cloth.positions, cloth.faces, recover);
}

std::vector<int> grid_edge(ObjectReader& p, const std::string& which, const GridInfo& g) {
  if (g.nu == 0) p.fail(p.key("grid_edge"), "only for a grid cloth");
  std::vector<int> vs;
  auto id = [&](int i, int j) { return j * (g.nu + 1) + i; };
  if (which == "u0" || which == "u1") {
    const int i = which == "u0" ? 0 : g.nu;
    for (int j = 0; j <= g.nv; ++j)
      vs.push_back(id(i, j));
  } else {
    const int j = which == "v0" ? 0 : g.nv;
    for (int i = 0; i <= g.nu; ++i)
      vs.push_back(id(i, j));
  }
  return vs;
}

}  // namespace

int SubstepRule::count(double body_displacement, double cloth_displacement_estimate) const {
  double n = std::ceil(body_displacement / displacement);
  if (cloth_displacement > 0) {
    n = std::max(n, std::ceil(cloth_displacement_estimate / cloth_displacement));
  }
  if (!(n >= min)) return min;  // also NaN
  return n > max ? max : static_cast<int>(n);
}

double SubstepRule::cloth_speed(std::span<const Vec3> v) const {
  if (v.empty()) return 0.0;
  std::vector<double> s(v.size());
  for (std::size_t i = 0; i < v.size(); ++i)
    s[i] = v[i].norm();
  const double rank = std::ceil(cloth_speed_quantile * static_cast<double>(s.size()));
  const std::size_t k = rank >= 1.0 ? static_cast<std::size_t>(rank) - 1 : 0;
  const auto at = s.begin() + static_cast<std::ptrdiff_t>(std::min(k, s.size() - 1));
  std::nth_element(s.begin(), at, s.end());
  return *at;
}

std::filesystem::path data_root_for(const std::filesystem::path& scene_file) {
  if (const char* env = std::getenv("CLOTHCD_DATA"); env != nullptr && *env != '\0') return env;
  const std::filesystem::path dir = std::filesystem::absolute(scene_file).parent_path();
  return (dir.parent_path().parent_path() / "shared" / "data").lexically_normal();
}

Scene load_scene(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw input_error(file.string(), 0, "cannot open scene file");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parse_scene_text(text, file);
}

Scene parse_scene_text(std::string_view json_text, const std::filesystem::path& file) {
  json j;
  try {
    j = json::parse(json_text);
  } catch (const json::exception& e) {
    // Not only parse_error: a number beyond double's range is an out_of_range (found by
    // fuzz_scene).
    throw input_error(file.string(), 0, fmt::format("invalid JSON: {}", e.what()));
  }
  return parse_scene(j, file);
}

Scene parse_scene(const json& j, const std::filesystem::path& file) {
  Scene s;
  s.file = file;
  ObjectReader top(j, "", file);
  s.name = top.string("name", "");
  s.frames = top.integer("frames", 120, 1, 1'000'000);
  s.frame_dt = top.number("frame_dt", 0.04, 1e-6, 10.0);
  s.solver.gravity = top.vec3("gravity", s.solver.gravity);

  ObjectReader c = top.object("cloth");
  GridInfo grid;
  if (c.has("grid")) {
    if (c.has("obj")) c.fail(c.key("obj"), "give either 'grid' or 'obj', not both");
    grid = read_grid(c.object("grid"), s.cloth);
  } else {
    read_obj_cloth(c, s.cloth);
  }
  c.finish();

  if (top.has("material")) {
    ObjectReader m = top.object("material");
    ClothMaterial& mat = s.material;
    mat.area_density = m.number("area_density", mat.area_density, 1e-9, 1e6);
    mat.stretch_stiffness = m.number("stretch_stiffness", mat.stretch_stiffness, 0.0, 1e12);
    mat.poisson = m.number("poisson", mat.poisson, 0.0, 0.49);
    mat.bending_stiffness = m.number("bending_stiffness", mat.bending_stiffness, 0.0, 1e6);
    mat.damping = m.number("damping", mat.damping, 0.0, 10.0);
    mat.friction = m.number("friction", mat.friction, 0.0, 10.0);
    mat.stitch_stiffness = m.number("stitch_stiffness", mat.stitch_stiffness, 0.0, 1e12);
    mat.cot_clamp = m.number("cot_clamp", mat.cot_clamp, 0.0, 1e6);
    mat.sliver_area_ratio = m.number("sliver_area_ratio", mat.sliver_area_ratio, 0.0, 1.0);
    mat.sliver_min_angle_deg =
        m.number("sliver_min_angle_deg", mat.sliver_min_angle_deg, 0.0, 60.0);
    mat.strain_limit = m.number("strain_limit", mat.strain_limit, 0.0, 100.0);
    if (mat.strain_limit != 0.0 && mat.strain_limit < 1.0) {
      m.fail(m.key("strain_limit"),
             fmt::format("expected 0 (off) or at least 1, got {}", mat.strain_limit));
    }
    mat.compression_limit = m.number("compression_limit", mat.compression_limit, 0.0, 1.0);
    m.finish();
  }
  if (top.has("solver")) {
    ObjectReader o = top.object("solver");
    s.solver.pcg_max_iterations = o.integer("pcg_max_iterations", s.solver.pcg_max_iterations, 1);
    s.solver.pcg_tolerance = o.number("pcg_tolerance", s.solver.pcg_tolerance, 0.0, 1.0);
    s.solver.release_tolerance =
        o.number("release_tolerance", s.solver.release_tolerance, 0.0, 1.0);
    s.solver.fast_pcg_tolerance =
        o.number("fast_pcg_tolerance", s.solver.fast_pcg_tolerance, 0.0, 1.0);
    s.solver.coarse_aggregate = o.integer("coarse_aggregate", s.solver.coarse_aggregate, 0);
    if (s.solver.coarse_aggregate == 1) {
      o.fail(o.key("coarse_aggregate"), "expected 0 (off) or at least 2, got 1");
    }
    s.solver.halve_residual = o.number("halve_residual", s.solver.halve_residual, 0.0, INFINITY);
    s.solver.max_halvings = o.integer("max_halvings", s.solver.max_halvings, 0, 10);
    s.solver.halve_unresolved = o.boolean("halve_unresolved", s.solver.halve_unresolved);
    s.solver.strain_sweeps = o.integer("strain_sweeps", s.solver.strain_sweeps, 1, 10000);
    s.solver.strain_ccd_passes =
        o.integer("strain_ccd_passes", s.solver.strain_ccd_passes, 0, 1000);
    s.solver.strain_ccd_sweeps =
        o.integer("strain_ccd_sweeps", s.solver.strain_ccd_sweeps, 1, 10000);
    // A solve that may stop above halve_residual would have every substep halved.
    for (const auto& [k, tolerance] :
         {std::pair{"pcg_tolerance", s.solver.pcg_tolerance},
          std::pair{"fast_pcg_tolerance", s.solver.fast_pcg_tolerance}}) {
      if (s.solver.max_halvings > 0 && tolerance > s.solver.halve_residual) {
        o.fail(o.key(k), fmt::format("{} is above halve_residual ({}): every substep would be "
                                     "halved (raise halve_residual or set max_halvings 0)",
                                     tolerance, s.solver.halve_residual));
      }
    }
    o.finish();
  }
  if (top.has("substeps")) {
    ObjectReader o = top.object("substeps");
    s.substeps.min = o.integer("min", s.substeps.min, 1, 10000);
    s.substeps.max = o.integer("max", s.substeps.max, s.substeps.min, 10000);
    s.substeps.displacement = o.number("displacement", s.substeps.displacement, 1e-9, 1e6);
    s.substeps.cloth_displacement =
        o.number("cloth_displacement", s.substeps.cloth_displacement, 0.0, 1e6);
    s.substeps.cloth_speed_quantile =
        o.number("cloth_speed_quantile", s.substeps.cloth_speed_quantile, 1e-6, 1.0);
    o.finish();
  }
  if (top.has("body")) {
    ObjectReader b = top.object("body");
    const std::string type = b.string("type", "", {"frames", "sphere"});
    if (type == "frames") {
      const std::string pattern = b.string("frames", "");
      if (pattern.find("{}") == std::string::npos) {
        b.fail(b.key("frames"), "expected a path with '{}' standing for the frame number");
      }
      const int first = b.integer("first", 0, 0);
      const int count = b.integer("count", 0, 1);
      std::vector<std::filesystem::path> paths;
      for (int k = 0; k < count; ++k) {
        std::string p = pattern;
        p.replace(p.find("{}"), 2, std::to_string(first + k));
        std::filesystem::path fp = expand(p, file);
        if (fp.is_relative()) fp = file.parent_path() / fp;
        if (!std::filesystem::exists(fp)) {
          b.fail(b.key("frames"), fmt::format("frame file '{}' not found (set CLOTHCD_DATA to the "
                                              "shared data folder)",
                                              fp.string()));
        }
        paths.push_back(fp);
      }
      s.body = std::make_unique<MeshSequenceBody>(std::move(paths), s.frame_dt,
                                                  b.vec3("translate", Vec3::Zero()));
    } else {
      SphereMotion m;
      m.center = b.vec3("center", m.center);
      m.radius = b.number("radius", m.radius, 1e-6, 1e6);
      m.velocity = b.vec3("velocity", m.velocity);
      m.spin_axis = b.vec3("spin_axis", m.spin_axis);
      if (m.spin_axis.norm() == 0.0) b.fail(b.key("spin_axis"), "must be nonzero");
      m.spin_rate = b.number("spin_deg_per_s", 0.0) * std::numbers::pi / 180.0;
      m.spin_start = b.number("spin_start", 0.0, 0.0);
      s.body = std::make_unique<SphereBody>(m, b.integer("subdivisions", 3, 0, 7));
    }
    b.finish();
  }
  if (top.has("pins")) {
    const json& arr = top.get("pins");
    if (!arr.is_array()) top.fail("pins", "expected an array of pin objects");
    const int n = static_cast<int>(s.cloth.positions.size());
    for (std::size_t k = 0; k < arr.size(); ++k) {
      ObjectReader p(arr[k], fmt::format("pins[{}]", k), file);
      PinGroup g;
      if (p.has("grid_edge")) {
        g.vertices = grid_edge(p, p.string("grid_edge", "", {"u0", "u1", "v0", "v1"}), grid);
      } else {
        const json& vs = p.get("vertices");
        if (!vs.is_array()) p.fail(p.key("vertices"), "expected an array of vertex ids");
        for (const json& v : vs) {
          if (!v.is_number_integer() || v.get<long long>() < 0 || v.get<long long>() >= n) {
            p.fail(p.key("vertices"),
                   fmt::format("{} is not a vertex id in 0..{}", v.dump(), n - 1));
          }
          g.vertices.push_back(v.get<int>());
        }
      }
      Vec3 centroid = Vec3::Zero();
      for (int v : g.vertices)
        centroid += s.cloth.positions[v];
      if (!g.vertices.empty()) centroid /= static_cast<double>(g.vertices.size());
      g.center = p.vec3("center", centroid);
      g.axis = p.vec3("axis", Vec3::UnitY());
      if (g.axis.norm() == 0.0) p.fail(p.key("axis"), "must be nonzero");
      g.angular_velocity = p.number("deg_per_s", 0.0) * std::numbers::pi / 180.0;
      g.velocity = p.vec3("velocity", Vec3::Zero());
      p.finish();
      s.pins.push_back(std::move(g));
    }
  }
  if (top.has("collisions")) {
    ObjectReader o = top.object("collisions");
    ContactOptions& c = s.contact;
    s.collisions = o.boolean("enabled", true);
    c.self = o.boolean("self", c.self);
    c.body = o.boolean("body", c.body);
    c.thickness = o.number("thickness", c.thickness, 0.0, 1.0);
    c.ccd_thickness = o.number("ccd_thickness", c.ccd_thickness, 0.0, 1.0);
    c.ccd_iterations = o.integer("ccd_iterations", c.ccd_iterations, 1, 1000);
    c.zone_rounds = o.integer("zone_rounds", c.zone_rounds, 0, 10000);
    c.repulsion_fraction = o.number("repulsion_fraction", c.repulsion_fraction, 0.0, 1.0);
    c.repulsion_sweeps = o.integer("repulsion_sweeps", c.repulsion_sweeps, 1, 1000);
    c.pointwise_repulsion = o.boolean("pointwise_repulsion", c.pointwise_repulsion);
    c.body_constraints = o.boolean("body_constraints", c.body_constraints);
    c.coupled_contacts = o.boolean("coupled_contacts", c.coupled_contacts);
    c.full_passes = o.boolean("full_passes", c.full_passes);
    c.untangle_step = o.number("untangle_step", c.untangle_step, 0.0, 1.0);
    // Only the exact settings: a simulator must not lose collisions to an unsound rule.
    c.culling =
        parse_culling(o.string("culling", std::string(to_string(c.culling)), {"none", "sound"}));
    c.cone_policy = parse_cone_policy(o.string("cone_policy", std::string(to_string(c.cone_policy)),
                                               {"provot", "proposed", "exact"}));
    c.cull_min_triangles = o.integer("cull_min_triangles", c.cull_min_triangles);
    c.reuse_front = o.boolean("reuse_front", c.reuse_front);
    c.affine_zones = o.string("zone_motion", c.affine_zones ? "affine" : "rigid",
                              {"rigid", "affine"}) == "affine";
    s.repair_initial_crossings = o.boolean("repair_initial_crossings", s.repair_initial_crossings);
    s.count_intersections = o.boolean("count_intersections", s.count_intersections);
    o.finish();
  }
  s.contact.friction = s.material.friction;
  if (top.has("output")) {
    ObjectReader o = top.object("output");
    s.output_format = o.string("format", "obj", {"obj", "ply"});
    o.finish();
  }
  top.finish();
  return s;
}

}  // namespace clothcd::sim
