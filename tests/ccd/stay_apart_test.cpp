// stay_apart (the earliest-impact query's cheap proof that a pair stays apart over [0, hi]) never
// clears a pair that comes within the distance: every pair it clears is checked by sampling the
// exact distance along the motion and, at zero distance, by the exact rational oracle. Cases: the
// near-touching pairs that cost the inclusion search the most (nearly parallel edges a fraction of
// a micrometre apart that slide along each other, as on a stitched seam; a vertex resting on a
// face), random pairs, and pairs that do close the gap, which it must not clear.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <random>

#include "ccd/inclusion.hpp"
#include "ccd/motion.hpp"
#include "ccd/refine.hpp"
#include "clothcd/ccd/proximity.hpp"
#include "exact_oracle.hpp"

namespace clothcd {
namespace {

using V = Eigen::Vector3d;

V lerp(const V& a, const V& b, double t) {
  return a + t * (b - a);
}

// Smallest exact distance at 4001 instants of [0, hi], and at the instants bisected around the
// smallest sample.
template <class At>
double sampled_min(At&& at, double hi) {
  constexpr int kSamples = 4000;
  double best = INFINITY;
  int arg = 0;
  for (int i = 0; i <= kSamples; ++i) {
    const double d = at(hi * i / kSamples);
    if (d < best) {
      best = d;
      arg = i;
    }
  }
  double lo = hi * std::max(0, arg - 1) / kSamples,
         up = hi * std::min(kSamples, arg + 1) / kSamples;
  for (int k = 0; k < 60; ++k) {  // the distance is convex in no parameter: a local refinement
    const double a = lo + (up - lo) / 3, b = up - (up - lo) / 3;
    const double da = at(a), db = at(b);
    best = std::min({best, da, db});
    (da < db ? up : lo) = da < db ? b : a;
  }
  return best;
}

double distance_at(const EdgeEdgeQuery& q, double t) {
  return edge_edge_proximity(lerp(q.ea0_t0, q.ea0_t1, t), lerp(q.ea1_t0, q.ea1_t1, t),
                             lerp(q.eb0_t0, q.eb0_t1, t), lerp(q.eb1_t0, q.eb1_t1, t))
      .distance;
}
double distance_at(const VertexFaceQuery& q, double t) {
  return point_triangle_proximity(lerp(q.v_t0, q.v_t1, t), lerp(q.f0_t0, q.f0_t1, t),
                                  lerp(q.f1_t0, q.f1_t1, t), lerp(q.f2_t0, q.f2_t1, t))
      .distance;
}
template <class Query>
double min_distance(const Query& q, double hi) {
  return sampled_min([&](double t) { return distance_at(q, t); }, hi);
}

struct Counts {
  int cleared = 0, total = 0;
};

// Checks one query at distance h over [0, hi]; counts whether stay_apart cleared it.
template <class Query>
void check(const Query& q, double hi, double h, Counts& c) {
  ++c.total;
  if (!ccd_detail::stay_apart(q, hi, h)) return;
  ++c.cleared;
  const double d = min_distance(q, hi);
  ASSERT_GT(d, h) << "cleared a pair that comes within " << h << " (sampled " << d << ")";
  if (h == 0) {
    Query r = q;  // the exact oracle over [0, 1]: the motion rescaled to [0, hi]
    if constexpr (std::is_same_v<Query, EdgeEdgeQuery>) {
      r.ea0_t1 = lerp(q.ea0_t0, q.ea0_t1, hi);
      r.ea1_t1 = lerp(q.ea1_t0, q.ea1_t1, hi);
      r.eb0_t1 = lerp(q.eb0_t0, q.eb0_t1, hi);
      r.eb1_t1 = lerp(q.eb1_t0, q.eb1_t1, hi);
      ASSERT_FALSE(test::exact_edge_edge_contact(r));
    } else {
      r.v_t1 = lerp(q.v_t0, q.v_t1, hi);
      r.f0_t1 = lerp(q.f0_t0, q.f0_t1, hi);
      r.f1_t1 = lerp(q.f1_t0, q.f1_t1, hi);
      r.f2_t1 = lerp(q.f2_t0, q.f2_t1, hi);
      ASSERT_FALSE(test::exact_vertex_face_contact(r));
    }
  }
}

V random_unit(std::mt19937& rng) {
  std::normal_distribution<double> n;
  V v(n(rng), n(rng), n(rng));
  return v.normalized();
}

// Two nearly parallel edges of length ~1 cm, `gap` apart, overlapping along their length, each
// end moved by up to `move` over the step, mostly along the edges (a seam sliding on itself).
EdgeEdgeQuery seam_pair(std::mt19937& rng, double gap, double tilt, double move) {
  std::uniform_real_distribution<double> u(-1, 1);
  const V origin(u(rng), u(rng), u(rng));
  const V dir = random_unit(rng);
  V side = dir.cross(random_unit(rng)).normalized();
  const double len = 0.01 * (1 + 0.5 * u(rng));
  EdgeEdgeQuery q;
  q.ea0_t0 = origin;
  q.ea1_t0 = origin + len * (dir + tilt * u(rng) * side).normalized();
  const V shift = 0.3 * len * u(rng) * dir + gap * dir.cross(side).normalized();
  q.eb0_t0 = origin + shift;
  q.eb1_t0 = origin + shift + len * (dir + tilt * u(rng) * side).normalized();
  const auto moved = [&](const V& x) {
    return V(x + move * (dir * u(rng) + 0.01 * random_unit(rng)));
  };
  q.ea0_t1 = moved(q.ea0_t0);
  q.ea1_t1 = moved(q.ea1_t0);
  q.eb0_t1 = moved(q.eb0_t0);
  q.eb1_t1 = moved(q.eb1_t0);
  return q;
}

// A vertex `gap` above a face of size ~1 cm, both moving by up to `move` (mostly in the plane).
VertexFaceQuery resting_pair(std::mt19937& rng, double gap, double move) {
  std::uniform_real_distribution<double> u(-1, 1), w(0.05, 0.9);
  const V origin(u(rng), u(rng), u(rng));
  const V n = random_unit(rng);
  const V e1 = n.cross(random_unit(rng)).normalized(), e2 = n.cross(e1);
  VertexFaceQuery q;
  q.f0_t0 = origin;
  q.f1_t0 = origin + 0.01 * e1;
  q.f2_t0 = origin + 0.01 * (0.3 * e1 + e2);
  const double a = w(rng), b = w(rng) * (1 - a);
  q.v_t0 = q.f0_t0 + a * (q.f1_t0 - q.f0_t0) + b * (q.f2_t0 - q.f0_t0) + gap * n;
  const auto moved = [&](const V& x) {
    return V(x + move * (e1 * u(rng) + e2 * u(rng) + 0.01 * n * u(rng)));
  };
  q.v_t1 = moved(q.v_t0);
  q.f0_t1 = moved(q.f0_t0);
  q.f1_t1 = moved(q.f1_t0);
  q.f2_t1 = moved(q.f2_t0);
  return q;
}

TEST(StayApart, ClearsSlidingSeamsOnlyWhenTheyStayApart) {
  std::mt19937 rng(7);
  Counts c;
  for (int i = 0; i < 120; ++i) {
    const double gap = std::ldexp(1.0, -20 - i % 8);  // 1e-6 .. 7e-9
    const EdgeEdgeQuery q = seam_pair(rng, gap, i % 3 == 0 ? 0.0 : 1e-6, 1e-3);
    for (const double hi : {1.0, 1e-2, 1e-4})
      for (const double h : {0.0, 0.25 * gap, 0.9 * gap})
        check(q, hi, h, c);
  }
  // The cases it exists for: most of them are settled without a search.
  EXPECT_GT(c.cleared, c.total / 2) << c.cleared << " of " << c.total;
}

TEST(StayApart, ClearsRestingVerticesOnlyWhenTheyStayApart) {
  std::mt19937 rng(11);
  Counts c;
  for (int i = 0; i < 120; ++i) {
    const double gap = std::ldexp(1.0, -18 - i % 10);
    const VertexFaceQuery q = resting_pair(rng, gap, 1e-3);
    for (const double hi : {1.0, 1e-2, 1e-4})
      for (const double h : {0.0, 0.5 * gap})
        check(q, hi, h, c);
  }
  EXPECT_GT(c.cleared, c.total / 2) << c.cleared << " of " << c.total;
}

TEST(StayApart, NeverClearsPairsThatClose) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  Counts c;
  int touching = 0;
  for (int i = 0; i < 120; ++i) {
    // Random pairs in a unit cube with random motions: some meet, some do not.
    EdgeEdgeQuery e;
    VertexFaceQuery f;
    for (V* x : {&e.ea0_t0, &e.ea1_t0, &e.eb0_t0, &e.eb1_t0, &f.v_t0, &f.f0_t0, &f.f1_t0, &f.f2_t0})
      *x = V(u(rng), u(rng), u(rng));
    const double move = i % 2 == 0 ? 0.1 : 2.0;
    e.ea0_t1 = e.ea0_t0 + move * random_unit(rng);
    e.ea1_t1 = e.ea1_t0 + move * random_unit(rng);
    e.eb0_t1 = e.eb0_t0 + move * random_unit(rng);
    e.eb1_t1 = e.eb1_t0 + move * random_unit(rng);
    f.v_t1 = f.v_t0 + move * random_unit(rng);
    f.f0_t1 = f.f0_t0 + move * random_unit(rng);
    f.f1_t1 = f.f1_t0 + move * random_unit(rng);
    f.f2_t1 = f.f2_t0 + move * random_unit(rng);
    for (const double h : {0.0, 0.05}) {
      check(e, 1.0, h, c);
      check(f, 1.0, h, c);
    }
    // The pairs that touch, by the exact oracle, are never cleared.
    if (test::exact_edge_edge_contact(e)) {
      ++touching;
      EXPECT_FALSE(ccd_detail::stay_apart(e, 1.0, 0.0));
    }
    if (test::exact_vertex_face_contact(f)) {
      ++touching;
      EXPECT_FALSE(ccd_detail::stay_apart(f, 1.0, 0.0));
    }
  }
  // And pairs made to pass through each other: an edge crossing another, a vertex crossing a
  // face's interior, at random times of the step.
  std::uniform_real_distribution<double> w(0.2, 0.8), n(-0.05, 0.05);
  for (int i = 0; i < 40; ++i) {
    const double z = w(rng);  // the crossing at t = z
    EdgeEdgeQuery e;
    e.ea0_t0 = e.ea0_t1 = V(0, n(rng), n(rng));
    e.ea1_t0 = e.ea1_t1 = V(1, n(rng), n(rng));
    e.eb0_t0 = V(w(rng), -0.5, z);
    e.eb1_t0 = V(w(rng), 0.5, z);
    e.eb0_t1 = e.eb0_t0 - V(0, 0, 1);
    e.eb1_t1 = e.eb1_t0 - V(0, 0, 1);
    VertexFaceQuery f;
    f.f0_t0 = f.f0_t1 = V(0, 0, n(rng));
    f.f1_t0 = f.f1_t1 = V(1, 0, n(rng));
    f.f2_t0 = f.f2_t1 = V(0, 1, n(rng));
    f.v_t0 = V(0.25, 0.25, z);
    f.v_t1 = f.v_t0 - V(0, 0, 1);
    ASSERT_TRUE(test::exact_edge_edge_contact(e));
    ASSERT_TRUE(test::exact_vertex_face_contact(f));
    touching += 2;
    for (const double hi : {1.0, std::min(1.0, z + 0.1)}) {
      ASSERT_TRUE(test::exact_edge_edge_contact(e, hi));
      ASSERT_TRUE(test::exact_vertex_face_contact(f, hi));
      EXPECT_FALSE(ccd_detail::stay_apart(e, hi, 0.0));
      EXPECT_FALSE(ccd_detail::stay_apart(f, hi, 0.0));
    }
  }
  EXPECT_GT(touching, 80);
  // A pair touching at t0 is never cleared.
  EdgeEdgeQuery start = seam_pair(rng, 0.0, 1e-6, 1e-3);
  start.eb0_t0 = start.ea0_t0;
  EXPECT_FALSE(ccd_detail::stay_apart(start, 1.0, 0.0));
  EXPECT_GT(c.cleared, 0);
}

// The inclusion solver's settings for a query at zero thickness, as the kernels set them.
ccd_detail::InclusionParams solver_params(const ccd_detail::Motion& m) {
  const CcdOptions o;
  ccd_detail::InclusionParams p;
  p.tolerance = o.tolerance * m.extent;
  p.toi_tolerance = o.toi_tolerance;
  p.max_boxes = o.max_boxes;
  return p;
}

TEST(StayApart, BoundedSearchesEndWhereTheWholeBudgetWouldRunOut) {
  // Seam pairs 40-400 nm apart sliding along each other (and drifting across by up to 10 um):
  // the plain search tiles their near-contact line until its budget runs out and reports a hit;
  // the bounded one proves many of them apart (each checked by the exact oracle) and otherwise
  // gives the plain search's answer. Wherever the plain search ends within its budget, both give
  // the same outcome.
  std::mt19937 rng(5);
  int exhausted = 0, settled = 0;
  for (int i = 0; i < 60; ++i) {
    const EdgeEdgeQuery q = seam_pair(rng, 4e-8 * (1 + i % 10), i % 2 == 0 ? 0.0 : 1e-6, 1e-3);
    const std::array<const V*, 8> x = {&q.ea0_t0, &q.ea1_t0, &q.eb0_t0, &q.eb1_t0,
                                       &q.ea0_t1, &q.ea1_t1, &q.eb0_t1, &q.eb1_t1};
    const ccd_detail::Motion m = ccd_detail::make_motion(x);
    const ccd_detail::InclusionParams p = solver_params(m);
    const ccd_detail::InclusionOutcome plain =
        ccd_detail::inclusion_solve(ccd_detail::Kind::EdgeEdge, m, p);
    const ccd_detail::InclusionOutcome bounded =
        ccd_detail::bounded_inclusion_solve(ccd_detail::Kind::EdgeEdge, m, p);
    if (plain.boxes > p.max_boxes) {
      ++exhausted;
      if (!bounded.hit) {
        ++settled;
        EXPECT_FALSE(test::exact_edge_edge_contact(q));
      } else {  // not proven apart: the whole search ran again, with its own answer
        EXPECT_EQ(bounded.toi, plain.toi);
      }
    } else {
      EXPECT_EQ(bounded.hit, plain.hit);
      EXPECT_EQ(bounded.toi, plain.toi);
    }
  }
  EXPECT_GT(exhausted, 0);
  EXPECT_GE(settled, 10) << settled << " of " << exhausted;
}

TEST(StayApart, CertifiedDistanceIsTheKernelsBound) {
  // sqrt(3) (h + tolerance L), L the largest coordinate range of the eight points, and a
  // rounding allowance.
  EdgeEdgeQuery q;
  q.ea0_t0 = V(0, 0, 0);
  q.ea1_t0 = V(2, 0, 0);
  q.eb0_t0 = V(0, 1, 0);
  q.eb1_t0 = V(1, 1, 0.5);
  q.ea0_t1 = q.ea0_t0;
  q.ea1_t1 = q.ea1_t0;
  q.eb0_t1 = q.eb0_t0;
  q.eb1_t1 = q.eb1_t0;
  CcdOptions o;
  o.thickness = 0.01;
  const double plain = std::sqrt(3.0) * (0.01 + 1e-6 * 2);
  const double d = ccd_detail::certified_distance(q, o);
  EXPECT_GE(d, plain);  // widened by the rounding bound only
  EXPECT_LE(d, plain * (1 + 1e-8));
}

}  // namespace
}  // namespace clothcd
