// The page of one detection step: both frames at full single precision (two frames need no
// differences), the hits of the result and, per face, whether a hit involves it.
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <map>

#include "clothcd/core/error.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/mesh/topology.hpp"
#include "clothcd/view/page.hpp"
#include "view/page_builder.hpp"

namespace clothcd::view {
namespace {

namespace fs = std::filesystem;

std::vector<float> as_floats(const std::vector<Vec3>& x) {
  std::vector<float> out;
  out.reserve(x.size() * 3);
  for (const Vec3& p : x)
    for (int a = 0; a < 3; ++a)
      out.push_back(static_cast<float>(p[a]));
  return out;
}

struct Hits {
  std::vector<std::uint8_t> kind;   // 0: vertex-face, 1: edge-edge
  std::vector<std::int32_t> verts;  // 4 per hit: v, f0, f1, f2 or a0, a1, b0, b1
  std::vector<float> toi;
};

// Reads the `vf` and `ee` lists of a `clothcd detect --json` result, checking every id against
// the mesh. `where` names the file in messages.
Hits read_hits(const nlohmann::json& j, const std::string& where, int num_vertices) {
  Hits h;
  auto vertex = [&](const nlohmann::json& v, const char* list, std::size_t i) {
    if (!v.is_number_integer() || v.get<long long>() < 0 || v.get<long long>() >= num_vertices) {
      throw input_error(where, 0,
                        fmt::format("{}[{}]: vertex {} is not a vertex of the meshes ({} vertices)",
                                    list, i, v.dump(), num_vertices));
    }
    return v.get<std::int32_t>();
  };
  auto toi = [&](const nlohmann::json& e, const char* list, std::size_t i) {
    if (!e.contains("toi") || !e.at("toi").is_number() || e.at("toi") < 0 || e.at("toi") > 1)
      throw input_error(where, 0, fmt::format("{}[{}]: 'toi' is not a number in [0, 1]", list, i));
    return e.at("toi").get<float>();
  };
  auto ids = [&](const nlohmann::json& e, const char* key, std::size_t count, const char* list,
                 std::size_t i) -> const nlohmann::json& {
    if (!e.is_object() || !e.contains(key) || !e.at(key).is_array() || e.at(key).size() != count)
      throw input_error(
          where, 0,
          fmt::format("{}[{}]: '{}' is not a list of {} vertex ids", list, i, key, count));
    return e.at(key);
  };
  for (const char* list : {"vf", "ee"}) {
    if (!j.contains(list)) continue;
    if (!j.at(list).is_array())
      throw input_error(where, 0, fmt::format("'{}' is not a list", list));
    const auto& a = j.at(list);
    for (std::size_t i = 0; i < a.size(); ++i) {
      const nlohmann::json& e = a[i];
      if (list[0] == 'v') {
        const auto& f = ids(e, "face", 3, list, i);
        if (!e.contains("vertex"))
          throw input_error(where, 0, fmt::format("vf[{}]: no 'vertex'", i));
        h.kind.push_back(0);
        h.verts.push_back(vertex(e.at("vertex"), list, i));
        for (int k = 0; k < 3; ++k)
          h.verts.push_back(vertex(f[k], list, i));
      } else {
        const auto& ea = ids(e, "edge_a", 2, list, i);
        const auto& eb = ids(e, "edge_b", 2, list, i);
        h.kind.push_back(1);
        for (const auto* edge : {&ea, &eb})
          for (int k = 0; k < 2; ++k)
            h.verts.push_back(vertex((*edge)[k], list, i));
      }
      h.toi.push_back(toi(e, list, i));
    }
  }
  return h;
}

// 1: a face of some vertex-face hit or around its vertex; 2: beside an edge of an edge-edge hit;
// 3: both. Ids of a welded run (`--weld`) may name no face of the input: those hits mark only
// what exists.
std::vector<std::uint8_t> hit_faces(const TriangleMesh& mesh, const Hits& h) {
  const Topology topo(mesh.faces, static_cast<int>(mesh.vertices.size()));
  std::map<std::array<int, 3>, int> face_of;
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    std::array<int, 3> key{mesh.faces[f][0], mesh.faces[f][1], mesh.faces[f][2]};
    std::sort(key.begin(), key.end());
    face_of.emplace(key, static_cast<int>(f));
  }
  std::vector<std::vector<int>> vertex_faces(mesh.vertices.size());
  for (std::size_t f = 0; f < mesh.faces.size(); ++f)
    for (int v : mesh.faces[f])
      vertex_faces[v].push_back(static_cast<int>(f));
  std::vector<std::uint8_t> flags(mesh.faces.size(), 0);
  for (std::size_t i = 0; i < h.kind.size(); ++i) {
    const std::int32_t* v = &h.verts[i * 4];
    if (h.kind[i] == 0) {
      std::array<int, 3> key{v[1], v[2], v[3]};
      std::sort(key.begin(), key.end());
      if (auto it = face_of.find(key); it != face_of.end()) flags[it->second] |= 1;
      for (int f : vertex_faces[v[0]])
        flags[f] |= 1;
    } else {
      for (int k : {0, 2}) {
        const int e = topo.find_edge(v[k], v[k + 1]);
        if (e < 0) continue;
        for (int f : topo.edge_faces(e))
          flags[f] |= 2;
      }
    }
  }
  return flags;
}

}  // namespace

