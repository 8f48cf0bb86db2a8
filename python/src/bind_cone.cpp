// Normal cones on arrays: merges, CCD leaf cones, the optimal cone of a vector set. A cone is an
// (axis, half_angle) pair; functions taking cones accept one cone (axis (3,), half_angle float)
// or a batch (axes (k, 3), half-angles (k,)) and answer in the same form.
#include <fmt/format.h>

#include <map>

#include "arrays.hpp"
#include "bindings.hpp"
#include "clothcd/geometry/cone.hpp"

namespace clothcd::python {
namespace {

// A float array of shape `inner` (single) or (k, *inner) (batch).
struct Batch {
  py::array_t<double, py::array::c_style> a;
  bool single = false;
  py::ssize_t k = 0;
};

Batch batch(const ArrayLike& obj, const char* name, std::vector<py::ssize_t> inner) {
  py::array raw = py::module_::import("numpy").attr("asarray")(obj).cast<py::array>();
  const auto rank = static_cast<py::ssize_t>(inner.size());
  std::string want = "(";
  for (std::size_t i = 0; i < inner.size(); ++i)
    want += (i > 0 ? ", " : "") + std::to_string(inner[i]);
  want += inner.size() == 1 ? ",)" : ")";
  if (inner.empty()) want = "() (a number)";
  const bool single = raw.ndim() == rank;
  if (raw.dtype().kind() != 'f' && raw.dtype().kind() != 'i' && raw.dtype().kind() != 'u') {
    fail(fmt::format("{}: expected a float array of shape {} or (k, ...), got {}", name, want,
                     describe(raw)));
  }
  if (!single && raw.ndim() != rank + 1) {
    fail(fmt::format("{}: expected a float array of shape {} or (k, ...), got {}", name, want,
                     describe(raw)));
  }
  for (py::ssize_t i = 0; i < rank; ++i) {
    if (raw.shape(i + (single ? 0 : 1)) != inner[i]) {
      fail(fmt::format("{}: expected a float array of shape {} or (k, ...), got {}", name, want,
                       describe(raw)));
    }
  }
  Batch b;
  b.a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(raw);
  b.single = single;
  b.k = single ? 1 : raw.shape(0);
  return b;
}

Eigen::Vector3d vec(const Batch& b, py::ssize_t i, int offset = 0) {
  const double* p = b.a.data() + i * (b.a.size() / std::max<py::ssize_t>(b.k, 1)) + 3 * offset;
  return {p[0], p[1], p[2]};
}
double scalar(const Batch& b, py::ssize_t i) {
  return b.a.data()[i];
}

py::tuple cones_out(const std::vector<NormalCone>& cones, bool single) {
  if (single) {
    py::array_t<double> axis(3);
    for (int c = 0; c < 3; ++c)
      axis.mutable_data()[c] = cones[0].axis[c];
    return py::make_tuple(axis, cones[0].half_angle);
  }
  const auto k = static_cast<py::ssize_t>(cones.size());
  py::array_t<double> axes({k, py::ssize_t{3}});
  py::array_t<double> angles(k);
  for (py::ssize_t i = 0; i < k; ++i) {
    for (int c = 0; c < 3; ++c)
      axes.mutable_data()[3 * i + c] = cones[i].axis[c];
    angles.mutable_data()[i] = cones[i].half_angle;
  }
  return py::make_tuple(axes, angles);
}

py::tuple merge(const ArrayLike& axis_a, const ArrayLike& angle_a, const ArrayLike& axis_b,
                const ArrayLike& angle_b, NormalCone (*op)(const NormalCone&, const NormalCone&)) {
  const Batch aa = batch(axis_a, "axis_a", {3}), ta = batch(angle_a, "half_angle_a", {});
  const Batch ab = batch(axis_b, "axis_b", {3}), tb = batch(angle_b, "half_angle_b", {});
  if (aa.single != ta.single || ab.single != tb.single || aa.k != ta.k || ab.k != tb.k ||
      aa.single != ab.single || aa.k != ab.k) {
    fail(
        "cones: give one cone each (axis (3,), half_angle) or batches of the same length k "
        "(axes (k, 3), half-angles (k,))");
  }
  std::vector<NormalCone> out(static_cast<std::size_t>(aa.k));
  for (py::ssize_t i = 0; i < aa.k; ++i) {
    out[i] = op(NormalCone{vec(aa, i), scalar(ta, i)}, NormalCone{vec(ab, i), scalar(tb, i)});
  }
  return cones_out(out, aa.single);
}

LeafConePolicy leaf_policy(const std::string& s) {
  static const std::map<std::string, LeafConePolicy> m{{"tang", LeafConePolicy::Tang},
                                                       {"provot", LeafConePolicy::Tang},
                                                       {"proposed", LeafConePolicy::Proposed},
                                                       {"exact", LeafConePolicy::Exact}};
  const auto it = m.find(s);
  if (it == m.end()) {
    fail(fmt::format("policy: unknown value '{}' (one of tang (= provot), proposed, exact)", s));
  }
  return it->second;
}

constexpr const char* kMergeDoc = R"(

Cones are (axis, half_angle) with unit axes and half-angles in radians. Give one cone each
(axis (3,), half_angle float) or batches (axes (k, 3), half-angles (k,)); returns the same form.
A saturated result (no cone below pi/2) has half_angle exactly pi/2. NaN raises ValueError.)";

}  // namespace

