// OBJ reading with line-level validation, and OBJ writing.
//
// A strict line scanner in double precision: lenient readers turn a non-numeric coordinate into 0
// or pad a short `v` line, which would hide broken files.

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "clothcd/core/error.hpp"
#include "clothcd/mesh/io.hpp"
#include "io_util.hpp"

namespace clothcd {
namespace {

using io_detail::parse_double;
using io_detail::parse_int;

// Splits a line into whitespace-separated tokens (at most `max` kept; the count is exact).
struct Tokens {
  static constexpr int kMax = 64;
  std::string_view items[kMax];
  int count = 0;
};

void tokenize(std::string_view line, Tokens& t) {
  t.count = 0;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r'))
      ++i;
    if (i >= line.size()) break;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r')
      ++i;
    if (t.count < Tokens::kMax) t.items[t.count] = line.substr(start, i - start);
    ++t.count;
  }
}

// A reference to a vertex used before its `v` line, checked once all vertices are known.
struct Pending {
  std::size_t line;
  long long index;  // 0-based, already resolved
};

class ObjParser {
 public:
  explicit ObjParser(std::string file, bool vertices_only = false)
      : file_(std::move(file)), vertices_only_(vertices_only) {}

  ObjContents parse(std::string_view text) {
    std::size_t pos = 0;
    while (pos < text.size()) {
      std::size_t end = text.find('\n', pos);
      if (end == std::string_view::npos) end = text.size();
      ++line_;
      parse_line(text.substr(pos, end - pos));
      pos = end + 1;
    }
    const long long nv = static_cast<long long>(out_.mesh.vertices.size());
    for (const Pending& p : pending_) {
      if (p.index >= nv) {
        throw error(p.line, fmt::format("vertex index {} is out of range: the file has {} vertices",
                                        p.index + 1, nv));
      }
    }
    const long long nt = static_cast<long long>(out_.texcoords.size());
    for (const Pending& p : pending_texcoords_) {
      if (p.index >= nt) {
        throw error(p.line, fmt::format("texture index {} is out of range: the file has {} texture "
                                        "coordinates",
                                        p.index + 1, nt));
      }
    }
    if (vertices_only_) return std::move(out_);
    for (const auto& [line, s] : stitch_lines_) {
      for (int v : {s.i, s.j, s.k}) {
        if (v >= nv) {
          throw error(line, fmt::format("stitch vertex {} is out of range, expected 0 <= index < "
                                        "{} (stitch indices are 0-based)",
                                        v, nv));
        }
      }
      out_.stitches.push_back(s);
    }
    if (out_.mesh.faces.empty()) {
      throw input_error(
          file_, 0, fmt::format("contains no faces ({} vertices): expected a triangle mesh", nv));
    }
    return std::move(out_);
  }

 private:
  InputError error(std::size_t line, std::string_view what) const {
    return input_error(file_, line, what);
  }

  void parse_line(std::string_view line) {
    if (vertices_only_) {
      // Only `v` lines count: skip the others before scanning them (an animation frame is
      // mostly faces). What passes here is a `v` line.
      const std::size_t first = line.find_first_not_of(" \t");
      if (first == std::string_view::npos || line[first] != 'v' || first + 1 >= line.size() ||
          (line[first + 1] != ' ' && line[first + 1] != '\t')) {
        return;
      }
    }
    if (line.find('\0') != std::string_view::npos) {
      throw error(line_, "contains a NUL byte: expected a text OBJ file");
    }
    if (const auto hash = line.find('#'); hash != std::string_view::npos) {
      line = line.substr(0, hash);
    }
    tokenize(line, tokens_);
    if (tokens_.count == 0) return;
    const std::string_view key = tokens_.items[0];
    if (key == "v") {
      parse_vertex();
    } else if (key == "vt") {
      parse_texcoord();
    } else if (key == "f") {
      parse_face();
    } else if (key == "stitch") {
      parse_stitch();
    }
    // Other statements (vn, g, o, s, usemtl, l, seam, ...) carry nothing a collision detector
    // or the simulator needs.
  }