PageSummary write_detection_page(const fs::path& t0, const fs::path& t1,
                                 const fs::path& result_json, const fs::path& out) {
  const TriangleMesh a = read_mesh(t0);
  const TriangleMesh b = read_mesh(t1);
  if (a.vertices.size() != b.vertices.size() || a.faces != b.faces) {
    throw input_error(t1.string(), 0,
                      fmt::format("topology differs from {} ({} vertices, {} faces here; {} and "
                                  "{} there): expected the two frames of one step",
                                  t0.string(), b.vertices.size(), b.faces.size(), a.vertices.size(),
                                  a.faces.size()));
  }
  std::ifstream in(result_json);
  if (!in) throw input_error(result_json.string(), 0, "cannot open");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw input_error(result_json.string(), 0, fmt::format("invalid JSON: {}", e.what()));
  }
  if (!j.is_object() || (!j.contains("vf") && !j.contains("ee"))) {
    throw input_error(result_json.string(), 0,
                      "has neither 'vf' nor 'ee' (expected the output of `clothcd detect --json`)");
  }
  const Hits hits = read_hits(j, result_json.string(), static_cast<int>(a.vertices.size()));

  detail::DataBlock block;
  std::vector<std::uint32_t> faces;
  faces.reserve(a.faces.size() * 3);
  for (const Face& f : a.faces)
    for (int v : f)
      faces.push_back(static_cast<std::uint32_t>(v));
  block.add("faces", std::span<const std::uint32_t>(faces));
  block.add("t0", std::span<const float>(as_floats(a.vertices)));
  block.add("t1", std::span<const float>(as_floats(b.vertices)));
  block.add("hit_kind", std::span<const std::uint8_t>(hits.kind));
  block.add("hit_vertices", std::span<const std::int32_t>(hits.verts));
  block.add("hit_toi", std::span<const float>(hits.toi));
  block.add("hit_faces", std::span<const std::uint8_t>(hit_faces(a, hits)));

  nlohmann::json meta = {{"kind", "detection"},
                         {"title", fmt::format("clothcd view: {} -> {}", t0.filename().string(),
                                               t1.filename().string())},
                         {"t0", t0.filename().string()},
                         {"t1", t1.filename().string()},
                         {"result", result_json.filename().string()},
                         {"vertices", a.vertices.size()},
                         {"faces", a.faces.size()},
                         {"stats", j.value("stats", nlohmann::json::object())}};
  for (const char* key : {"missed_vf", "missed_ee"}) {
    if (j.contains(key) && j.at(key).is_array()) meta[key] = j.at(key).size();
  }
  PageSummary summary;
  summary.frames = 2;
  summary.hits = static_cast<int>(hits.kind.size());
  detail::write_page(out, std::move(meta), block, summary);
  return summary;
}

}  // namespace clothcd::view
