// The batched NP filter (SSE2, AVX2, AVX-512 and the dispatching entry) against the scalar filter,
// unscaled_np_filter: the same verdict for every query, on seeded random queries over many scales,
// near-coplanar and exactly coplanar ones, out-of-range magnitudes and non-finite coordinates;
// and no culled query that the exact oracle finds in contact. Likewise fast_path_settle against
// its scalar reference and the kernel, its misses and certified hits against the exact oracle;
// and make_motion's scale and coordinates against their definitions. The batched distance filter
// against distance_filter_culls, and its culls against the exact oracle.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "ccd/motion.hpp"
#include "ccd/np_batch.hpp"
#include "clothcd/ccd/proximity.hpp"
#include "exact_oracle.hpp"
#include "support/isa_paths.hpp"
#include "support/random_gen.hpp"

namespace clothcd::np_batch_test {
namespace {

using ccd_detail::Kind;
using ccd_detail::NpBatch;
using ccd_detail::NpVerdict;
using V = Eigen::Vector3d;
using Points = std::array<V, 8>;

using test::Gen;

// One query of family `family` (0..5).
Points make_query(Gen& g, int family) {
  Points p;
  switch (family) {
    case 0: {  // generic, log-uniform scale, including outside [2^-300, 2^100]
      const double s = std::ldexp(1.0, g.integer(-340, 140));
      const V shift = g.vec(4 * s);
      for (auto& x : p)
        x = shift + g.vec(s);
      break;
    }
    case 1: {  // near-coplanar: all points close to the plane z = 0, small motion
      const double s = std::ldexp(1.0, g.integer(-20, 20));
      const double eps = std::ldexp(s, -g.integer(10, 60));
      for (int i = 0; i < 4; ++i) {
        p[i] = V(g.uniform(-s, s), g.uniform(-s, s), g.uniform(-eps, eps));
        p[i + 4] = p[i] + V(g.uniform(-s, s) / 8, g.uniform(-s, s) / 8, g.uniform(-eps, eps));
      }
      break;
    }
    case 2: {  // small integer grid: exact coplanarity, zero coefficients, degenerate features
      const double s = std::ldexp(1.0, g.integer(-10, 10));
      for (auto& x : p)
        x = V(g.integer(-2, 2), g.integer(-2, 2), g.integer(-1, 1)) * s;
      if (g.integer(0, 1) == 0) {
        for (int i = 0; i < 4; ++i)
          p[i + 4] = p[i];
      }
      break;
    }
    case 3: {  // cloth-like: a small triangle and a nearby point or edge, sliding past
      const double s = 0.01;
      const V o = g.vec(1.0);
      for (int i = 0; i < 4; ++i) {
        p[i] = o + g.vec(s);
        p[i + 4] = p[i] + g.vec(s / 4);
      }
      break;
    }
    case 4: {  // subnormal and tiny coordinates
      const double s = std::ldexp(1.0, g.integer(-1074, -1000));
      for (auto& x : p)
        x = g.vec(s);
      break;
    }
    default: {  // a non-finite or huge coordinate somewhere
      for (auto& x : p)
        x = g.vec(1.0);
      const double bad[] = {std::numeric_limits<double>::infinity(),
                            -std::numeric_limits<double>::infinity(),
                            std::numeric_limits<double>::quiet_NaN(), 1e308, -1e308};
      p[g.integer(0, 7)][g.integer(0, 2)] = bad[g.integer(0, 4)];
      if (g.integer(0, 2) == 0) p[g.integer(0, 7)][g.integer(0, 2)] = bad[g.integer(0, 4)];
      break;
    }
  }
  return p;
}

void fill(NpBatch& b, const std::vector<Points>& qs) {
  b.size = 0;
  for (const Points& q : qs) {
    b.push({q[0].data(), q[1].data(), q[2].data(), q[3].data(), q[4].data(), q[5].data(),
            q[6].data(), q[7].data()});
  }
}

// Every instruction set the processor has gives the scalar verdicts on `qs` (at most a batch).
std::vector<NpVerdict> check_batch(Kind kind, const std::vector<Points>& qs) {
  NpBatch b;
  fill(b, qs);
  std::vector<NpVerdict> expect(qs.size()), got(NpBatch::kCapacity);
  EXPECT_TRUE(ccd_detail::np_filter_batch_with(0, kind, b, expect.data()));
  for (int isa = 1; isa <= 4; ++isa) {
    got.assign(got.size(), NpVerdict::Undecided);
    if (isa < 4) {
      const bool ran = ccd_detail::np_filter_batch_with(isa, kind, b, got.data());
      test::note_isa("np_filter_batch", isa, ran);
      if (!ran) continue;
    } else {
      ccd_detail::np_filter_batch(kind, b, got.data());
      test::note_isa("np_filter_batch", isa, true);
    }
    for (std::size_t i = 0; i < qs.size(); ++i) {
      EXPECT_EQ(got[i], expect[i]) << "isa " << isa << " query " << i;
    }
  }
  return expect;
}

VertexFaceQuery vf_query(const Points& p) {
  return {p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]};
}
EdgeEdgeQuery ee_query(const Points& p) {
  return {p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]};
}
// The GMP oracle's verdict on query p of this kind.
bool exact_contact(Kind kind, const Points& p) {
  return kind == Kind::VertexFace ? test::exact_vertex_face_contact(vf_query(p))
                                  : test::exact_edge_edge_contact(ee_query(p));
}

