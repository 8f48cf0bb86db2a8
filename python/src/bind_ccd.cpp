// The CCD kernels on batches of queries, and the query CSV reader.
#include <fmt/format.h>
#include <pybind11/stl/filesystem.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <stdexcept>

#include "arrays.hpp"
#include "bindings.hpp"
#include "clothcd/ccd/queries.hpp"
#include "clothcd/ccd/query_csv.hpp"

namespace clothcd::python {
namespace {

// Query i of a C-contiguous (k, 8, 3) array, rows in the CSV order (four points at t0, then t1).
template <class Query>
Query query_at(const double* q, py::ssize_t i) {
  const double* p = q + 24 * i;
  auto pt = [&](int r) { return Eigen::Vector3d(p[3 * r], p[3 * r + 1], p[3 * r + 2]); };
  return Query{pt(0), pt(1), pt(2), pt(3), pt(4), pt(5), pt(6), pt(7)};
}

template <class Query>
py::tuple batch(const ArrayLike& obj, const CcdOptions& opt, int threads) {
  const auto q = float_array(obj, "q", 3);
  if (q.shape(1) != 8 || q.shape(2) != 3) {
    fail(fmt::format("q: expected a float array of shape (k, 8, 3), got {}", describe(q)));
  }
  const py::ssize_t k = q.shape(0);
  const double* data = q.data();
  // The first query with a non-finite coordinate gets the kernel's own message, deterministically.
  for (py::ssize_t i = 0; i < 24 * k; ++i) {
    if (!std::isfinite(data[i])) {
      try {
        const Query bad = query_at<Query>(data, i / 24);
        if constexpr (std::is_same_v<Query, VertexFaceQuery>) {
          (void)vertex_face_ccd(bad, opt);
        } else {
          (void)edge_edge_ccd(bad, opt);
        }
      } catch (const std::invalid_argument& e) {
        fail(fmt::format("query {}: {}", i / 24, e.what()));
      }
      fail(fmt::format("query {}: non-finite coordinate", i / 24));
    }
  }
  py::array_t<bool> hit(k);
  py::array_t<double> toi(k);
  bool* h = hit.mutable_data();
  double* t = toi.mutable_data();
  Workers workers(threads);
  workers.run([&] {
    tbb::parallel_for(py::ssize_t{0}, k, [&](py::ssize_t i) {
      const Query one = query_at<Query>(data, i);
      CcdResult r;
      if constexpr (std::is_same_v<Query, VertexFaceQuery>) {
        r = vertex_face_ccd(one, opt);
      } else {
        r = edge_edge_ccd(one, opt);
      }
      h[i] = r.hit;
      t[i] = r.toi;
    });
  });
  return py::make_tuple(hit, toi);
}

CcdOptions options(double thickness, bool fast_path, double tolerance, double toi_tolerance,
                   std::uint32_t max_boxes) {
  if (!(thickness >= 0) || !std::isfinite(thickness)) {
    fail(fmt::format("thickness must be finite and >= 0, got {}", thickness));
  }
  CcdOptions o;
  o.thickness = thickness;
  o.fast_path = fast_path;
  o.tolerance = tolerance;
  o.toi_tolerance = toi_tolerance;
  o.max_boxes = max_boxes;
  return o;
}

constexpr const char* kBatchDoc = R"(

q: float array of shape (k, 8, 3); rows 0-3 are the four points at t0, rows 4-7 the same points
at t1 (the row order of the CCD query CSV files). Returns (hit, toi): (k,) bool and (k,) float64,
the conservative time of impact (1 where there is no hit). Never misses a contact closer than
`thickness`. The loop runs in C++ on `threads` workers (0: all cores) without the GIL. Raises
ValueError for a non-finite coordinate, naming the query.)";

}  // namespace

void bind_ccd(py::module_& m) {
  const CcdOptions d;
  m.def(
      "vertex_face_ccd",
      [](const ArrayLike& q, double thickness, bool fast_path, double tolerance,
         double toi_tolerance, std::uint32_t max_boxes, int threads) {
        return batch<VertexFaceQuery>(
            q, options(thickness, fast_path, tolerance, toi_tolerance, max_boxes), threads);
      },
      py::arg("q"), py::kw_only(), py::arg("thickness") = 0.0, py::arg("fast_path") = d.fast_path,
      py::arg("tolerance") = d.tolerance, py::arg("toi_tolerance") = d.toi_tolerance,
      py::arg("max_boxes") = d.max_boxes, py::arg("threads") = 0,
      (std::string("Vertex-face CCD on a batch: rows v, f0, f1, f2 at t0, then at t1.") + kBatchDoc)
          .c_str());
  m.def(
      "edge_edge_ccd",
      [](const ArrayLike& q, double thickness, bool fast_path, double tolerance,
         double toi_tolerance, std::uint32_t max_boxes, int threads) {
        return batch<EdgeEdgeQuery>(
            q, options(thickness, fast_path, tolerance, toi_tolerance, max_boxes), threads);
      },
      py::arg("q"), py::kw_only(), py::arg("thickness") = 0.0, py::arg("fast_path") = d.fast_path,
      py::arg("tolerance") = d.tolerance, py::arg("toi_tolerance") = d.toi_tolerance,
      py::arg("max_boxes") = d.max_boxes, py::arg("threads") = 0,
      (std::string("Edge-edge CCD on a batch: rows ea0, ea1, eb0, eb1 at t0, then at t1.") +
       kBatchDoc)
          .c_str());

  m.def(
      "read_query_csv",
      [](const std::filesystem::path& path, std::optional<std::string> kind) {
        QueryKind k;
        if (kind) {
          if (*kind == "vertex-face" || *kind == "vf") {
            k = QueryKind::VertexFace;
          } else if (*kind == "edge-edge" || *kind == "ee") {
            k = QueryKind::EdgeEdge;
          } else {
            fail(fmt::format("kind: unknown value '{}' (one of vertex-face, edge-edge)", *kind));
          }
        } else if (const auto from_path = query_kind_from_path(path)) {
          k = *from_path;
        } else {
          fail(fmt::format("{}: no vertex-face or edge-edge folder in the path; give kind",
                           path.string()));
        }
        QueryFile file;
        {
          py::gil_scoped_release release;
          file = read_query_csv(path, k);
        }
        const auto n = static_cast<py::ssize_t>(file.queries.size());
        py::array_t<double> q({n, py::ssize_t{8}, py::ssize_t{3}});
        py::array_t<bool> truth(n);
        double* p = q.mutable_data();
        for (py::ssize_t i = 0; i < n; ++i) {
          for (int r = 0; r < 8; ++r)
            for (int c = 0; c < 3; ++c)
              p[24 * i + 3 * r + c] = file.queries[i].points[r][c];
          truth.mutable_data()[i] = file.queries[i].truth;
        }
        return py::make_tuple(q, truth, k == QueryKind::VertexFace ? "vertex-face" : "edge-edge");
      },
      py::arg("path"), py::arg("kind") = py::none(),
      R"(Reads a CCD query CSV file (8 rows per query, x_num,x_den,y_num,y_den,z_num,z_den,truth).

kind: "vertex-face" or "edge-edge"; by default from the nearest such folder in the path.
Returns (q, truth, kind): q float64 (k, 8, 3) for vertex_face_ccd / edge_edge_ccd, truth (k,)
bool.)");
}

}  // namespace clothcd::python
