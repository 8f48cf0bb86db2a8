// The PCG's coarse correction (src/sim/coarse.hpp): its aggregates, and solves with it against
// block Jacobi alone on the same systems.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <vector>

#include "clothcd/core/error.hpp"
#include "clothcd/sim/cloth_model.hpp"
#include "grid.hpp"
#include "sim/coarse.hpp"
#include "sim/couplings.hpp"
#include "sim/pcg.hpp"
#include "sim/system.hpp"

namespace clothcd::sim {
namespace {

using test::grid_cloth;
using test::random_vec;

constexpr double kC = 0.01 * 0.011;  // h (h + beta) of a 10 ms substep

// A grid stretched by 1% in x, its system and a right-hand side of the size of a substep's.
struct Stretched {
  ClothModel model;
  BlockCsr h;
  Vecs b;
};
Stretched stretched_grid(int nx) {
  Stretched s{ClothModel(grid_cloth(nx, nx, 1.0, 1.0), ClothMaterial{}), {}, {}};
  std::vector<Vec3> x = s.model.initial_positions();
  for (Vec3& p : x)
    p.x() *= 1.01;
  SystemAssembler assembler(s.model);
  s.h = assembler.make_matrix();
  Vecs gradient;
  assembler.assemble(x, s.h, gradient);
  s.b.resize(x.size());
  for (std::size_t i = 0; i < x.size(); ++i)
    s.b[i] = -0.01 * gradient[i] + Vec3(0, -1e-4, 0);
  return s;
}

// |b - S A dv| / |S b|, the filtered system's true residual.
double true_residual(const Stretched& s, const VertexFilter& filter, const CouplingTerms* ct,
                     const Vecs& dv) {
  Vecs q(dv.size());
  apply_system(s.h, kC, s.model.mass(), dv, q, ct, &filter);
  double e = 0.0, bb = 0.0;
  for (std::size_t i = 0; i < dv.size(); ++i) {
    const int v = static_cast<int>(i);
    e += filter.apply(v, s.b[i] - q[i]).squaredNorm();
    bb += filter.apply(v, s.b[i]).squaredNorm();
  }
  return std::sqrt(e / bb);
}

TEST(CoarseSpace, AggregatesCoverEveryVertexOnceAndAreConnectedPatches) {
  const Stretched s = stretched_grid(20);
  const int n = s.model.num_vertices();
  ASSERT_FALSE(s.h.scalar_row_start.empty());
  for (int size : {2, 7, 64}) {
    const CoarseSpace cs(s.h, size);
    std::vector<int> count(cs.num_aggregates(), 0);
    for (int i = 0; i < n; ++i) {
      ASSERT_GE(cs.aggregate_of(i), 0);
      ASSERT_LT(cs.aggregate_of(i), cs.num_aggregates());
      ++count[cs.aggregate_of(i)];
    }
    EXPECT_LE(*std::max_element(count.begin(), count.end()), size);
    EXPECT_EQ(*std::max_element(count.begin(), count.end()), size);  // the grid has room
    EXPECT_LT(cs.num_aggregates(), n);
    // Connected: from one vertex of each aggregate, the matrix's graph (full and scalar
    // blocks) restricted to the aggregate reaches all of its vertices.
    std::vector<int> reached(cs.num_aggregates(), 0), seen(n, 0), stack;
    for (int i = 0; i < n; ++i) {
      const int a = cs.aggregate_of(i);
      if (reached[a] > 0) continue;
      stack.assign(1, i);
      seen[i] = 1;
      while (!stack.empty()) {
        const int v = stack.back();
        stack.pop_back();
        ++reached[a];
        auto visit = [&](int w) {
          if (!seen[w] && cs.aggregate_of(w) == a) {
            seen[w] = 1;
            stack.push_back(w);
          }
        };
        for (int q = s.h.row_start[v]; q < s.h.row_start[v + 1]; ++q)
          visit(s.h.cols[q]);
        for (int q = s.h.scalar_row_start[v]; q < s.h.scalar_row_start[v + 1]; ++q)
          visit(s.h.scalar_cols[q]);
      }
    }
    EXPECT_EQ(reached, count) << "size " << size;
  }
  EXPECT_THROW(CoarseSpace(s.h, 1), InputError);
}

TEST(CoarseSpace, CutsTheIterationsToTheSameAccuracyOnAStiffMembrane) {
  // From a zero start (no warm start), block Jacobi needs many iterations on the membrane's
  // smooth error; the coarse correction removes it. The stopping rule measures the residual in
  // the same (block-Jacobi) norm either way, so the two end at comparable true residuals.
  const Stretched s = stretched_grid(120);
  const int n = s.model.num_vertices();
  VertexFilter filter;
  filter.reset(n);
  const PcgOptions options{500, 1e-3};
  Vecs plain(n, Vec3::Zero());
  const PcgResult jacobi = solve_pcg(s.h, kC, s.model.mass(), s.b, filter, options, plain);
  ASSERT_TRUE(jacobi.converged);
  const double plain_residual = true_residual(s, filter, nullptr, plain);
  for (int size : {16, 64}) {
    CoarseSpace cs(s.h, size);
    cs.update(s.h, kC, s.model.mass(), nullptr);
    Vecs dv(n, Vec3::Zero());
    const PcgResult two_level =
        solve_pcg(s.h, kC, s.model.mass(), s.b, filter, options, dv, nullptr, &cs);
    ASSERT_TRUE(two_level.converged);
    EXPECT_LT(2 * two_level.iterations, jacobi.iterations)
        << "size " << size << ": " << two_level.iterations << " against " << jacobi.iterations;
    EXPECT_LT(true_residual(s, filter, nullptr, dv), 1.5 * plain_residual) << "size " << size;
  }
}

TEST(CoarseSpace, SolvesTheFilteredCoupledSystemBitForBitOnAnyThreadCount) {
  // Pinned and plane-constrained vertices and couplings between two distant rows: the solve
  // with the coarse correction ends where a tight block-Jacobi solve does, leaves the
  // prescribed components alone, and is the same on 1 and 2 threads.
  const Stretched s = stretched_grid(30);
  const int n = s.model.num_vertices();
  std::vector<double> inverse_mass(n);
  for (int i = 0; i < n; ++i)
    inverse_mass[i] = 1.0 / s.model.mass()[i];
  VertexFilter filter;
  filter.reset(n);
  std::mt19937_64 rng(5);
  Vecs start(n, Vec3::Zero());
  for (int i = 0; i < 31; ++i) {
    filter.kind[i] = VertexFilter::Pinned;  // the first row, moving by a prescribed change
    start[i] = Vec3(0, 1e-3, 0);
  }
  for (int i = 100; i < n; i += 37) {
    filter.kind[i] = VertexFilter::Plane;
    filter.direction[i] = random_vec(rng, 1.0).normalized();
  }
  std::vector<ContactCoupling> list;
  for (int k = 0; k < 31; ++k) {
    ContactCoupling c;
    c.vertex = {31 * 20 + k, 31 * 5 + k, -1, -1};
    c.c = {1.0, -1.0, 0.0, 0.0};
    c.n = Vec3::UnitY();
    list.push_back(c);
  }
  CouplingTerms couplings;
  couplings.reset(list, inverse_mass, 100.0);
  ASSERT_EQ(couplings.size(), 31);

  Vecs reference = start;
  ASSERT_TRUE(solve_pcg(s.h, kC, s.model.mass(), s.b, filter, PcgOptions{2000, 1e-12}, reference,
                        &couplings)
                  .converged);
  CoarseSpace cs(s.h, 32);
  cs.update(s.h, kC, s.model.mass(), &couplings);
  auto solve = [&](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    Vecs dv = start;
    const PcgResult r = solve_pcg(s.h, kC, s.model.mass(), s.b, filter, PcgOptions{2000, 1e-10}, dv,
                                  &couplings, &cs);
    EXPECT_TRUE(r.converged);
    return dv;
  };
  const Vecs one = solve(1), two = solve(2);
  double scale = 0.0;
  for (const Vec3& v : reference)
    scale = std::max(scale, v.norm());
  ASSERT_GT(scale, 0.0);
  for (int i = 0; i < n; ++i) {
    ASSERT_EQ(one[i], two[i]) << "vertex " << i;
    EXPECT_LE((one[i] - reference[i]).norm(), 1e-6 * scale) << "vertex " << i;
    if (filter.kind[i] == VertexFilter::Pinned) {
      EXPECT_EQ(one[i], start[i]);
    }
    if (filter.kind[i] == VertexFilter::Plane) {
      EXPECT_NEAR(filter.direction[i].dot(one[i]), 0.0, 1e-12 * scale);
    }
  }
}

}  // namespace
}  // namespace clothcd::sim