void bind_cone(py::module_& m) {
  m.attr("SATURATED_HALF_ANGLE") = kSaturatedHalfAngle;
  m.def(
      "merge_provot",
      [](const ArrayLike& a, const ArrayLike& ta, const ArrayLike& b, const ArrayLike& tb) {
        return merge(a, ta, b, tb, &merge_provot);
      },
      py::arg("axis_a"), py::arg("half_angle_a"), py::arg("axis_b"), py::arg("half_angle_b"),
      (std::string("Provot's merge (PROVOT): axis = unit(a1 + a2), angle = beta/2 + max(t1, t2).") +
       kMergeDoc)
          .c_str());
  m.def(
      "merge_tight",
      [](const ArrayLike& a, const ArrayLike& ta, const ArrayLike& b, const ArrayLike& tb) {
        return merge(a, ta, b, tb, &merge_tight);
      },
      py::arg("axis_a"), py::arg("half_angle_a"), py::arg("axis_b"), py::arg("half_angle_b"),
      (std::string("The minimal cone enclosing both cones (PROPOSED's merge).") + kMergeDoc)
          .c_str());
  m.def(
      "ccd_leaf_cone",
      [](const ArrayLike& t0, const ArrayLike& t1, const std::string& policy) {
        const Batch a = batch(t0, "T0", {3, 3}), b = batch(t1, "T1", {3, 3});
        if (a.single != b.single || a.k != b.k) {
          fail(fmt::format("T0 and T1 must have the same shape, got {} and {}", describe(a.a),
                           describe(b.a)));
        }
        const LeafConePolicy p = leaf_policy(policy);
        std::vector<NormalCone> out(static_cast<std::size_t>(a.k));
        for (py::ssize_t i = 0; i < a.k; ++i) {
          out[i] = ccd_leaf_cone(vec(a, i, 0), vec(a, i, 1), vec(a, i, 2), vec(b, i, 0),
                                 vec(b, i, 1), vec(b, i, 2), p);
        }
        return cones_out(out, a.single);
      },
      py::arg("T0"), py::arg("T1"), py::arg("policy") = "proposed",
      R"(A cone containing the normal of each triangle at every time of its linear motion.

T0, T1: the corners (a, b, c) as rows, (3, 3) for one triangle or (k, 3, 3) for a batch.
policy: "tang" (= "provot", C_Tang), "proposed" (C_Proposed) or "exact" (minimal cap).
Returns (axis, half_angle) or (axes (k, 3), half-angles (k,)); saturated (pi/2) where a triangle
degenerates during the step.)");
  m.def(
      "optimal_cone",
      [](const ArrayLike& vectors) {
        const auto a = float_array(vectors, "vectors", 2);
        if (a.shape(1) != 3) {
          fail(fmt::format("vectors: expected a float array of shape (n, 3), got {}", describe(a)));
        }
        std::vector<Eigen::Vector3d> v(static_cast<std::size_t>(a.shape(0)));
        for (std::size_t i = 0; i < v.size(); ++i)
          v[i] = {a.data()[3 * i], a.data()[3 * i + 1], a.data()[3 * i + 2]};
        return cones_out({optimal_cone(v)}, true);
      },
      py::arg("vectors"),
      R"(The minimal cone (axis, half_angle) containing the directions of the rows of an (n, 3)
array; saturated (pi/2) when no cone below pi/2 exists. ValueError for an empty array or NaN.)");
}

}  // namespace clothcd::python
