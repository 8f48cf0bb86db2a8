// A table of named degenerate CCD cases. Each states the expected answer, which the exact oracle
// must confirm (so the table itself is checked), and the kernel must report every contact, with a
// time of impact no later than the first one, in both modes (fast path on and off).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "clothcd/ccd/queries.hpp"
#include "exact_oracle.hpp"

namespace clothcd {
namespace {

using V = Eigen::Vector3d;

enum class Expect {
  hit,
  miss,       ///< separated by far more than the tolerance: the kernel must say no too
  near_miss,  ///< no contact, but a false positive is allowed
};

struct VfCase {
  std::string name;
  VertexFaceQuery q;
  Expect expect;
  double latest_toi = 1;  ///< for hits: the first contact is no later than this
};

struct EeCase {
  std::string name;
  EdgeEdgeQuery q;
  Expect expect;
  double latest_toi = 1;
};

// Static triangle in z = 0 with corners (0,0,0), (1,0,0), (0,1,0); the vertex moves v0 -> v1.
VertexFaceQuery vf_static(const V& v0, const V& v1) {
  const V a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  return {v0, a, b, c, v1, a, b, c};
}

EdgeEdgeQuery ee(const V& a0, const V& a1, const V& b0, const V& b1, const V& da, const V& db) {
  return {a0, a1, b0, b1, a0 + da, a1 + da, b0 + db, b1 + db};
}

VertexFaceQuery transform(VertexFaceQuery q, double s, const V& shift) {
  for (V* p : {&q.v_t0, &q.f0_t0, &q.f1_t0, &q.f2_t0, &q.v_t1, &q.f0_t1, &q.f1_t1, &q.f2_t1}) {
    *p = *p * s + shift;
  }
  return q;
}
std::vector<V> points_of(const VertexFaceQuery& q) {
  return {q.v_t0, q.f0_t0, q.f1_t0, q.f2_t0, q.v_t1, q.f0_t1, q.f1_t1, q.f2_t1};
}
std::vector<V> points_of(const EdgeEdgeQuery& q) {
  return {q.ea0_t0, q.ea1_t0, q.eb0_t0, q.eb1_t0, q.ea0_t1, q.ea1_t1, q.eb0_t1, q.eb1_t1};
}

EdgeEdgeQuery transform(EdgeEdgeQuery q, double s, const V& shift) {
  for (V* p :
       {&q.ea0_t0, &q.ea1_t0, &q.eb0_t0, &q.eb1_t0, &q.ea0_t1, &q.ea1_t1, &q.eb0_t1, &q.eb1_t1}) {
    *p = *p * s + shift;
  }
  return q;
}

std::vector<VfCase> vf_cases() {
  const double eps = std::ldexp(1.0, -40);
  std::vector<VfCase> c = {
      {"through_face", vf_static({0.25, 0.25, 1}, {0.25, 0.25, -1}), Expect::hit, 0.5},
      {"coplanar_slide_in", vf_static({-1, 0.25, 0}, {0.5, 0.25, 0}), Expect::hit, 2.0 / 3},
      {"coplanar_slide_past", vf_static({-1, 2, 0}, {2, 2, 0}), Expect::miss},
      {"coplanar_inside_throughout", vf_static({0.2, 0.2, 0}, {0.3, 0.3, 0}), Expect::hit, 0},
      {"contact_at_t0", vf_static({0.25, 0.25, 0}, {0.25, 0.25, 1}), Expect::hit, 0},
      {"contact_at_t1", vf_static({0.25, 0.25, 1}, {0.25, 0.25, 0}), Expect::hit, 1},
      {"through_edge", vf_static({0.5, 0, 1}, {0.5, 0, -1}), Expect::hit, 0.5},
      {"through_corner", vf_static({0, 0, 1}, {0, 0, -1}), Expect::hit, 0.5},
      {"through_hypotenuse", vf_static({0.5, 0.5, 1}, {0.5, 0.5, -1}), Expect::hit, 0.5},
      {"outside_by_eps", vf_static({0.5, -eps, 1}, {0.5, -eps, -1}), Expect::near_miss},
      {"inside_by_eps", vf_static({0.5, eps, 1}, {0.5, eps, -1}), Expect::hit, 0.5},
      {"beyond_hypotenuse_by_eps", vf_static({0.5 + eps, 0.5, 1}, {0.5 + eps, 0.5, -1}),
       Expect::near_miss},
      {"stops_eps_short", vf_static({0.25, 0.25, 1}, {0.25, 0.25, eps}), Expect::near_miss},
      {"zero_motion_touching", vf_static({0.25, 0.25, 0}, {0.25, 0.25, 0}), Expect::hit, 0},
      {"zero_motion_apart", vf_static({0.25, 0.25, 1}, {0.25, 0.25, 1}), Expect::miss},
      {"far_above_moving_sideways", vf_static({-5, 0.2, 1}, {5, 0.2, 1}), Expect::miss},
  };
  // Degenerate faces.
  {
    const V a(0, 0, 0), b(1, 0, 0), d(2, 0, 0);
    c.push_back(
        {"collinear_face_hit", {V(0.5, 0, 1), a, b, d, V(0.5, 0, -1), a, b, d}, Expect::hit, 0.5});
    c.push_back(
        {"collinear_face_miss", {V(0.5, 0.1, 1), a, b, d, V(0.5, 0.1, -1), a, b, d}, Expect::miss});
    c.push_back({"point_face_hit", {V(0, 0, 1), a, a, a, V(0, 0, -1), a, a, a}, Expect::hit, 0.5});
    c.push_back({"point_face_miss", {V(0, 1, 1), a, a, a, V(0, 1, -1), a, a, a}, Expect::miss});
  }
  // The face moves onto a resting vertex; the face flips (normal reverses) while the vertex passes.
  {
    const V a(0, 0, 1), b(1, 0, 1), cc(0, 1, 1), down(0, 0, -2);
    c.push_back({"face_moves_onto_vertex",
                 {V(0.2, 0.2, 0), a, b, cc, V(0.2, 0.2, 0), a + down, b + down, cc + down},
                 Expect::hit,
                 0.5});
    c.push_back({"face_flips_through_vertex",
                 {V(0.1, 0.1, 0), V(0, 0, 0), V(1, 0, 1), V(0, 1, 1), V(0.1, 0.1, 0), V(0, 0, 0),
                  V(1, 0, -1), V(0, 1, -1)},
                 Expect::hit,
                 0.5});
  }
  // The face tilts about its x = 0 edge while the vertex rests on that edge.
  c.push_back({"on_hinge_edge",
               {V(0, 0.5, 0), V(0, 0, 0), V(0, 1, 0), V(1, 0, 1), V(0, 0.5, 0), V(0, 0, 0),
                V(0, 1, 0), V(1, 0, -1)},
               Expect::hit,
               0});
  return c;
}

std::vector<EeCase> ee_cases() {
  const double eps = std::ldexp(1.0, -40);
  const V z(0, 0, 0), down(0, 0, -2);
  std::vector<EeCase> c = {
      {"crossing", ee({0, 0, 1}, {1, 0, 1}, {0.5, -1, 0}, {0.5, 1, 0}, down, z), Expect::hit, 0.5},
      {"crossing_misses_by_eps",
       ee({0, 0, 1}, {1, 0, 1}, {1 + eps, -1, 0}, {1 + eps, 1, 0}, down, z), Expect::near_miss},
      {"crossing_hits_by_eps", ee({0, 0, 1}, {1, 0, 1}, {1 - eps, -1, 0}, {1 - eps, 1, 0}, down, z),
       Expect::hit, 0.5},
      {"endpoint_on_edge", ee({0, 0, 1}, {1, 0, 1}, {1, -1, 0}, {1, 1, 0}, down, z), Expect::hit,
       0.5},
      {"endpoint_on_endpoint", ee({0, 0, 1}, {1, 0, 1}, {1, 0, 0}, {1, 1, 0}, down, z), Expect::hit,
       0.5},
      {"parallel_overlap", ee({0, 0, 1}, {1, 0, 1}, {0.5, 0, 0}, {1.5, 0, 0}, down, z), Expect::hit,
       0.5},
      {"parallel_offset", ee({0, 0, 1}, {1, 0, 1}, {0.5, 0.1, 0}, {1.5, 0.1, 0}, down, z),
       Expect::miss},
      {"parallel_end_to_end", ee({0, 0, 1}, {1, 0, 1}, {1, 0, 0}, {2, 0, 0}, down, z), Expect::hit,
       0.5},
      {"parallel_gap_eps", ee({0, 0, 1}, {1, 0, 1}, {1 + eps, 0, 0}, {2, 0, 0}, down, z),
       Expect::near_miss},
      {"collinear_slide_overlap", ee({0, 0, 0}, {1, 0, 0}, {2.5, 0, 0}, {3, 0, 0}, {2, 0, 0}, z),
       Expect::hit, 0.75},
      {"collinear_slide_short", ee({0, 0, 0}, {1, 0, 0}, {5, 0, 0}, {6, 0, 0}, {2, 0, 0}, z),
       Expect::miss},
      {"collinear_overlap_static", ee({0, 0, 0}, {1, 0, 0}, {0.5, 0, 0}, {3, 0, 0}, z, z),
       Expect::hit, 0},
      {"coplanar_slide_cross", ee({-1, 0, 0}, {-1, 1, 0}, {0, -1, 0}, {0, 2, 0}, {2, 0, 0}, z),
       Expect::hit, 0.5},
      {"coplanar_slide_miss", ee({-1, 0, 0}, {-1, 1, 0}, {0, 3, 0}, {0, 4, 0}, {2, 0, 0}, z),
       Expect::miss},
      {"contact_at_t0", ee({0, 0, 0}, {1, 0, 0}, {0.5, -1, 0}, {0.5, 1, 0}, {0, 0, 1}, z),
       Expect::hit, 0},
      {"contact_at_t1", ee({0, 0, 1}, {1, 0, 1}, {0.5, -1, 0}, {0.5, 1, 0}, {0, 0, -1}, z),
       Expect::hit, 1},
      {"stops_eps_short", ee({0, 0, 1}, {1, 0, 1}, {0.5, -1, 0}, {0.5, 1, 0}, {0, 0, -1 + eps}, z),
       Expect::near_miss},
      {"zero_length_edge_hit", ee({0.5, 0, 1}, {0.5, 0, 1}, {0, 0, 0}, {1, 0, 0}, down, z),
       Expect::hit, 0.5},
      {"both_points_hit", ee({0.5, 0, 1}, {0.5, 0, 1}, {0.5, 0, 0}, {0.5, 0, 0}, down, z),
       Expect::hit, 0.5},
      {"both_points_miss", ee({0.5, 0, 1}, {0.5, 0, 1}, {0.5, 1, 0}, {0.5, 1, 0}, down, z),
       Expect::miss},
      {"zero_motion_touching", ee({0, 0, 0}, {1, 0, 0}, {0.5, -1, 0}, {0.5, 1, 0}, z, z),
       Expect::hit, 0},
      {"zero_motion_apart", ee({0, 0, 1}, {1, 0, 1}, {0.5, -1, 0}, {0.5, 1, 0}, z, z),
       Expect::miss},
      {"skew_pass_above", ee({0, 0, 1}, {1, 0, 1}, {0.5, -1, 0}, {0.5, 1, 0}, {0, 5, 0}, z),
       Expect::miss},
  };
  // Rotating edge sweeping over a static one: contact in mid-motion with a twisting line.
  c.push_back({"twisting_edge",
               {V(-1, 0, 1), V(1, 0, -1), V(0, -1, 0), V(0, 1, 0), V(-1, 0, -1), V(1, 0, 1),
                V(0, -1, 0), V(0, 1, 0)},
               Expect::hit,
               0.5});
  return c;
}

// Scales and shifts under which every case is re-run (powers of two keep the geometry exact).
struct Frame {
  const char* name;
  double scale;
  V shift;
};
const Frame kFrames[] = {
    {"unit", 1, V(0, 0, 0)},
    {"huge", std::ldexp(1.0, 900), V(0, 0, 0)},
    {"tiny", std::ldexp(1.0, -900), V(0, 0, 0)},
    {"subnormal_range", std::ldexp(1.0, -1040), V(0, 0, 0)},
    {"offset", 1, V(1024, -2048, 512)},
    {"small_far", std::ldexp(1.0, -20), V(3, 5, -7)},
};

template <class Q>
bool oracle(const Q& q, double t_max = 1) {
  if constexpr (std::is_same_v<Q, VertexFaceQuery>) {
    return test::exact_vertex_face_contact(q, t_max);
  } else {
    return test::exact_edge_edge_contact(q, t_max);
  }
}
template <class Q>
CcdResult kernel(const Q& q, const CcdOptions& opt) {
  if constexpr (std::is_same_v<Q, VertexFaceQuery>) {
    return vertex_face_ccd(q, opt);
  } else {
    return edge_edge_ccd(q, opt);
  }
}

template <class Case>
void check(const Case& c) {
  for (const Frame& f : kFrames) {
    const auto q = transform(c.q, f.scale, f.shift * f.scale);
    // Offsets and subnormal scales are not exact for every case: the oracle says what the
    // transformed query does, and the table's expectation is checked on the exact frames.
    const bool truth = oracle(q);
    const bool exact_frame = std::string(f.name) == "unit" || std::string(f.name) == "huge" ||
                             std::string(f.name) == "tiny";
    if (exact_frame) {
      ASSERT_EQ(truth, c.expect == Expect::hit) << c.name << " in frame " << f.name;
    }
    for (bool fast : {true, false}) {
      CcdOptions opt;
      opt.fast_path = fast;
      const CcdResult r = kernel(q, opt);
      const std::string where = c.name + " in frame " + f.name + (fast ? " (fast)" : " (incl)");
      ASSERT_TRUE(r.toi >= 0 && r.toi <= 1) << where;
      if (truth) {
        EXPECT_TRUE(r.hit) << where << ": false negative";
        if (r.hit && r.toi > 0) {
          EXPECT_FALSE(oracle(q, std::nextafter(r.toi, 0.0))) << where << ": toi " << r.toi;
        }
        if (exact_frame) {
          EXPECT_LE(r.toi, c.latest_toi) << where;
        }
      } else if (exact_frame && c.expect == Expect::miss) {
        EXPECT_FALSE(r.hit) << where << ": clear miss reported as a hit";
      }
    }
  }
}

TEST(CcdDegenerate, VertexFaceTable) {
  for (const auto& c : vf_cases())
    check(c);
}

TEST(CcdDegenerate, EdgeEdgeTable) {
  for (const auto& c : ee_cases())
    check(c);
}

// Scaling a query by a power of two changes nothing, also where every coordinate ends up below
// 2^-1023 (subnormal or nearly): the kernel must give the unit-scale query's answer and time of
// impact, in both modes. Coordinates on a grid of 1/16 up to 64 scale exactly to 2^-1050.
TEST(CcdDegenerate, AllSubnormalQueriesAnswerAsAtUnitScale) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> grid(-1024, 1024);
  auto point = [&] {
    V p;
    for (int a = 0; a < 3; ++a)
      p[a] = grid(rng) / 16.0;
    return p;
  };
  int hits = 0, misses = 0;
  for (int i = 0; i < 2000; ++i) {
    const V d = point() / 8;  // short motions: a mix of contacts and misses
    const VertexFaceQuery vf{point(),     point(),     point(),     point(),
                             point() + d, point() + d, point() + d, point() + d};
    const EdgeEdgeQuery ee{point(), point(), point(), point(), point(), point(), point(), point()};
    for (int k : {-1040, -1050}) {
      const auto svf = transform(vf, std::ldexp(1.0, k), V::Zero());
      const auto see = transform(ee, std::ldexp(1.0, k), V::Zero());
      // Back in two exact steps (2^-k itself is no double).
      const double half = std::ldexp(1.0, -k / 2), rest = std::ldexp(1.0, -k - (-k / 2));
      ASSERT_EQ(points_of(transform(transform(svf, half, V::Zero()), rest, V::Zero())),
                points_of(vf));
      ASSERT_EQ(points_of(transform(transform(see, half, V::Zero()), rest, V::Zero())),
                points_of(ee));
      for (bool fast : {true, false}) {
        CcdOptions opt;
        opt.fast_path = fast;
        const std::string where =
            std::to_string(i) + " at 2^" + std::to_string(k) + (fast ? " (fast)" : " (incl)");
        const CcdResult want_vf = vertex_face_ccd(vf, opt), got_vf = vertex_face_ccd(svf, opt);
        EXPECT_EQ(got_vf.hit, want_vf.hit) << "VF " << where;
        EXPECT_EQ(got_vf.toi, want_vf.toi) << "VF " << where;
        const CcdResult want_ee = edge_edge_ccd(ee, opt), got_ee = edge_edge_ccd(see, opt);
        EXPECT_EQ(got_ee.hit, want_ee.hit) << "EE " << where;
        EXPECT_EQ(got_ee.toi, want_ee.toi) << "EE " << where;
        (want_vf.hit ? hits : misses) += 1;
        (want_ee.hit ? hits : misses) += 1;
      }
    }
  }
  EXPECT_GT(hits, 100);
  EXPECT_GT(misses, 100);
}

TEST(CcdDegenerate, ThicknessContactsBeforeTouching) {
  // The vertex falls from z = 1 to z = -1: with thickness h it is in contact from t = (1 - h)/2.
  const auto q = vf_static({0.25, 0.25, 1}, {0.25, 0.25, -1});
  for (double h : {1e-6, 1e-3, 0.1, 0.5}) {
    CcdOptions opt;
    opt.thickness = h;
    const CcdResult r = vertex_face_ccd(q, opt);
    EXPECT_TRUE(r.hit) << h;
    EXPECT_LE(r.toi, (1 - h) / 2) << h;
  }
  // Passing 0.3 above the face: a contact for h >= 0.3 only.
  const auto above = vf_static({-1, 0.25, 0.3}, {2, 0.25, 0.3});
  CcdOptions thin;
  thin.thickness = 0.29;
  EXPECT_FALSE(vertex_face_ccd(above, thin).hit);
  CcdOptions thick;
  thick.thickness = 0.31;
  EXPECT_TRUE(vertex_face_ccd(above, thick).hit);
  // Parallel edges 0.2 apart, never closer.
  const auto par = ee({0, 0, 0}, {1, 0, 0}, {0, 0.2, 0}, {1, 0.2, 0}, {0, 0, 1}, {0, 0, 1});
  thin.thickness = 0.19;
  thick.thickness = 0.21;
  EXPECT_FALSE(edge_edge_ccd(par, thin).hit);
  EXPECT_TRUE(edge_edge_ccd(par, thick).hit);
}

TEST(CcdDegenerate, NonFiniteInputThrows) {
  auto q = vf_static({0.25, 0.25, 1}, {0.25, 0.25, -1});
  q.f1_t1.y() = std::nan("");
  EXPECT_THROW((void)vertex_face_ccd(q), std::invalid_argument);
  EXPECT_THROW((void)np_filter_culls(q), std::invalid_argument);
  auto e = ee({0, 0, 1}, {1, 0, 1}, {0.5, -1, 0}, {0.5, 1, 0}, {0, 0, -2}, {0, 0, 0});
  e.eb0_t0.x() = INFINITY;
  EXPECT_THROW((void)edge_edge_ccd(e), std::invalid_argument);
  CcdOptions bad;
  bad.thickness = -1;
  EXPECT_THROW((void)vertex_face_ccd(vf_static({0, 0, 1}, {0, 0, -1}), bad), std::invalid_argument);
}

TEST(CcdDegenerate, NpFilterCullsSeparatedAndKeepsContacts) {
  // Vertex stays above the face: every Bernstein coefficient is positive.
  EXPECT_TRUE(np_filter_culls(vf_static({0.25, 0.25, 1}, {3, 3, 0.5})));
  for (const auto& c : vf_cases()) {
    if (c.expect == Expect::hit) {
      EXPECT_FALSE(np_filter_culls(c.q)) << c.name;
    }
  }
  for (const auto& c : ee_cases()) {
    if (c.expect == Expect::hit) {
      EXPECT_FALSE(np_filter_culls(c.q)) << c.name;
    }
  }
}

}  // namespace
}  // namespace clothcd