TEST(NpBatch, MatchesTheScalarFilterOnRandomQueries) {
  int culled = 0, kept = 0, undecided = 0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    Gen g(seed);
    for (const Kind kind : {Kind::VertexFace, Kind::EdgeEdge}) {
      std::vector<Points> qs;
      // Full batches and partial ones (every remainder of the vector widths).
      const int n = seed % 2 == 0 ? NpBatch::kCapacity : g.integer(1, NpBatch::kCapacity);
      for (int i = 0; i < n; ++i)
        qs.push_back(make_query(g, g.integer(0, 5)));
      for (const NpVerdict v : check_batch(kind, qs)) {
        culled += v == NpVerdict::Culled;
        kept += v == NpVerdict::Kept;
        undecided += v == NpVerdict::Undecided;
      }
    }
  }
  // Every verdict occurs, so each lane path was compared.
  EXPECT_GT(culled, 100);
  EXPECT_GT(kept, 100);
  EXPECT_GT(undecided, 100);
}

TEST(NpBatch, CullsNoQueryInContact) {
  int culled = 0;
  for (std::uint64_t seed = 100; seed < 106; ++seed) {
    Gen g(seed);
    for (const Kind kind : {Kind::VertexFace, Kind::EdgeEdge}) {
      std::vector<Points> qs;
      for (int i = 0; i < 64; ++i)
        qs.push_back(make_query(g, g.integer(1, 3)));  // the families with contacts
      const std::vector<NpVerdict> v = check_batch(kind, qs);
      for (std::size_t i = 0; i < qs.size(); ++i) {
        if (v[i] != NpVerdict::Culled) continue;
        ++culled;
        EXPECT_FALSE(exact_contact(kind, qs[i])) << "seed " << seed << " query " << i;
      }
    }
  }
  EXPECT_GT(culled, 50);
}

struct Settled {
  int kept = 0, missed = 0, hits = 0;
};

