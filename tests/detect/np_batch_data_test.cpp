// The batched NP filter on real queries, the candidate pairs of cloth_ball 92 -> 93: the same
// verdict as the scalar filter from every instruction set, no culled pair among the ground-truth
// collisions, and every answer of the vector fast path (miss or certified hit) the kernel's own;
// and the narrow phase's queued path (FeatureContext::queue_vf, queue_ee, flush) gives the scalar
// path's collisions, times of impact and counters under every filter setting, at zero thickness
// and at a thickness.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <span>

#include "clothcd/mesh/io.hpp"
#include "detect/narrow.hpp"
#include "support/data.hpp"
#include "support/isa_paths.hpp"
#include "support/json_file.hpp"

namespace clothcd::np_batch_data_test {
namespace {

using test::read_json;

struct Candidates {
  std::vector<std::pair<int, int>> vf, ee;  // (vertex, face), (edge, edge) with edge ids < ...
  std::vector<bool> vf_truth, ee_truth;
};

Candidates candidates(const std::filesystem::path& root, int nv, int ne) {
  Candidates c;
  const auto vf = read_json(root / "boxes/92vf.json");
  const auto ee = read_json(root / "boxes/92ee.json");
  for (const auto& t : read_json(root / "mma_bool/92vf_mma_bool.json"))
    c.vf_truth.push_back(t.get<bool>());
  for (const auto& t : read_json(root / "mma_bool/92ee_mma_bool.json"))
    c.ee_truth.push_back(t.get<bool>());
  for (const auto& p : vf)
    c.vf.emplace_back(p[0].get<int>(), p[1].get<int>() - nv - ne);
  for (const auto& p : ee) {
    const int a = p[0].get<int>() - nv, b = p[1].get<int>() - nv;
    c.ee.emplace_back(std::min(a, b), std::max(a, b));
  }
  return c;
}

struct Frames {
  std::vector<Eigen::Vector3d> x0, x1;
  Topology topo;
};

Frames frames(const std::filesystem::path& root) {
  const TriangleMesh m0 = read_mesh(root / "frames/cloth_ball92.ply");
  const TriangleMesh m1 = read_mesh(root / "frames/cloth_ball93.ply");
  Frames f;
  f.topo = Topology(m0.faces, m0.num_vertices());
  for (int i = 0; i < m0.num_vertices(); ++i) {
    f.x0.push_back(m0.vertices[i]);
    f.x1.push_back(m1.vertices[i]);
  }
  return f;
}

// The candidates a batch at a time: every instruction set's verdicts against the scalar ones.
template <class PointsOf>
void compare_verdicts(ccd_detail::Kind kind, const std::vector<std::pair<int, int>>& pairs,
                      const std::vector<bool>& truth, PointsOf&& points_of) {
  using ccd_detail::NpVerdict;
  ccd_detail::NpBatch b;
  std::vector<NpVerdict> expect(ccd_detail::NpBatch::kCapacity), got(expect.size());
  std::size_t culled = 0;
  for (std::size_t start = 0; start < pairs.size(); start += ccd_detail::NpBatch::kCapacity) {
    b.size = 0;
    const std::size_t end = std::min(pairs.size(), start + ccd_detail::NpBatch::kCapacity);
    for (std::size_t i = start; i < end; ++i)
      b.push(points_of(pairs[i]));
    ASSERT_TRUE(ccd_detail::np_filter_batch_with(0, kind, b, expect.data()));
    for (int isa = 1; isa <= 3; ++isa) {
      const bool ran = ccd_detail::np_filter_batch_with(isa, kind, b, got.data());
      test::note_isa("np_filter_batch", isa, ran);
      if (!ran) continue;
      for (int i = 0; i < b.size; ++i)
        ASSERT_EQ(got[i], expect[i]) << "isa " << isa << " pair " << start + i;
    }
    for (int i = 0; i < b.size; ++i) {
      if (expect[i] != NpVerdict::Culled) continue;
      ++culled;
      EXPECT_FALSE(truth[start + i]) << "a colliding pair culled: " << start + i;
    }
  }
  EXPECT_GT(culled, 0u);
}

TEST(NpBatchData, ClothBallCandidatesMatchTheScalarFilter) {
  CLOTHCD_REQUIRE_DATA(root, "cloth-ball");
  const Frames f = frames(root);
  const Candidates c = candidates(root, f.topo.num_vertices(), f.topo.num_edges());
  ASSERT_EQ(c.vf.size(), c.vf_truth.size());
  ASSERT_EQ(c.ee.size(), c.ee_truth.size());
  compare_verdicts(ccd_detail::Kind::VertexFace, c.vf, c.vf_truth, [&](std::pair<int, int> p) {
    const Face& t = f.topo.faces()[p.second];
    const int v = p.first;
    return std::array<const double*, 8>{f.x0[v].data(),    f.x0[t[0]].data(), f.x0[t[1]].data(),
                                        f.x0[t[2]].data(), f.x1[v].data(),    f.x1[t[0]].data(),
                                        f.x1[t[1]].data(), f.x1[t[2]].data()};
  });
  compare_verdicts(ccd_detail::Kind::EdgeEdge, c.ee, c.ee_truth, [&](std::pair<int, int> p) {
    const Edge& a = f.topo.edges()[p.first];
    const Edge& b = f.topo.edges()[p.second];
    return std::array<const double*, 8>{f.x0[a[0]].data(), f.x0[a[1]].data(), f.x0[b[0]].data(),
                                        f.x0[b[1]].data(), f.x1[a[0]].data(), f.x1[a[1]].data(),
                                        f.x1[b[0]].data(), f.x1[b[1]].data()};
  });
}

struct Settled {
  std::size_t kept = 0, missed = 0, hits = 0;
};

// fast_path_settle on `pairs` a batch at a time: every instruction set gives the scalar
// reference's answers (times of impact bit for bit); each miss is the kernel's (no hit, path
// FastPath) and, where `truth` is given, no ground-truth collision; each hit is the kernel's
// (path Certified, the same time of impact). Adds to the counts in `n`.
template <class PointsOf, class Kernel>
void compare_settled(ccd_detail::Kind kind, const std::vector<std::pair<int, int>>& pairs,
                     const std::vector<bool>& truth, PointsOf&& points_of, Kernel&& kernel,
                     const CcdOptions& opt, Settled& n) {
  using ccd_detail::FastSettled;
  using ccd_detail::NpVerdict;
  constexpr int kCap = ccd_detail::NpBatch::kCapacity;
  ccd_detail::NpBatch b;
  std::vector<NpVerdict> verdict(kCap);
  FastSettled expect[kCap], got[kCap];
  double expect_toi[kCap], got_toi[kCap];
  for (std::size_t start = 0; start < pairs.size(); start += kCap) {
    b.size = 0;
    const std::size_t end = std::min(pairs.size(), start + kCap);
    for (std::size_t i = start; i < end; ++i)
      b.push(points_of(pairs[i]));
    ccd_detail::np_filter_batch(kind, b, verdict.data());
    EXPECT_TRUE(ccd_detail::fast_path_settle_with(0, kind, b, verdict.data(), opt.toi_tolerance,
                                                  expect, expect_toi));
    for (int isa = 1; isa <= 3; ++isa) {
      const bool ran = ccd_detail::fast_path_settle_with(isa, kind, b, verdict.data(),
                                                         opt.toi_tolerance, got, got_toi);
      test::note_isa("fast_path_settle", isa, ran);
      if (!ran) continue;
      for (int i = 0; i < b.size; ++i) {
        EXPECT_EQ(got[i], expect[i]) << "isa " << isa << " pair " << start + i;
        if (got[i] == FastSettled::Hit && expect[i] == FastSettled::Hit) {
          EXPECT_EQ(got_toi[i], expect_toi[i]) << "isa " << isa << " pair " << start + i;
        }
      }
    }
    for (int i = 0; i < b.size; ++i) {
      n.kept += verdict[i] == NpVerdict::Kept;
      if (expect[i] == FastSettled::Run) continue;
      const CcdResult r = kernel(pairs[start + i]);
      if (expect[i] == FastSettled::Miss) {
        ++n.missed;
        if (!truth.empty()) {
          EXPECT_FALSE(truth[start + i]) << "a colliding pair missed: " << start + i;
        }
        EXPECT_FALSE(r.hit) << "pair " << start + i;
        EXPECT_EQ(r.path, CcdPath::FastPath) << "pair " << start + i;
      } else {
        ++n.hits;
        EXPECT_TRUE(r.hit) << "pair " << start + i;
        EXPECT_EQ(r.path, CcdPath::Certified) << "pair " << start + i;
        EXPECT_EQ(r.toi, expect_toi[i]) << "pair " << start + i;
      }
    }
    if (::testing::Test::HasFailure()) break;
  }
}

TEST(NpBatchData, ClothBallSettledQueriesAreTheKernelsAnswers) {
  CLOTHCD_REQUIRE_DATA(root, "cloth-ball");
  const Frames f = frames(root);
  Candidates c = candidates(root, f.topo.num_vertices(), f.topo.num_edges());
  // The benchmark's candidates nearly all collide: add the close pairs of the mesh itself, every
  // vertex and edge (a sample) against the faces and edges within two rings, the pairs a
  // detection step tests most.
  const Topology& t = f.topo;
  std::vector<int> ring;
  const auto two_ring = [&](std::span<const int> start) {
    ring.clear();
    for (int h : start) {
      for (int w : t.faces()[h]) {
        for (int g : t.vertex_faces(w))
          ring.push_back(g);
      }
    }
    std::sort(ring.begin(), ring.end());
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
  };
  for (int v = 0; v < t.num_vertices(); v += 7) {
    two_ring(t.vertex_faces(v));
    for (int g : ring) {
      const Face& tg = t.faces()[g];
      if (v != tg[0] && v != tg[1] && v != tg[2]) c.vf.emplace_back(v, g);
    }
  }
  for (int e = 0; e < t.num_edges(); e += 11) {
    two_ring(t.edge_faces(e));
    const Edge& a = t.edges()[e];
    for (int g : ring) {
      for (int d : t.face_edges(g)) {
        const Edge& b = t.edges()[d];
        if (d > e && a[0] != b[0] && a[0] != b[1] && a[1] != b[0] && a[1] != b[1]) {
          c.ee.emplace_back(e, d);
        }
      }
    }
  }
  c.vf_truth.clear();
  c.ee_truth.clear();
  CcdOptions opt;
  opt.fast_path = true;
  Settled n;
  compare_settled(
      ccd_detail::Kind::VertexFace, c.vf, c.vf_truth,
      [&](std::pair<int, int> p) {
        const Face& t = f.topo.faces()[p.second];
        const int v = p.first;
        return std::array<const double*, 8>{f.x0[v].data(),    f.x0[t[0]].data(), f.x0[t[1]].data(),
                                            f.x0[t[2]].data(), f.x1[v].data(),    f.x1[t[0]].data(),
                                            f.x1[t[1]].data(), f.x1[t[2]].data()};
      },
      [&](std::pair<int, int> p) {
        const Face& t = f.topo.faces()[p.second];
        const int v = p.first;
        return ccd_detail::vertex_face_ccd_np_kept({f.x0[v], f.x0[t[0]], f.x0[t[1]], f.x0[t[2]],
                                                    f.x1[v], f.x1[t[0]], f.x1[t[1]], f.x1[t[2]]},
                                                   opt);
      },
      opt, n);
  compare_settled(
      ccd_detail::Kind::EdgeEdge, c.ee, c.ee_truth,
      [&](std::pair<int, int> p) {
        const Edge& a = f.topo.edges()[p.first];
        const Edge& b = f.topo.edges()[p.second];
        return std::array<const double*, 8>{f.x0[a[0]].data(), f.x0[a[1]].data(), f.x0[b[0]].data(),
                                            f.x0[b[1]].data(), f.x1[a[0]].data(), f.x1[a[1]].data(),
                                            f.x1[b[0]].data(), f.x1[b[1]].data()};
      },
      [&](std::pair<int, int> p) {
        const Edge& a = f.topo.edges()[p.first];
        const Edge& b = f.topo.edges()[p.second];
        return ccd_detail::edge_edge_ccd_np_kept({f.x0[a[0]], f.x0[a[1]], f.x0[b[0]], f.x0[b[1]],
                                                  f.x1[a[0]], f.x1[a[1]], f.x1[b[0]], f.x1[b[1]]},
                                                 opt);
      },
      opt, n);
  // Many pairs the NP filter keeps end at the first inside tests, even these close ones; most of
  // the benchmark's colliding pairs are certified hits.
  EXPECT_GT(n.missed, n.kept / 5);
  EXPECT_GT(n.hits, n.kept / 10);
  EXPECT_LE(n.missed + n.hits, n.kept);
}

// Every `stride`-th candidate pair through ctx's scalar path (kernel_vf, kernel_ee) and its queued
// path (queue_vf, queue_ee, flush): the same counters, and the same collisions with the same
// times of impact in the same order. Returns the scalar path's counters and collisions.
struct Tested {
  detail::FeatureCounters counters;
  std::size_t collisions = 0;
};
Tested expect_queued_equal_scalar(const detail::FeatureContext& ctx, const Candidates& c,
                                  std::size_t stride) {
  detail::FeatureCounters sc, qc;
  std::vector<VertexFaceCollision> svf, qvf;
  std::vector<EdgeEdgeCollision> see, qee;
  detail::FeatureBatch batch;
  for (std::size_t i = 0; i < c.vf.size(); i += stride) {
    const auto [v, face] = c.vf[i];
    ctx.kernel_vf(v, face, sc, svf);
    ctx.queue_vf(v, face, batch, qc, qvf);
  }
  for (std::size_t i = 0; i < c.ee.size(); i += stride) {
    const auto [a, b] = c.ee[i];
    ctx.kernel_ee(a, b, sc, see);
    ctx.queue_ee(a, b, batch, qc, qee);
  }
  ctx.flush(batch, qc, qvf, qee);
  EXPECT_EQ(qc.vf_tests, sc.vf_tests);
  EXPECT_EQ(qc.ee_tests, sc.ee_tests);
  EXPECT_EQ(qc.vf_np, sc.vf_np);
  EXPECT_EQ(qc.ee_np, sc.ee_np);
  // Same lists, in the same order (the queue keeps the order of the pairs), times of impact
  // included.
  EXPECT_EQ(qvf, svf);
  EXPECT_EQ(qee, see);
  return {sc, svf.size() + see.size()};
}

TEST(NpBatchData, QueuedPairsGiveTheScalarResults) {
  CLOTHCD_REQUIRE_DATA(root, "cloth-ball");
  const Frames f = frames(root);
  const Candidates c = candidates(root, f.topo.num_vertices(), f.topo.num_edges());
  // A few linked vertex pairs, so that the queue's link check is exercised too.
  const std::vector<std::pair<int, int>> links = {
      {c.vf[0].first, f.topo.faces()[c.vf[0].second][0]},
      {f.topo.edges()[c.ee[1].first][0], f.topo.edges()[c.ee[1].second][1]}};
  const auto sorted = detail::sorted_links(links, f.topo.num_vertices());
  for (const bool np : {true, false}) {
    for (const bool fast : {true, false}) {
      if (!np && !fast) continue;  // the inclusion solver alone: slow, and nothing batched
      SCOPED_TRACE(testing::Message() << "np_filter " << np << " fast_path " << fast);
      DetectOptions o;
      o.np_filter = np;
      o.fast_path = fast;
      const detail::FeatureContext ctx = detail::ccd_context(f.topo, f.x0, f.x1, o, sorted);
      ASSERT_NE(ctx.plan.batch, detail::FeatureFilter::None);
      ASSERT_NE(ctx.plan.batch, detail::FeatureFilter::Distance);
      expect_queued_equal_scalar(ctx, c, 1);
    }
  }
}

// At a thickness the queue runs the distance filter vectorised (a simulator's setting: depth 6,
// a coarse time-of-impact tolerance); on a sample of the candidates, whose survivors take the
// thick kernel's inclusion solve. The candidates of the whole step all come close enough to
// defeat the filter, so the step is shortened to a fraction of its motion (a substep's), where
// it culls most, some only after bisections.
TEST(NpBatchData, QueuedPairsGiveTheScalarResultsAtAThickness) {
  CLOTHCD_REQUIRE_DATA(root, "cloth-ball");
  const Frames f = frames(root);
  const Candidates c = candidates(root, f.topo.num_vertices(), f.topo.num_edges());
  std::vector<Eigen::Vector3d> x1(f.x0.size());
  for (std::size_t i = 0; i < x1.size(); ++i)
    x1[i] = f.x0[i] + 0.05 * (f.x1[i] - f.x0[i]);
  for (const double thickness : {1e-5, 1e-3}) {
    for (const int depth : {0, 6}) {
      SCOPED_TRACE(testing::Message() << "thickness " << thickness << " depth " << depth);
      DetectOptions o;
      o.thickness = thickness;
      o.distance_filter_depth = depth;
      o.toi_tolerance = 0.05;
      const detail::FeatureContext ctx = detail::ccd_context(f.topo, f.x0, x1, o);
      ASSERT_EQ(ctx.plan.batch, detail::FeatureFilter::Distance);
      const Tested t = expect_queued_equal_scalar(ctx, c, 16);
      const detail::FeatureCounters& n = t.counters;
      // The filter culls most pairs but not all; the thicker step has collisions.
      EXPECT_GT(n.vf_np, n.vf_tests / 2);
      EXPECT_GT(n.ee_np, n.ee_tests / 2);
      EXPECT_LT(n.vf_np + n.ee_np, n.vf_tests + n.ee_tests);
      if (thickness == 1e-3) {
        EXPECT_GT(t.collisions, 0u);
      }
    }
  }
}

}  // namespace
}  // namespace clothcd::np_batch_data_test
