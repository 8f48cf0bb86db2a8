// The query CSV reader: exact values, kinds from folder names, and a clear error (file and line)
// for each kind of malformed input.
#include <gtest/gtest.h>

#include <string>

#include "clothcd/ccd/query_csv.hpp"
#include "clothcd/core/error.hpp"

namespace clothcd {
namespace {

std::string rows(int n, const std::string& row = "1,2,-3,4,5,8,1") {
  std::string s;
  for (int i = 0; i < n; ++i)
    s += row + "\n";
  return s;
}

TEST(CcdQueryCsv, ParsesExactValues) {
  std::string text = "1,2,-3,4,5,2596148429267413814265248164610048,1\n" + rows(15);
  const auto qs = parse_query_csv(text, "t.csv");
  ASSERT_EQ(qs.size(), 2u);
  EXPECT_EQ(qs[0].points[0].x(), 0.5);
  EXPECT_EQ(qs[0].points[0].y(), -0.75);
  EXPECT_EQ(qs[0].points[0].z(), std::ldexp(5.0, -111));
  EXPECT_TRUE(qs[0].truth);
  EXPECT_EQ(qs[0].first_line, 1u);
  EXPECT_EQ(qs[1].first_line, 9u);
}

void expect_error(const std::string& text, const std::string& needle) {
  try {
    (void)parse_query_csv(text, "bad.csv");
    ADD_FAILURE() << "no error for: " << needle;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("bad.csv"), std::string::npos) << msg;
    EXPECT_NE(msg.find(needle), std::string::npos) << msg;
  }
}

TEST(CcdQueryCsv, MalformedInputNamesFileAndLine) {
  expect_error("", "empty");
  expect_error(rows(3) + "1,2,3\n" + rows(4), "bad.csv:4: expected 7");
  expect_error(rows(1) + "1,2,x,4,5,8,1\n" + rows(6), "bad.csv:2: column 3 is not an integer");
  expect_error(rows(1) + "1.5,2,3,4,5,8,1\n" + rows(6), "bad.csv:2:");
  expect_error(rows(5) + "1,0,3,4,5,8,1\n" + rows(2), "bad.csv:6: zero denominator");
  expect_error(rows(9), "not a multiple of 8");
  expect_error(rows(7) + "1,2,-3,4,5,8,0\n", "bad.csv:8: truth 0 differs");
  expect_error(rows(7) + "1,2,-3,4,5,8,2\n", "bad.csv:8: truth must be 0 or 1");
}

TEST(CcdQueryCsv, KindFromFolder) {
  EXPECT_EQ(query_kind_from_path("a/b/vertex-face/data_0_0.csv"), QueryKind::VertexFace);
  EXPECT_EQ(query_kind_from_path("a/edge-edge/x/data.csv"), QueryKind::EdgeEdge);
  EXPECT_FALSE(query_kind_from_path("a/b/data.csv").has_value());
  EXPECT_THROW((void)find_query_files({"/nonexistent/ccd/path"}), InputError);
}

TEST(CcdQueryCsv, RunsTheRightKernel) {
  // A vertex falling through a face; read as EE it is two edges that never meet.
  const std::string text =
      "1,4,1,4,1,1,1\n0,1,0,1,0,1,1\n1,1,0,1,0,1,1\n0,1,1,1,0,1,1\n"
      "1,4,1,4,-1,1,1\n0,1,0,1,0,1,1\n1,1,0,1,0,1,1\n0,1,1,1,0,1,1\n";
  const auto qs = parse_query_csv(text, "t.csv");
  ASSERT_EQ(qs.size(), 1u);
  EXPECT_TRUE(run_query(QueryKind::VertexFace, qs[0]).hit);
  EXPECT_FALSE(run_query(QueryKind::EdgeEdge, qs[0]).hit);
}

}  // namespace
}  // namespace clothcd