// fast_path_settle on `qs` (at most a batch) from every instruction set: the scalar reference's
// answers (times of impact bit for bit), each miss the kernel's own (no hit, path FastPath) and
// each hit the kernel's own (path Certified, the same time of impact). Returns the answers.
std::vector<ccd_detail::FastSettled> check_settled(Kind kind, const std::vector<Points>& qs,
                                                   Settled& n, double toi_tolerance = 1e-4) {
  using ccd_detail::FastSettled;
  NpBatch b;
  fill(b, qs);
  std::vector<NpVerdict> verdict(NpBatch::kCapacity);
  EXPECT_TRUE(ccd_detail::np_filter_batch_with(0, kind, b, verdict.data()));
  FastSettled expect[NpBatch::kCapacity], got[NpBatch::kCapacity];
  double expect_toi[NpBatch::kCapacity], got_toi[NpBatch::kCapacity];
  EXPECT_TRUE(ccd_detail::fast_path_settle_with(0, kind, b, verdict.data(), toi_tolerance, expect,
                                                expect_toi));
  for (int isa = 1; isa <= 4; ++isa) {
    std::fill(std::begin(got), std::end(got), FastSettled::Run);
    if (isa < 4) {
      const bool ran = ccd_detail::fast_path_settle_with(isa, kind, b, verdict.data(),
                                                         toi_tolerance, got, got_toi);
      test::note_isa("fast_path_settle", isa, ran);
      if (!ran) continue;
    } else {
      ccd_detail::fast_path_settle(kind, b, verdict.data(), toi_tolerance, got, got_toi);
      test::note_isa("fast_path_settle", isa, true);
    }
    for (std::size_t i = 0; i < qs.size(); ++i) {
      EXPECT_EQ(got[i], expect[i]) << "isa " << isa << " query " << i;
      if (got[i] == FastSettled::Hit && expect[i] == FastSettled::Hit) {
        EXPECT_EQ(got_toi[i], expect_toi[i]) << "isa " << isa << " query " << i;
      }
    }
  }
  std::vector<FastSettled> out(expect, expect + qs.size());
  CcdOptions opt;
  opt.fast_path = true;
  opt.toi_tolerance = toi_tolerance;
  for (std::size_t i = 0; i < qs.size(); ++i) {
    n.kept += verdict[i] == NpVerdict::Kept;
    if (expect[i] == FastSettled::Run) continue;
    EXPECT_EQ(verdict[i], NpVerdict::Kept);
    const CcdResult r = kind == Kind::VertexFace
                            ? ccd_detail::vertex_face_ccd_np_kept(vf_query(qs[i]), opt)
                            : ccd_detail::edge_edge_ccd_np_kept(ee_query(qs[i]), opt);
    if (expect[i] == FastSettled::Miss) {
      ++n.missed;
      EXPECT_FALSE(r.hit) << "query " << i;
      EXPECT_EQ(r.path, CcdPath::FastPath) << "query " << i;
    } else {
      ++n.hits;
      EXPECT_TRUE(r.hit) << "query " << i;
      EXPECT_EQ(r.path, CcdPath::Certified) << "query " << i;
      EXPECT_EQ(r.toi, expect_toi[i]) << "query " << i;
    }
  }
  return out;
}

TEST(FastPathSettle, MatchTheKernelOnRandomQueries) {
  Settled n;
  for (std::uint64_t seed = 200; seed < 240; ++seed) {
    Gen g(seed);
    for (const Kind kind : {Kind::VertexFace, Kind::EdgeEdge}) {
      std::vector<Points> qs;
      const int size = seed % 2 == 0 ? NpBatch::kCapacity : g.integer(1, NpBatch::kCapacity);
      for (int i = 0; i < size; ++i)
        qs.push_back(make_query(g, g.integer(0, 5)));
      // The kernel's default tolerance, none (refined to depth 40) and a coarse one.
      const double tolerance[] = {1e-4, 0.0, 0.05};
      check_settled(kind, qs, n, tolerance[seed % 3]);
    }
  }
  // Every answer occurs among the kept queries, so each lane path was compared.
  EXPECT_GT(n.missed, 100);
  EXPECT_GT(n.hits, 20);
  EXPECT_GT(n.kept - n.missed - n.hits, 20);
}

