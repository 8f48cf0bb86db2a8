// Minimal, fast OBJ parsing with from_chars; errors name file and line.
#include "clothcd/sim/obj_reader.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>

#include "clothcd/core/error.hpp"

namespace clothcd::sim {
namespace {

std::string slurp(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw input_error(file.string(), 0, "cannot open file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct LineParser {
  std::string_view rest;
  const std::filesystem::path& file;
  std::size_t line;

  void skip_space() {
    while (!rest.empty() && (rest.front() == ' ' || rest.front() == '\t' || rest.front() == '\r')) {
      rest.remove_prefix(1);
    }
  }
  bool at_end() {
    skip_space();
    return rest.empty();
  }
  std::string_view token() {
    skip_space();
    std::size_t k = 0;
    while (k < rest.size() && rest[k] != ' ' && rest[k] != '\t' && rest[k] != '\r')
      ++k;
    const std::string_view t = rest.substr(0, k);
    rest.remove_prefix(k);
    return t;
  }
  double number(const char* what) {
    const std::string_view t = token();
    double v = 0.0;
    const auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (ec != std::errc() || p != t.data() + t.size()) {
      throw input_error(file.string(), line,
                        fmt::format("expected a number for {}, got '{}'", what, t));
    }
    // from_chars reads "nan" and "inf"; a non-finite position would poison the whole solve.
    if (!std::isfinite(v)) {
      throw input_error(file.string(), line, fmt::format("{} '{}' is not finite", what, t));
    }
    return v;
  }
  long integer(std::string_view t, const char* what) const {
    long v = 0;
    const auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (ec != std::errc() || p != t.data() + t.size()) {
      throw input_error(file.string(), line,
                        fmt::format("expected an integer for {}, got '{}'", what, t));
    }
    return v;
  }
};

int resolve(long idx, std::size_t count, const LineParser& lp, const char* what) {
  const long n = static_cast<long>(count);
  const long r = idx > 0 ? idx - 1 : n + idx;
  if (idx == 0 || r < 0 || r >= n) {
    throw input_error(lp.file.string(), lp.line,
                      fmt::format("{} index {} out of range (1..{} so far)", what, idx, n));
  }
  return static_cast<int>(r);
}

template <typename OnLine>
void for_each_line(const std::string& text, OnLine on_line) {
  std::size_t pos = 0, line = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    ++line;
    on_line(std::string_view(text).substr(pos, end - pos), line);
    pos = end + 1;
  }
}

}  // namespace

ObjData read_obj(const std::filesystem::path& file) {
  const std::string text = slurp(file);
  ObjData d;
  for_each_line(text, [&](std::string_view s, std::size_t line) {
    LineParser lp{s, file, line};
    const std::string_view key = lp.token();
    if (key == "v") {
      const double x = lp.number("x"), y = lp.number("y"), z = lp.number("z");
      d.positions.emplace_back(x, y, z);
    } else if (key == "vt") {
      const double u = lp.number("u"), v = lp.number("v");
      d.texcoords.emplace_back(u, v);
    } else if (key == "f") {
      std::vector<std::pair<int, int>> corners;
      while (!lp.at_end()) {
        const std::string_view t = lp.token();
        const std::size_t s1 = t.find('/');
        const int v =
            resolve(lp.integer(t.substr(0, s1), "vertex"), d.positions.size(), lp, "vertex");
        int vt = -1;
        if (s1 != std::string_view::npos) {
          const std::string_view r = t.substr(s1 + 1);
          const std::string_view tt = r.substr(0, r.find('/'));
          if (!tt.empty())
            vt = resolve(lp.integer(tt, "texture"), d.texcoords.size(), lp, "texture");
        }
        corners.emplace_back(v, vt);
      }
      if (corners.size() < 3)
        throw input_error(file.string(), line, "face with fewer than 3 corners");
      for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
        d.faces.push_back({corners[0].first, corners[k].first, corners[k + 1].first});
        d.face_texcoords.push_back({corners[0].second, corners[k].second, corners[k + 1].second});
      }
    } else if (key == "stitch") {
      Stitch st;
      // Checked before narrowing, so 2^32 + 1 is not read as vertex 1 (the range check against
      // the vertex count comes after the whole file is read).
      auto vertex = [&] {
        const std::string_view t = lp.token();
        const long v = lp.integer(t, "stitch vertex");
        if (v < 0 || v > std::numeric_limits<int>::max()) {
          throw input_error(file.string(), line,
                            fmt::format("stitch vertex {} is not a 0-based vertex id", t));
        }
        return static_cast<int>(v);
      };
      st.a = vertex();
      st.b = vertex();
      st.c = vertex();
      st.r = lp.number("stitch ratio");
      d.stitches.push_back(st);
    }
  });
  for (std::size_t s = 0; s < d.stitches.size(); ++s) {
    const Stitch& st = d.stitches[s];
    for (int v : {st.a, st.b, st.c}) {
      if (v < 0 || v >= static_cast<int>(d.positions.size())) {
        throw input_error(file.string(), 0,
                          fmt::format("stitch {} refers to vertex {} (0-based), file has {}", s, v,
                                      d.positions.size()));
      }
    }
  }
  return d;
}

std::vector<Vec3> read_obj_positions(const std::filesystem::path& file) {
  const std::string text = slurp(file);
  std::vector<Vec3> out;
  for_each_line(text, [&](std::string_view s, std::size_t line) {
    if (s.size() < 2 || s[0] != 'v' || (s[1] != ' ' && s[1] != '\t')) return;
    LineParser lp{s.substr(1), file, line};
    const double x = lp.number("x"), y = lp.number("y"), z = lp.number("z");
    out.emplace_back(x, y, z);
  });
  return out;
}

}  // namespace clothcd::sim
