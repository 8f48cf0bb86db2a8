// The implicit system's matrix: its product against one summed element by element (membrane
// blocks of every face, bending of every hinge, stitches), with the constant identity blocks
// kept as scalars; and the solve's one-pass product with couplings and filters.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <span>
#include <utility>
#include <vector>

#include "clothcd/sim/elements.hpp"
#include "grid.hpp"
#include "sim/couplings.hpp"
#include "sim/pcg.hpp"
#include "sim/system.hpp"

namespace clothcd::sim {
namespace {

using test::grid_cloth;
using test::random_vec;

// The system matrix at the model's initial shape crumpled by up to 5 mm.
struct Crumpled {
  std::vector<Vec3> x;
  BlockCsr h;
};
Crumpled crumpled_system(const ClothModel& m, std::mt19937_64& rng) {
  Crumpled c{m.initial_positions(), {}};
  for (Vec3& p : c.x)
    p += random_vec(rng, 0.005);
  SystemAssembler assembler(m);
  c.h = assembler.make_matrix();
  Vecs gradient;
  assembler.assemble(c.x, c.h, gradient);
  return c;
}

// H r with H = membrane (PSD-projected, at x) + bending + stitches, element by element.
std::vector<Vec3> reference_product(const ClothModel& m, const std::vector<Vec3>& x,
                                    const std::vector<Vec3>& r) {
  std::vector<Vec3> y(r.size(), Vec3::Zero());
  const auto& faces = m.topology().faces();
  for (int f = 0; f < m.topology().num_faces(); ++f) {
    if (!m.membrane_active()[f]) continue;
    const Face& t = faces[f];
    const MembraneEval e =
        membrane_eval({x[t[0]], x[t[1]], x[t[2]]}, m.membrane_rest()[f], m.moduli(), true);
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j)
        y[t[i]] += e.hessian[i][j] * r[t[j]];
    }
  }
  for (const Hinge& h : m.hinges()) {
    Vec3 s = Vec3::Zero();
    for (int a = 0; a < 4; ++a)
      s += h.w.k[a] * r[h.v[a]];
    for (int a = 0; a < 4; ++a)
      y[h.v[a]] += h.w.scale * h.w.k[a] * s;
  }
  for (const StitchTerm& st : m.stitches()) {
    Vec3 s = Vec3::Zero();
    for (int a = 0; a < st.count; ++a)
      s += st.w[a] * r[st.v[a]];
    for (int a = 0; a < st.count; ++a)
      y[st.v[a]] += m.material().stitch_stiffness * st.w[a] * s;
  }
  return y;
}

TEST(SystemAssembler, ProductMatchesTheElementsWithIdentityBlocksAsScalars) {
  // Two 8 x 8 grids side by side, stitched along the seam between them, crumpled by 5 mm.
  ClothMeshInput in = grid_cloth(8, 8, 0.2, 0.2);
  const int half = static_cast<int>(in.positions.size());
  const ClothMeshInput right = grid_cloth(8, 8, 0.2, 0.2);
  for (const Vec3& p : right.positions)
    in.positions.push_back(p + Vec3(0.2, 0, 0));
  for (const Face& f : right.faces)
    in.faces.push_back({f[0] + half, f[1] + half, f[2] + half});
  for (int j = 0; j <= 8; ++j)
    in.stitches.push_back({j * 9 + 8, half + j * 9, half + j * 9, 0.0});
  const ClothModel m(in, ClothMaterial{});
  ASSERT_GT(m.stitches().size(), 0u);
  std::mt19937_64 rng(3);
  const auto [x, h] = crumpled_system(m, rng);
  // The scalar blocks are exactly the vertex pairs that a hinge or a stitch joins and no face
  // does; the diagonal is always a full block.
  std::set<std::pair<int, int>> in_face, expected_scalar, scalar;
  for (const Face& f : m.topology().faces()) {
    for (int a : f) {
      for (int b : f)
        in_face.emplace(a, b);
    }
  }
  auto joined = [&](std::span<const int> vs) {
    for (int a : vs) {
      for (int b : vs) {
        if (a != b && !in_face.count({a, b})) expected_scalar.emplace(a, b);
      }
    }
  };
  for (const Hinge& hg : m.hinges())
    joined(hg.v);
  for (const StitchTerm& st : m.stitches())
    joined(std::span<const int>(st.v.data(), st.count));
  for (int i = 0; i < h.rows(); ++i) {
    EXPECT_EQ(h.cols[h.diag[i]], i);
    for (int q = h.scalar_row_start[i]; q < h.scalar_row_start[i + 1]; ++q)
      scalar.emplace(i, h.scalar_cols[q]);
  }
  EXPECT_FALSE(expected_scalar.empty());
  EXPECT_EQ(scalar, expected_scalar);
  for (int trial = 0; trial < 3; ++trial) {
    std::vector<Vec3> r(m.num_vertices());
    for (Vec3& v : r)
      v = random_vec(rng, 1.0);
    std::vector<Vec3> y(r.size());
    multiply(h, r, y);
    const std::vector<Vec3> want = reference_product(m, x, r);
    double scale = 0.0;
    for (const Vec3& v : want)
      scale = std::max(scale, v.norm());
    ASSERT_GT(scale, 0.0);
    for (int i = 0; i < m.num_vertices(); ++i)
      EXPECT_LE((y[i] - want[i]).norm(), 1e-12 * scale) << "vertex " << i;
  }
}