// Exactly coplanar motion (every point in z = 0: the cubic is zero, never of one sign): a vertex
// or an edge sliding along a long slanted edge, outside it by 2^-3..2^-9 of its travel. The
// inside test's intervals tell them apart only on short ranges, so the search examines every
// range down to that depth, often more ranges than the kernel's budget.
Points sliding_coplanar(Gen& g, Kind kind) {
  const double angle = g.uniform(0.2, 1.4);
  const V u(std::cos(angle), std::sin(angle), 0.0), n(-u.y(), u.x(), 0.0);
  const double gap = std::ldexp(1.0, -g.integer(3, 9));
  const double x0 = g.uniform(-0.6, -0.4), x1 = g.uniform(0.4, 0.6);
  Points p;
  if (kind == Kind::VertexFace) {  // p[0] the vertex below edge p[1]p[2] of the static triangle
    p[0] = x0 * u - gap * n;
    p[4] = x1 * u - gap * n;
    p[1] = p[5] = -0.8 * u;
    p[2] = p[6] = 0.8 * u;
    p[3] = p[7] = 0.8 * n;
  } else {  // edge p[0]p[1] across the line of static edge p[2]p[3], beyond it by the gap
    p[0] = x0 * u + gap * n;
    p[1] = x0 * u + (gap + 0.3) * n;
    p[4] = x1 * u + gap * n;
    p[5] = x1 * u + (gap + 0.3) * n;
    p[2] = p[6] = -0.8 * u;
    p[3] = p[7] = 0.8 * u;
  }
  return p;
}

TEST(FastPathSettle, MatchTheKernelOnSlidingCoplanarQueries) {
  Settled n;
  for (std::uint64_t seed = 400; seed < 404; ++seed) {
    Gen g(seed);
    for (const Kind kind : {Kind::VertexFace, Kind::EdgeEdge}) {
      std::vector<Points> qs;
      for (int i = 0; i < NpBatch::kCapacity; ++i)
        qs.push_back(sliding_coplanar(g, kind));
      check_settled(kind, qs, n);
    }
  }
  EXPECT_GT(n.missed, 10);
  EXPECT_GT(n.kept - n.missed - n.hits, 10);
}

TEST(FastPathSettle, MissNoQueryInContactAndHitOnlyThose) {
  Settled n;
  for (std::uint64_t seed = 300; seed < 306; ++seed) {
    Gen g(seed);
    for (const Kind kind : {Kind::VertexFace, Kind::EdgeEdge}) {
      std::vector<Points> qs;
      for (int i = 0; i < 64; ++i)
        qs.push_back(make_query(g, g.integer(1, 3)));  // the families with contacts
      const std::vector<ccd_detail::FastSettled> s = check_settled(kind, qs, n);
      for (std::size_t i = 0; i < qs.size(); ++i) {
        if (s[i] == ccd_detail::FastSettled::Run) continue;
        EXPECT_EQ(exact_contact(kind, qs[i]), s[i] == ccd_detail::FastSettled::Hit)
            << "seed " << seed << " query " << i;
      }
    }
  }
  EXPECT_GT(n.missed, 50);
  EXPECT_GT(n.hits, 10);
}

