#include "arrays.hpp"

#include <fmt/format.h>

#include <climits>
#include <cstring>
#include <stdexcept>

namespace clothcd::python {

static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double), "Vector3d rows must be packed");
static_assert(sizeof(Face) == 3 * sizeof(int) && sizeof(Edge) == 2 * sizeof(int));

void fail(const std::string& message) {
  throw std::invalid_argument(message);
}

std::string describe(const py::array& a) {
  std::string shape;
  for (py::ssize_t i = 0; i < a.ndim(); ++i) {
    shape += (i > 0 ? ", " : "") + std::to_string(a.shape(i));
  }
  if (a.ndim() == 1) shape += ",";
  return fmt::format("{} array of shape ({})", std::string(py::str(a.dtype())), shape);
}

namespace {

py::array as_array(const py::handle& obj) {
  // numpy.asarray: no copy for an ndarray, inferred dtype for a list.
  return py::module_::import("numpy").attr("asarray")(obj).cast<py::array>();
}

std::string shape_text(int ndim) {
  return ndim == 1 ? "(n,)" : ndim == 2 ? "(n, 3)" : "(k, 8, 3)";
}

// Integer arrays of any integer dtype, read as int64 (range-checked against int later).
py::array_t<long long, py::array::c_style> int_array(const py::handle& obj, const char* name,
                                                     int ndim, const char* shape) {
  py::array a = as_array(obj);
  const char kind = a.dtype().kind();
  if (kind != 'i' && kind != 'u' && !(a.size() == 0 && kind == 'f')) {
    fail(
        fmt::format("{}: expected an integer array of shape {}, got {}", name, shape, describe(a)));
  }
  if (a.ndim() != ndim && !(a.size() == 0 && ndim == 2)) {
    fail(
        fmt::format("{}: expected an integer array of shape {}, got {}", name, shape, describe(a)));
  }
  return py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(a);
}

int checked_int(long long x, const char* name, py::ssize_t i) {
  if (x < INT_MIN || x > INT_MAX) {
    fail(fmt::format("{}: entry {} ({}) does not fit a 32-bit vertex id", name, i, x));
  }
  return static_cast<int>(x);
}

}  // namespace

py::array_t<double, py::array::c_style> float_array(const py::handle& obj, const char* name,
                                                    int ndim) {
  py::array a = as_array(obj);
  if (a.dtype().kind() != 'f') {
    fail(fmt::format("{}: expected a float array of shape {}, got {}", name, shape_text(ndim),
                     describe(a)));
  }
  if (a.ndim() != ndim) {
    fail(fmt::format("{}: expected a float array of shape {}, got {}", name, shape_text(ndim),
                     describe(a)));
  }
  // No copy for a C-contiguous float64 array.
  return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
}

Positions positions(const py::handle& obj, const char* name) {
  const auto a = float_array(obj, name, 2);
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  // Any column count goes through, so that the library's own message names the wrong shape.
  return Eigen::Map<const RowMajor>(a.data(), a.shape(0), a.shape(1));
}

Positions PointsArg::matrix() const {
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  return Eigen::Map<const RowMajor>(array_.data(), array_.shape(0), array_.shape(1));
}

std::vector<Face> faces(const py::handle& obj, const char* name) {
  const auto a = int_array(obj, name, 2, "(m, 3)");
  if (a.size() == 0) return {};
  if (a.shape(1) != 3) {
    fail(fmt::format("{}: expected an integer array of shape (m, 3), got {}", name, describe(a)));
  }
  std::vector<Face> out(static_cast<std::size_t>(a.shape(0)));
  const long long* p = a.data();
  for (py::ssize_t i = 0; i < a.size(); ++i) {
    out[i / 3][i % 3] = checked_int(p[i], name, i / 3);
  }
  return out;
}

std::vector<int> indices(const py::handle& obj, const char* name) {
  const auto a = int_array(obj, name, 1, "(n,)");
  std::vector<int> out(static_cast<std::size_t>(a.size()));
  for (py::ssize_t i = 0; i < a.size(); ++i)
    out[i] = checked_int(a.data()[i], name, i);
  return out;
}

std::vector<std::pair<int, int>> index_pairs(const py::handle& obj, const char* name) {
  const auto a = int_array(obj, name, 2, "(k, 2)");
  if (a.size() == 0) return {};
  if (a.shape(1) != 2) {
    fail(fmt::format("{}: expected an integer array of shape (k, 2), got {}", name, describe(a)));
  }
  std::vector<std::pair<int, int>> out(static_cast<std::size_t>(a.shape(0)));
  for (py::ssize_t i = 0; i < a.shape(0); ++i) {
    out[i] = {checked_int(a.data()[2 * i], name, i), checked_int(a.data()[2 * i + 1], name, i)};
  }
  return out;
}

py::array_t<double> vertices_array(std::vector<Eigen::Vector3d>&& v) {
  const auto n = static_cast<py::ssize_t>(v.size());
  return take<double>(std::move(v), {n, 3});
}

py::array_t<int> faces_array(std::vector<Face>&& f) {
  const auto n = static_cast<py::ssize_t>(f.size());
  return take<int>(std::move(f), {n, 3});
}

py::array_t<int> edges_array(const std::vector<Edge>& e) {
  py::array_t<int> out({static_cast<py::ssize_t>(e.size()), py::ssize_t{2}});
  if (!e.empty()) std::memcpy(out.mutable_data(), e.data(), e.size() * sizeof(Edge));
  return out;
}

py::array_t<double> matrix_array(const Positions& m) {
  py::array_t<double> out({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(m.cols())});
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  Eigen::Map<RowMajor>(out.mutable_data(), m.rows(), m.cols()) = m;
  return out;
}

}  // namespace clothcd::python
