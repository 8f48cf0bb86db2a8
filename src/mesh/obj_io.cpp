// OBJ reading with line-level validation, and OBJ writing.
//
// A strict line scanner in double precision: lenient readers turn a non-numeric coordinate into 0
// or pad a short `v` line, which would hide broken files.

#include <fmt/format.h>

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
  explicit ObjParser(std::string file) : file_(std::move(file)) {}

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
    } else if (key == "f") {
      parse_face();
    } else if (key == "stitch") {
      parse_stitch();
    }
    // Other statements (vt, vn, g, o, s, usemtl, l, seam, ...) carry nothing a collision
    // detector needs.
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

  int vertex_reference(std::string_view token) {
    // v, v/t, v//n or v/t/n: only v matters, but every part must be an integer.
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
    for (int p = 1; p < num_parts; ++p) {
      long long ignored = 0;
      if (!(parts[p].empty() && p == 1 && num_parts == 3) && !parse_int(parts[p], ignored)) {
        throw error(line_, fmt::format("face corner '{}' is malformed", token));
      }
    }
    const long long nv = static_cast<long long>(out_.mesh.vertices.size());
    if (index == 0) throw error(line_, "vertex index 0 is invalid: OBJ indices start at 1");
    if (index < 0) {
      // Relative reference: -1 is the latest vertex.
      if (-index > nv) {
        throw error(line_, fmt::format("relative vertex index {} reaches before the first vertex "
                                       "({} vertices defined so far)",
                                       index, nv));
      }
      return static_cast<int>(nv + index);
    }
    if (index > std::numeric_limits<int>::max()) {
      throw error(line_, fmt::format("vertex index {} is out of range", index));
    }
    if (index > nv) pending_.push_back({line_, index - 1});
    return static_cast<int>(index - 1);
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
    int ids[Tokens::kMax];
    for (int c = 0; c < corners; ++c)
      ids[c] = vertex_reference(tokens_.items[c + 1]);
    for (int a = 0; a < corners; ++a) {
      for (int b = a + 1; b < corners; ++b) {
        if (ids[a] == ids[b]) {
          throw error(
              line_, fmt::format("face repeats vertex {}, expected distinct vertices", ids[a] + 1));
        }
      }
    }
    for (int c = 1; c + 1 < corners; ++c)
      out_.mesh.faces.push_back({ids[0], ids[c], ids[c + 1]});
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
  std::size_t line_ = 0;
  Tokens tokens_;
  ObjContents out_;
  std::vector<Pending> pending_;
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