// Every instruction set gives distance_filter_culls' verdicts on `qs` (at most a batch), the
// finite queries marked Kept and every third of them left Culled or Undecided (never to be
// touched). Returns the scalar verdicts; counts the finite queries in `tested`.
std::vector<NpVerdict> check_distance(Kind kind, const std::vector<Points>& qs, double thickness,
                                      int depth, int& tested) {
  NpBatch b;
  fill(b, qs);
  std::vector<NpVerdict> given(qs.size());
  for (std::size_t i = 0; i < qs.size(); ++i) {
    const bool finite =
        std::all_of(qs[i].begin(), qs[i].end(), [](const V& x) { return x.allFinite(); });
    const NpVerdict other = i % 2 == 0 ? NpVerdict::Culled : NpVerdict::Undecided;
    given[i] = finite && i % 3 != 0 ? NpVerdict::Kept : other;
    tested += given[i] == NpVerdict::Kept;
  }
  std::vector<NpVerdict> expect = given, got;
  EXPECT_TRUE(ccd_detail::distance_filter_batch_with(0, kind, b, thickness, depth, expect.data()));
  for (std::size_t i = 0; i < qs.size(); ++i) {
    if (given[i] != NpVerdict::Kept) continue;
    const bool culls = kind == Kind::VertexFace
                           ? distance_filter_culls(vf_query(qs[i]), thickness, depth)
                           : distance_filter_culls(ee_query(qs[i]), thickness, depth);
    EXPECT_EQ(expect[i], culls ? NpVerdict::Culled : NpVerdict::Kept) << "query " << i;
  }
  for (int isa = 1; isa <= 4; ++isa) {
    got = given;
    if (isa < 4) {
      const bool ran =
          ccd_detail::distance_filter_batch_with(isa, kind, b, thickness, depth, got.data());
      test::note_isa("distance_filter_batch", isa, ran);
      if (!ran) continue;
    } else {
      ccd_detail::distance_filter_batch(kind, b, thickness, depth, got.data());
      test::note_isa("distance_filter_batch", isa, true);
    }
    for (std::size_t i = 0; i < qs.size(); ++i)
      EXPECT_EQ(got[i], expect[i]) << "isa " << isa << " depth " << depth << " query " << i;
  }
  return expect;
}

TEST(DistanceFilterBatch, MatchesTheScalarFilterOnRandomQueries) {
  int tested = 0, culled = 0;
  for (std::uint64_t seed = 500; seed < 540; ++seed) {
    Gen g(seed);
    for (const Kind kind : {Kind::VertexFace, Kind::EdgeEdge}) {
      std::vector<Points> qs;
      const int size = seed % 2 == 0 ? NpBatch::kCapacity : g.integer(1, NpBatch::kCapacity);
      for (int i = 0; i < size; ++i) {
        Points p = make_query(g, g.integer(0, 5));
        if (g.integer(0, 9) == 0) p[g.integer(0, 7)] = p[g.integer(0, 7)];  // a repeated point
        if (g.integer(0, 19) == 0) {  // a degenerate feature: all its points on one line
          for (int k = 1; k < 4; ++k)
            p[k] = p[0] + (k * 0.25) * (p[4] - p[0]);
        }
        qs.push_back(p);
      }
      const double thickness = seed % 4 == 0 ? std::ldexp(1.0, -g.integer(2, 30)) : 0.0;
      const std::vector<NpVerdict> v = check_distance(kind, qs, thickness, int(seed % 4), tested);
      culled += static_cast<int>(std::count(v.begin(), v.end(), NpVerdict::Culled));
    }
  }
  // Both verdicts occur often, so each lane path was compared.
  EXPECT_GT(tested, 2000);
  EXPECT_GT(culled, 1000);
}

TEST(DistanceFilterBatch, CullsNoQueryInContact) {
  int culled = 0;
  for (std::uint64_t seed = 540; seed < 546; ++seed) {
    Gen g(seed);
    for (const Kind kind : {Kind::VertexFace, Kind::EdgeEdge}) {
      std::vector<Points> qs;
      for (int i = 0; i < 96; ++i)
        qs.push_back(make_query(g, g.integer(1, 3)));  // the families with contacts
      for (int i = 0; i < 32; ++i)
        qs.push_back(sliding_coplanar(g, kind));
      int tested = 0;
      const std::vector<NpVerdict> v = check_distance(kind, qs, 0.0, 2, tested);
      for (std::size_t i = 0; i < qs.size(); ++i) {
        if (v[i] != NpVerdict::Culled || i % 3 == 0) continue;  // culled by the filter
        ++culled;
        EXPECT_FALSE(exact_contact(kind, qs[i])) << "seed " << seed << " query " << i;
      }
    }
  }
  EXPECT_GT(culled, 100);
}

