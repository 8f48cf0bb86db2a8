#pragma once
/// @file
/// Reader for CCD query files in the Sample-Queries CSV format: 8 rows per query, each row
/// `x_num,x_den,y_num,y_den,z_num,z_den,truth`. VF rows: v, f0, f1, f2 at t0, then at t1; EE rows:
/// ea0, ea1, eb0, eb1 at t0, then at t1. A value is double(num) / double(den): both integers are
/// read with correct rounding, so the value is exact whenever |num| < 2^53 and den is a power of
/// two (true for all of the shared data); otherwise it is within about 1.5 ulp.

#include <filesystem>
#include <optional>
#include <string_view>
#include <vector>

#include "clothcd/ccd/queries.hpp"

namespace clothcd {

enum class QueryKind { VertexFace, EdgeEdge };

struct CsvQuery {
  Eigen::Vector3d points[8];
  bool truth = false;
  std::size_t first_line = 0;  ///< 1-based line of the query's first row
};

struct QueryFile {
  std::filesystem::path path;
  QueryKind kind = QueryKind::VertexFace;
  std::vector<CsvQuery> queries;
};

/// Parses CSV text; `name` is used in messages. Throws InputError naming the line on a wrong
/// column count, a non-integer, a zero denominator, a truth value other than 0/1, a truth bit that
/// differs within a query, a row count that is not a multiple of 8, or an empty file.
[[nodiscard]] std::vector<CsvQuery> parse_query_csv(std::string_view text, std::string_view name);

/// Reads one file (InputError when it cannot be read or is malformed).
[[nodiscard]] QueryFile read_query_csv(const std::filesystem::path& file, QueryKind kind);

/// The kind named by the nearest folder called `vertex-face` or `edge-edge` in the path.
[[nodiscard]] std::optional<QueryKind> query_kind_from_path(const std::filesystem::path& file);

/// The `.csv` files of the given files and folders (folders searched recursively), sorted.
/// InputError for a path that does not exist.
[[nodiscard]] std::vector<std::filesystem::path> find_query_files(
    const std::vector<std::filesystem::path>& paths);

[[nodiscard]] VertexFaceQuery to_vertex_face(const CsvQuery& q);
[[nodiscard]] EdgeEdgeQuery to_edge_edge(const CsvQuery& q);

/// Runs the kernel of `kind` on a query.
[[nodiscard]] CcdResult run_query(QueryKind kind, const CsvQuery& q, const CcdOptions& opt = {});

}  // namespace clothcd