  void parse_texcoord() {
    // u v, optionally w.
    if (tokens_.count < 3 || tokens_.count > 4) {
      throw error(line_, fmt::format("texture coordinate line has {} numbers, expected 2 (u v)",
                                     tokens_.count - 1));
    }
    double uv[3];
    for (int i = 1; i < tokens_.count; ++i) {
      if (!parse_double(tokens_.items[i], uv[i - 1])) {
        throw error(line_,
                    fmt::format("texture coordinate '{}' is not a number", tokens_.items[i]));
      }
      if (!std::isfinite(uv[i - 1])) {
        throw error(line_, fmt::format("texture coordinate '{}' is not finite", tokens_.items[i]));
      }
    }
    out_.texcoords.emplace_back(uv[0], uv[1]);
  }

  void parse_vertex() {
    // x y z, optionally w or a colour; every token must be a finite number.
    if (tokens_.count < 4 || tokens_.count > 7) {
      throw error(line_,
                  fmt::format("vertex line has {} numbers, expected 3 (x y z)", tokens_.count - 1));
    }
    double xyz[3];
    for (int i = 1; i < tokens_.count; ++i) {
      double value = 0;
      if (!parse_double(tokens_.items[i], value)) {
        throw error(line_, fmt::format("vertex coordinate '{}' is not a number", tokens_.items[i]));
      }
      if (!std::isfinite(value)) {
        throw error(line_, fmt::format("vertex coordinate '{}' is not finite", tokens_.items[i]));
      }
      if (i <= 3) xyz[i - 1] = value;
    }
    if (out_.mesh.vertices.size() >= static_cast<std::size_t>(std::numeric_limits<int>::max())) {
      throw error(line_, "too many vertices for 32-bit indices");
    }
    out_.mesh.vertices.emplace_back(xyz[0], xyz[1], xyz[2]);
  }

  // A corner's vertex index (resolved, 0-based) and its texture index (-1 when it names none).
  struct Corner {
    int vertex;
    int texcoord;
  };

  // A 1-based or relative (negative) OBJ index against `count` items so far; an absolute index
  // past them is checked once the file is read (`pending`).
  int resolve(long long index, long long count, const char* what, std::vector<Pending>& pending) {
    if (index == 0) {
      throw error(line_, fmt::format("{} index 0 is invalid: OBJ indices start at 1", what));
    }
    if (index < 0) {
      // Relative reference: -1 is the latest one.
      if (-index > count) {
        throw error(line_, fmt::format("relative {0} index {1} reaches before the first {0} ({2} "
                                       "defined so far)",
                                       what, index, count));
      }
      return static_cast<int>(count + index);
    }
    if (index > std::numeric_limits<int>::max()) {
      throw error(line_, fmt::format("{} index {} is out of range", what, index));
    }
    if (index > count) pending.push_back({line_, index - 1});
    return static_cast<int>(index - 1);
  }

  Corner vertex_reference(std::string_view token) {
    // v, v/t, v//n or v/t/n: v and t matter, but every part must be an integer.
    std::string_view parts[3];
    int num_parts = 0;
    std::size_t start = 0;
    while (true) {
      const std::size_t slash = token.find('/', start);
      if (num_parts == 3) {
        throw error(line_, fmt::format("face corner '{}' has too many '/' parts", token));
      }
      parts[num_parts++] = token.substr(
          start, slash == std::string_view::npos ? std::string_view::npos : slash - start);
      if (slash == std::string_view::npos) break;
      start = slash + 1;
    }
    long long index = 0;
    if (!parse_int(parts[0], index)) {
      throw error(line_, fmt::format("face corner '{}' is not a vertex index (an integer)", token));
    }
    long long texture = 0;  // 0: none
    for (int p = 1; p < num_parts; ++p) {
      long long value = 0;
      if (!(parts[p].empty() && p == 1 && num_parts == 3) && !parse_int(parts[p], value)) {
        throw error(line_, fmt::format("face corner '{}' is malformed", token));
      }
      if (p == 1) texture = value;
    }
    Corner c{};
    c.vertex =
        resolve(index, static_cast<long long>(out_.mesh.vertices.size()), "vertex", pending_);
    c.texcoord = num_parts >= 2 && !parts[1].empty()
                     ? resolve(texture, static_cast<long long>(out_.texcoords.size()), "texture",
                               pending_texcoords_)
                     : -1;
    return c;
  }