// The filter's bound at depth 0, (d0 + d1 - D) / 2 with the distances or with their lower
// bounds, and its slack, computed as distance_filter.cpp does.
struct Bounds {
  double exact, lower, slack;
};
Bounds filter_bounds(Kind kind, const Points& p) {
  const auto dist = [&](int o) {
    return kind == Kind::VertexFace
               ? point_triangle_proximity(p[o], p[o + 1], p[o + 2], p[o + 3]).distance
               : edge_edge_proximity(p[o], p[o + 1], p[o + 2], p[o + 3]).distance;
  };
  const auto lower = [&](int o) {
    return kind == Kind::VertexFace
               ? point_triangle_distance_lower_bound(p[o], p[o + 1], p[o + 2], p[o + 3])
               : edge_edge_distance_lower_bound(p[o], p[o + 1], p[o + 2], p[o + 3]);
  };
  const int first = kind == Kind::VertexFace ? 1 : 2;
  double move = 0.0, top = 1.0;
  for (int i = 0; i < first; ++i) {
    for (int j = first; j < 4; ++j)
      move = std::max(move, ((p[i + 4] - p[i]) - (p[j + 4] - p[j])).squaredNorm());
  }
  for (const V& x : p)
    top = std::max(top, x.cwiseAbs().maxCoeff());
  move = std::sqrt(move);
  return {0.5 * (dist(0) + dist(4) - move), 0.5 * (lower(0) + lower(4) - move), 1e-12 * top};
}

// Makes the face (VF) nearly a segment, or the edges (EE) nearly parallel, at both times, the
// sine of the angle at the face's first corner, or between the edges, about the distances'
// thresholds for trusting the interior solution (1e-6 for a face, 1e-7 for two edges), either
// side; the vertex above the face's interior, the second edge crossing over the first's middle,
// so that the interior solution is the nearest candidate where it counts.
void thin(Gen& g, Kind kind, Points& p) {
  const double sine = (kind == Kind::VertexFace ? 1e-6 : 1e-7) * g.uniform(0.5, 2.0);
  const double along = g.uniform(0.2, 0.8), above = g.uniform(0.01, 0.5);
  for (const int o : {0, 4}) {
    if (kind == Kind::VertexFace) {
      const V a = p[o + 1], u = p[o + 2] - a;
      const V side = u.cross(V(0.3, -0.5, 0.8)).normalized() * u.norm();
      p[o + 3] = a + along * u + along * sine * side;
      p[o] = a + 0.5 * along * u + 0.25 * along * sine * side + above * u.cross(side) / u.norm();
    } else {
      const V a = p[o], u = p[o + 1] - a;
      const V side = u.cross(V(0.3, -0.5, 0.8)).normalized() * u.norm();
      p[o + 2] =
          a + 0.5 * (1 - along) * u - 0.5 * along * sine * side + above * u.cross(side) / u.norm();
      p[o + 3] = p[o + 2] + along * u + along * sine * side;
    }
  }
}

// At thicknesses that put the verdict on the last bit of either bound (one query per batch), so
// that any difference in a lane's rounding of the distances or slack shows, and any verdict that
// the scalar filter's first try with the lower bounds decides and the lanes' distances do not.
TEST(DistanceFilterBatch, MatchesTheScalarFilterAtItsThreshold) {
  int tested = 0, flips = 0;
  for (std::uint64_t seed = 560; seed < 580; ++seed) {
    Gen g(seed);
    for (const Kind kind : {Kind::VertexFace, Kind::EdgeEdge}) {
      for (int i = 0; i < 40; ++i) {
        Points p = make_query(g, g.integer(0, 4));
        if (i % 2 == 0) {
          Points q = p;  // moving little, so that the bound is positive
          for (int k = 0; k < 4; ++k)
            q[k + 4] = q[k] + g.vec(1e-3 * (q[1] - q[0]).norm());
          thin(g, kind, q);
          if (std::all_of(q.begin(), q.end(), [](const V& x) { return x.allFinite(); })) p = q;
        }
        const Bounds b = filter_bounds(kind, p);
        for (const double bound : {b.exact, b.lower}) {
          if (!(std::isfinite(bound) && bound > b.slack)) continue;
          const double t = bound - b.slack;
          std::vector<NpVerdict> at;
          for (const double th : {std::nextafter(t, 0.0), t, std::nextafter(t, INFINITY)}) {
            int n = 0;
            at.push_back(check_distance(kind, {p, p}, th, 0, n)[1]);
            tested += n;
          }
          flips += at.front() != at.back();
        }
      }
    }
  }
  EXPECT_GT(tested, 1000);
  EXPECT_GT(flips, 300);  // the thresholds were reached
}

