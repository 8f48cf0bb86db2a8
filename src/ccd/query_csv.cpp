#include "clothcd/ccd/query_csv.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include <fmt/format.h>

#include "clothcd/core/error.hpp"

namespace clothcd {

namespace {

bool is_integer(std::string_view s) {
  std::size_t i = 0;
  if (i < s.size() && (s[i] == '-' || s[i] == '+')) ++i;
  if (i == s.size()) return false;
  for (; i < s.size(); ++i) {
    if (s[i] < '0' || s[i] > '9') return false;
  }
  return true;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) {
    s.remove_suffix(1);
  }
  return s;
}

// Correctly rounded decimal integer (strtod rounds to nearest).
double integer_value(std::string_view s) {
  const std::string str(s);
  return std::strtod(str.c_str(), nullptr);
}

}  // namespace

std::vector<CsvQuery> parse_query_csv(std::string_view text, std::string_view name) {
  std::vector<CsvQuery> out;
  std::size_t line_no = 0, rows = 0;
  CsvQuery current;
  current.truth = false;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = trim(text.substr(pos, end - pos));
    pos = end + 1;
    ++line_no;
    if (line.empty()) continue;
    std::string_view fields[7];
    std::size_t count = 0, start = 0;
    while (true) {
      const std::size_t comma = line.find(',', start);
      const std::string_view f =
          trim(line.substr(start, comma == std::string_view::npos ? line.npos : comma - start));
      if (count < 7) fields[count] = f;
      ++count;
      if (comma == std::string_view::npos) break;
      start = comma + 1;
    }
    if (count != 7) {
      throw input_error(name, line_no,
                        fmt::format("expected 7 comma-separated columns (x_num, x_den, y_num, "
                                    "y_den, z_num, z_den, truth), found {}",
                                    count));
    }
    for (std::size_t c = 0; c < 7; ++c) {
      if (!is_integer(fields[c])) {
        throw input_error(name, line_no,
                          fmt::format("column {} is not an integer: '{}'", c + 1, fields[c]));
      }
    }
    const int row = static_cast<int>(rows % 8);
    if (row == 0) {
      for (auto& x : current.points)
        x.setZero();
      current.first_line = line_no;
    }
    for (int a = 0; a < 3; ++a) {
      const double num = integer_value(fields[2 * a]);
      const double den = integer_value(fields[2 * a + 1]);
      if (den == 0) {
        throw input_error(name, line_no, fmt::format("zero denominator in column {}", 2 * a + 2));
      }
      const double value = num / den;
      if (!std::isfinite(value)) {
        throw input_error(name, line_no,
                          fmt::format("coordinate {}/{} is not a finite double", fields[2 * a],
                                      fields[2 * a + 1]));
      }
      current.points[row][a] = value;
    }
    if (fields[6] != "0" && fields[6] != "1") {
      throw input_error(name, line_no, fmt::format("truth must be 0 or 1, got '{}'", fields[6]));
    }
    const bool truth = fields[6] == "1";
    if (row == 0) {
      current.truth = truth;
    } else if (truth != current.truth) {
      throw input_error(name, line_no,
                        fmt::format("truth {} differs from the query's first row (line {})",
                                    int(truth), current.first_line));
    }
    ++rows;
    if (rows % 8 == 0) out.push_back(current);
  }
  if (rows == 0) throw input_error(name, 0, "empty file: no query rows");
  if (rows % 8 != 0) {
    throw input_error(name, line_no,
                      fmt::format("{} rows is not a multiple of 8 (8 rows per query)", rows));
  }
  return out;
}

QueryFile read_query_csv(const std::filesystem::path& file, QueryKind kind) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw input_error(file.string(), 0, "cannot open file");
  std::ostringstream ss;
  ss << in.rdbuf();
  QueryFile out;
  out.path = file;
  out.kind = kind;
  out.queries = parse_query_csv(ss.str(), file.string());
  return out;
}

std::optional<QueryKind> query_kind_from_path(const std::filesystem::path& file) {
  for (auto p = file.parent_path(); !p.empty(); p = p.parent_path()) {
    const auto name = p.filename().string();
    if (name == "vertex-face") return QueryKind::VertexFace;
    if (name == "edge-edge") return QueryKind::EdgeEdge;
    if (p == p.parent_path()) break;
  }
  return std::nullopt;
}

std::vector<std::filesystem::path> find_query_files(
    const std::vector<std::filesystem::path>& paths) {
  namespace fs = std::filesystem;
  std::vector<fs::path> out;
  for (const auto& p : paths) {
    std::error_code ec;
    if (fs::is_directory(p, ec)) {
      std::vector<fs::path> found;
      for (const auto& entry : fs::recursive_directory_iterator(p)) {
        if (entry.is_regular_file() && entry.path().extension() == ".csv") {
          found.push_back(entry.path());
        }
      }
      std::sort(found.begin(), found.end());
      out.insert(out.end(), found.begin(), found.end());
    } else if (fs::exists(p, ec)) {
      out.push_back(p);
    } else {
      throw input_error(p.string(), 0, "no such file or folder");
    }
  }
  return out;
}

VertexFaceQuery to_vertex_face(const CsvQuery& q) {
  const auto& x = q.points;
  return {x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7]};
}

EdgeEdgeQuery to_edge_edge(const CsvQuery& q) {
  const auto& x = q.points;
  return {x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7]};
}

CcdResult run_query(QueryKind kind, const CsvQuery& q, const CcdOptions& opt) {
  return kind == QueryKind::VertexFace ? vertex_face_ccd(to_vertex_face(q), opt)
                                       : edge_edge_ccd(to_edge_edge(q), opt);
}

}  // namespace clothcd
