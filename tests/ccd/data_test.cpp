// The Sample-Queries set (../shared/data/ccd-queries): zero false negatives on every file, false
// positives reported; the exact oracle agrees with the Mathematica ground truth; every reported
// time of impact is no later than the first contact.
#include <gtest/gtest.h>

#include <cmath>

#include "clothcd/ccd/query_csv.hpp"
#include "exact_oracle.hpp"
#include "support/data.hpp"

namespace clothcd {
namespace {

bool exact(QueryKind kind, const CsvQuery& q, double t_max = 1.0) {
  return kind == QueryKind::VertexFace ? test::exact_vertex_face_contact(to_vertex_face(q), t_max)
                                       : test::exact_edge_edge_contact(to_edge_edge(q), t_max);
}

std::vector<QueryFile> load(const std::filesystem::path& root) {
  std::vector<QueryFile> out;
  for (const auto& f : find_query_files({root})) {
    const auto kind = query_kind_from_path(f);
    if (!kind) continue;
    out.push_back(read_query_csv(f, *kind));
  }
  return out;
}

class CcdQueriesData : public ::testing::TestWithParam<bool> {};

TEST_P(CcdQueriesData, NoFalseNegativesAndEarlyToi) {
  CLOTHCD_REQUIRE_DATA(root, "ccd-queries");
  CcdOptions opt;
  opt.fast_path = GetParam();
  std::size_t total_fp = 0, total_q = 0;
  const auto files = load(root);
  ASSERT_FALSE(files.empty());
  for (const auto& file : files) {
    std::size_t fn = 0, fp = 0;
    for (const auto& q : file.queries) {
      const CcdResult r = run_query(file.kind, q, opt);
      ASSERT_TRUE(std::isfinite(r.toi));
      ASSERT_GE(r.toi, 0.0);
      ASSERT_LE(r.toi, 1.0);
      if (q.truth && !r.hit) {
        ++fn;
        ADD_FAILURE() << file.path.string() << ":" << q.first_line << ": false negative";
      }
      fp += !q.truth && r.hit;
      // Conservative time of impact: no contact strictly before it.
      if (q.truth && r.hit && r.toi > 0) {
        EXPECT_FALSE(exact(file.kind, q, std::nextafter(r.toi, 0.0)))
            << file.path.string() << ":" << q.first_line << ": contact before toi " << r.toi;
      }
    }
    EXPECT_EQ(fn, 0u) << file.path.string();
    std::printf("%-70s queries %5zu  FP %3zu\n", file.path.string().c_str(), file.queries.size(),
                fp);
    total_fp += fp;
    total_q += file.queries.size();
  }
  std::printf("total: %zu queries, %zu false positives (fast_path=%d)\n", total_q, total_fp,
              int(GetParam()));
}

INSTANTIATE_TEST_SUITE_P(FastPath, CcdQueriesData, ::testing::Bool());

// The oracle used by the random tests reproduces the Mathematica ground truth exactly.
TEST(CcdExactOracle, MatchesGroundTruth) {
  CLOTHCD_REQUIRE_DATA(root, "ccd-queries");
  std::size_t checked = 0;
  for (const auto& file : load(root)) {
    for (const auto& q : file.queries) {
      EXPECT_EQ(exact(file.kind, q), q.truth) << file.path.string() << ":" << q.first_line;
      ++checked;
    }
  }
  EXPECT_GT(checked, 0u);
}

}  // namespace
}  // namespace clothcd