// make_motion's scale: std::frexp's exponent, applied with std::ldexp, for every magnitude.
TEST(FastPathSettle, InverseBinadeIsFrexpAndLdexp) {
  Gen g(11);
  std::vector<double> ms = {0.0, std::numeric_limits<double>::denorm_min(),
                            std::numeric_limits<double>::min(), std::numeric_limits<double>::max(),
                            0.5, 1.0, std::nextafter(1.0, 0.0), 0x1p-1022, 0x1p-1023, 0x1p1023,
                            // Either side of the largest m whose scale comes from its bits alone.
                            std::nextafter(0x1p1021, 0.0), 0x1p1021, std::nextafter(0x1p1022, 0.0),
                            0x1p1022};
  for (int i = 0; i < 20000; ++i) {
    const double m = std::ldexp(g.uniform(0.5, 1.0), g.integer(-1080, 1024));
    if (std::isfinite(m)) ms.push_back(m);
  }
  for (const double m : ms) {
    int e = 0;
    if (m > 0) std::frexp(m, &e);
    const double want = std::ldexp(1.0, -e);
    EXPECT_EQ(ccd_detail::inverse_binade(m), want) << m;
  }
}

// make_motion against its vector-expression form, coordinate for coordinate.
TEST(FastPathSettle, MakeMotionMatchesItsVectorForm) {
  for (std::uint64_t seed = 400; seed < 420; ++seed) {
    Gen g(seed);
    for (int i = 0; i < 200; ++i) {
      Points p = make_query(g, g.integer(0, 4));
      if (g.integer(0, 9) == 0) p[g.integer(0, 7)] = V::Zero();
      std::array<const V*, 8> pts;
      for (int k = 0; k < 8; ++k)
        pts[k] = &p[k];
      double m = 0;
      for (const V& x : p)
        m = std::max(m, x.cwiseAbs().maxCoeff());
      int e = 0;
      if (m > 0) std::frexp(m, &e);
      V lo = V::Constant(INFINITY), hi = -lo, top = V::Zero();
      const ccd_detail::Motion got = ccd_detail::make_motion(pts);
      ASSERT_EQ(got.scale_exponent, -e);
      // 2^-e, or 0 where it is no double (every coordinate below 2^-1023).
      ASSERT_EQ(got.scale, -e <= DBL_MAX_EXP - 1 ? std::ldexp(1.0, -e) : 0.0);
      ASSERT_EQ(got.largest, m);
      const auto scaled = [e](const V& x) {
        return V(std::ldexp(x[0], -e), std::ldexp(x[1], -e), std::ldexp(x[2], -e));
      };
      for (int k = 0; k < 4; ++k) {
        const V a = scaled(p[k]), b = scaled(p[k + 4]);
        for (const V* x : {&a, &b}) {
          lo = lo.cwiseMin(*x);
          hi = hi.cwiseMax(*x);
          top = top.cwiseMax(x->cwiseAbs());
        }
        for (int c = 0; c < 3; ++c) {
          EXPECT_EQ(std::bit_cast<std::uint64_t>(got.x0[k][c]), std::bit_cast<std::uint64_t>(a[c]));
          EXPECT_EQ(std::bit_cast<std::uint64_t>(got.x1[k][c]), std::bit_cast<std::uint64_t>(b[c]));
        }
      }
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(got.max_abs[c], top[c]);
      EXPECT_EQ(got.extent, (hi - lo).maxCoeff());
    }
  }
}

}  // namespace
}  // namespace clothcd::np_batch_test