// The solve's product in one pass over the rows is the four passes it replaces, bit for bit, and
// its coupling part is the penalty's definition: kappa_j c_jk n_j (n_j . sum_k c_jk x_k) with
// kappa_j = scale / sum_k c_jk^2 / m_k.
TEST(SystemProduct, OnePassIsTheSeparatePassesBitForBit) {
  const ClothModel m(grid_cloth(10, 10, 0.2, 0.2), ClothMaterial{});
  const int n = m.num_vertices();
  std::mt19937_64 rng(11);
  const BlockCsr h = crumpled_system(m, rng).h;
  std::vector<double> mass(m.mass().begin(), m.mass().end()), inverse_mass(n);
  for (int i = 0; i < n; ++i)
    inverse_mass[i] = 1.0 / mass[i];
  inverse_mass[5] = 0.0;  // a pinned vertex inside a coupling
  // Vertex-face couplings between random vertices and faces, some with a body point (-1).
  std::vector<ContactCoupling> list;
  std::uniform_int_distribution<int> pick_v(0, n - 1), pick_f(0, m.topology().num_faces() - 1);
  for (int j = 0; j < 60; ++j) {
    ContactCoupling c;
    const Face& f = m.topology().faces()[pick_f(rng)];
    c.vertex = {j % 7 == 0 ? 5 : pick_v(rng), f[0], f[1], j % 5 == 0 ? -1 : f[2]};
    c.c = {1.0, -0.2, -0.5, -0.3};
    c.n = random_vec(rng, 1.0);
    list.push_back(c);
  }
  CouplingTerms k;
  k.reset(list, inverse_mass, 100.0);
  ASSERT_EQ(k.size(), 60);
  VertexFilter filter;
  filter.reset(n);
  for (int i = 0; i < n; i += 3) {
    filter.kind[i] = i % 2 == 0 ? VertexFilter::Plane : VertexFilter::Pinned;
    filter.direction[i] = random_vec(rng, 1.0).normalized();
  }
  const double c = 2.5e-5;
  for (int trial = 0; trial < 3; ++trial) {
    Vecs r(n), separate(n), hr(n), fused(n), unfiltered(n);
    for (Vec3& v : r)
      v = random_vec(rng, 1.0);
    multiply(h, r, hr);
    for (int i = 0; i < n; ++i)
      separate[i] = mass[i] * r[i] + c * hr[i];
    k.add_product(r, separate);
    apply_system(h, c, mass, r, unfiltered, &k);
    apply_system(h, c, mass, r, fused, &k, &filter);
    double scale = 0.0;
    for (int i = 0; i < n; ++i) {
      scale = std::max(scale, separate[i].norm());
      ASSERT_EQ(unfiltered[i], separate[i]) << "vertex " << i;
      ASSERT_EQ(fused[i], filter.apply(i, separate[i])) << "vertex " << i;
    }
    // The coupling part against its definition.
    Vecs want(n);
    for (int i = 0; i < n; ++i)
      want[i] = mass[i] * r[i] + c * hr[i];
    for (const ContactCoupling& cp : list) {
      const Vec3 nn = cp.n.normalized();
      double w = 0.0, g = 0.0;
      for (int a = 0; a < 4; ++a) {
        if (cp.vertex[a] < 0) continue;
        w += cp.c[a] * cp.c[a] * inverse_mass[cp.vertex[a]];
        g += cp.c[a] * nn.dot(r[cp.vertex[a]]);
      }
      for (int a = 0; a < 4; ++a) {
        if (cp.vertex[a] >= 0) want[cp.vertex[a]] += (100.0 / w) * cp.c[a] * g * nn;
      }
    }
    for (int i = 0; i < n; ++i)
      EXPECT_LE((unfiltered[i] - want[i]).norm(), 1e-12 * scale) << "vertex " << i;
  }
}

}  // namespace
}  // namespace clothcd::sim