  void parse_face() {
    const int corners = tokens_.count - 1;
    if (corners < 3) {
      throw error(line_, fmt::format("face has {} corners, expected at least 3", corners));
    }
    if (corners > Tokens::kMax - 1) {
      throw error(line_, fmt::format("face has {} corners, at most {} supported", corners,
                                     Tokens::kMax - 1));
    }
    int ids[Tokens::kMax], tex[Tokens::kMax];
    for (int c = 0; c < corners; ++c) {
      const Corner corner = vertex_reference(tokens_.items[c + 1]);
      ids[c] = corner.vertex;
      tex[c] = corner.texcoord;
    }
    for (int a = 0; a < corners; ++a) {
      for (int b = a + 1; b < corners; ++b) {
        if (ids[a] == ids[b]) {
          throw error(
              line_, fmt::format("face repeats vertex {}, expected distinct vertices", ids[a] + 1));
        }
      }
    }
    for (int c = 1; c + 1 < corners; ++c) {
      out_.mesh.faces.push_back({ids[0], ids[c], ids[c + 1]});
      out_.face_texcoords.push_back({tex[0], tex[c], tex[c + 1]});
    }
  }

  void parse_stitch() {
    if (tokens_.count != 5) {
      throw error(
          line_, fmt::format("stitch line has {} values, expected 4 (i j k r)", tokens_.count - 1));
    }
    int idx[3];
    for (int t = 0; t < 3; ++t) {
      if (!parse_int(tokens_.items[t + 1], idx[t]) || idx[t] < 0) {
        throw error(line_, fmt::format("stitch vertex '{}' is not a non-negative integer (0-based)",
                                       tokens_.items[t + 1]));
      }
    }
    double r = 0;
    if (!parse_double(tokens_.items[4], r) || !(r >= 0.0 && r <= 1.0)) {
      throw error(line_,
                  fmt::format("stitch weight '{}' is not a number in [0, 1]", tokens_.items[4]));
    }
    if (idx[1] == idx[2]) {
      throw error(line_, fmt::format("stitch edge ({}, {}) repeats a vertex", idx[1], idx[2]));
    }
    stitch_lines_.push_back({line_, Stitch{idx[0], idx[1], idx[2], r}});
  }

  std::string file_;
  bool vertices_only_ = false;
  std::size_t line_ = 0;
  Tokens tokens_;
  ObjContents out_;
  std::vector<Pending> pending_, pending_texcoords_;
  std::vector<std::pair<std::size_t, Stitch>> stitch_lines_;
};

}  // namespace

ObjContents read_obj_with_stitches(const std::filesystem::path& path) {
  const std::string text = io_detail::read_file(path);
  return ObjParser(path.string()).parse(text);
}

TriangleMesh read_obj(const std::filesystem::path& path) {
  return read_obj_with_stitches(path).mesh;
}

std::vector<Eigen::Vector3d> read_obj_vertices(const std::filesystem::path& path) {
  const std::string text = io_detail::read_file(path);
  return ObjParser(path.string(), true).parse(text).mesh.vertices;
}

void write_obj(const std::filesystem::path& path, const TriangleMesh& mesh) {
  validate_mesh(mesh, path.string());
  io_detail::write_atomically(path, [&](std::ostream& out) {
    fmt::memory_buffer buf;
    const auto flush = [&] {
      out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
      buf.clear();
    };
    fmt::format_to(std::back_inserter(buf), "# clothcd: {} vertices, {} faces\n",
                   mesh.num_vertices(), mesh.num_faces());
    // fmt's default format is the shortest decimal that reads back to the same double.
    for (const auto& v : mesh.vertices) {
      fmt::format_to(std::back_inserter(buf), "v {} {} {}\n", v.x(), v.y(), v.z());
      if (buf.size() > (1u << 16)) flush();
    }
    for (const auto& f : mesh.faces) {
      fmt::format_to(std::back_inserter(buf), "f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
      if (buf.size() > (1u << 16)) flush();
    }
    flush();
  });
}

}  // namespace clothcd
