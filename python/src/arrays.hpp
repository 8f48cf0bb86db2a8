#pragma once
// NumPy <-> clothcd conversions. Inputs are checked here for what the library cannot see (array
// rank, dtype, integer range) and raise ValueError naming the argument; everything else (row
// counts, non-finite coordinates, face ids out of range) is left to the library, whose InputError
// becomes a ValueError with its own message. Outputs that the library already holds in NumPy's
// layout (std::vector of Vector3d or Face) are handed over without a copy.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "clothcd/detect/detector.hpp"
#include "clothcd/mesh/topology.hpp"

namespace clothcd::python {

namespace py = pybind11;

/// An argument converted by the functions below (any object numpy.asarray accepts); its own type
/// so that signatures in docstrings read "ArrayLike" rather than "handle".
struct ArrayLike {
  py::object obj;
  operator py::handle() const { return obj; }  // NOLINT: used where a handle is expected
};

/// Raises ValueError (through pybind11's translation of std::invalid_argument).
[[noreturn]] void fail(const std::string& message);

/// "float32 array of shape (4, 2)".
[[nodiscard]] std::string describe(const py::array& a);

/// A float array (float64 read in place, other float dtypes converted) of shape (rows, 3); a
/// list is converted like numpy.asarray. ValueError for another dtype or rank.
[[nodiscard]] py::array_t<double, py::array::c_style> float_array(const py::handle& obj,
                                                                  const char* name, int ndim);

/// An (n, 3) float array as the library's column-major n x 3 matrix. The library takes its
/// positions as an owning Eigen::MatrixXd, so this one copy (O(n), no allocation per vertex) is
/// the only one; a C-contiguous float64 array is read in place.
[[nodiscard]] Positions positions(const py::handle& obj, const char* name);

/// An (n, k) float array for the detectors' per-step calls. With k == 3 its rows are the points:
/// a C-contiguous float64 array (NumPy's default) is read in place, with no copy; other dtypes and
/// layouts are converted once. Another k is kept for matrix(), so that the library's own message
/// names the wrong shape.
class PointsArg {
 public:
  PointsArg(const py::handle& obj, const char* name) : array_(float_array(obj, name, 2)) {}
  [[nodiscard]] bool has_points() const { return array_.shape(1) == 3; }
  /// The rows as points (valid while this object lives); only when has_points().
  [[nodiscard]] std::span<const Eigen::Vector3d> points() const {
    return {reinterpret_cast<const Eigen::Vector3d*>(array_.data()),
            static_cast<std::size_t>(array_.shape(0))};
  }
  [[nodiscard]] Positions matrix() const;

 private:
  py::array_t<double, py::array::c_style> array_;
};

/// Calls f with every argument's points when all of them have three columns, else with their
/// matrices (the library then reports the wrong shape).
template <class F, class... Args>
auto with_points(F&& f, const Args&... args) {
  if ((args.has_points() && ...)) return f(args.points()...);
  return f(args.matrix()...);
}

/// An (m, 3) integer array as faces (ids checked to fit an int; their range is the library's).
[[nodiscard]] std::vector<Face> faces(const py::handle& obj, const char* name);

/// A 1-D integer array (or sequence) as ints.
[[nodiscard]] std::vector<int> indices(const py::handle& obj, const char* name);

/// An (k, 2) integer array as pairs.
[[nodiscard]] std::vector<std::pair<int, int>> index_pairs(const py::handle& obj, const char* name);

/// Moves a vector into a NumPy array of the given shape without copying (the array owns it).
template <class Scalar, class T>
py::array_t<Scalar> take(std::vector<T>&& v, std::vector<py::ssize_t> shape) {
  static_assert(sizeof(T) % sizeof(Scalar) == 0);
  auto* owned = new std::vector<T>(std::move(v));
  py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<Scalar>(shape, reinterpret_cast<Scalar*>(owned->data()), owner);
}

[[nodiscard]] py::array_t<double> vertices_array(std::vector<Eigen::Vector3d>&& v);
[[nodiscard]] py::array_t<int> faces_array(std::vector<Face>&& f);
[[nodiscard]] py::array_t<int> edges_array(const std::vector<Edge>& e);
/// An n x 3 matrix as an (n, 3) C-contiguous array.
[[nodiscard]] py::array_t<double> matrix_array(const Positions& m);

}  // namespace clothcd::python

namespace pybind11::detail {
template <>
struct type_caster<clothcd::python::ArrayLike> {
  PYBIND11_TYPE_CASTER(clothcd::python::ArrayLike, const_name("numpy.typing.ArrayLike"));
  bool load(handle src, bool) {
    value.obj = reinterpret_borrow<object>(src);
    return true;
  }
  static handle cast(const clothcd::python::ArrayLike& src, return_value_policy, handle) {
    return src.obj.inc_ref();
  }
};
}  // namespace pybind11::detail
