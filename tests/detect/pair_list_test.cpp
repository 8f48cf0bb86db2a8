// The traversal's pair storage (pair_list.hpp): every pushed pair comes back once, in push order,
// through the views, the pieces (with their indices) and for_each; across block boundaries, after
// clear() and refilling with more or fewer pairs, and with several threads' blocks in one list.

#include <gtest/gtest.h>

#include <cstddef>
#include <vector>

#include "detect/pair_list.hpp"

namespace clothcd::pair_list_test {
namespace {

using detail::FacePair;
using detail::PairBlocks;
using detail::PairList;

std::vector<FacePair> numbered(std::size_t n, int salt) {
  std::vector<FacePair> out;
  for (std::size_t i = 0; i < n; ++i)
    out.emplace_back(static_cast<int>(i), static_cast<int>(i) * 7 + salt);
  return out;
}

// The pairs of `list` in its order, read three ways, each checked against `expect`.
void expect_list(const PairList& list, const std::vector<FacePair>& expect) {
  ASSERT_EQ(list.size(), expect.size());
  EXPECT_EQ(list.empty(), expect.empty());
  std::vector<FacePair> seen;
  list.for_each([&](std::size_t i, const FacePair& p) {
    EXPECT_EQ(i, seen.size());
    seen.push_back(p);
  });
  EXPECT_EQ(seen, expect);
  for (const std::size_t piece : {std::size_t{7}, std::size_t{64}, std::size_t{1000}}) {
    std::vector<FacePair> joined;
    for (const PairList::Piece& p : list.pieces(piece)) {
      ASSERT_FALSE(p.pairs.empty());
      ASSERT_LE(p.pairs.size(), piece);
      ASSERT_EQ(p.first, joined.size()) << "piece size " << piece;
      joined.insert(joined.end(), p.pairs.begin(), p.pairs.end());
    }
    EXPECT_EQ(joined, expect) << "piece size " << piece;
  }
}

PairList list_of(const PairBlocks& b) {
  PairList l;
  l.add(b);
  return l;
}

TEST(PairList, BlocksGiveBackEveryPairInOrder) {
  // Around the first block's capacity (65536) and over several of the larger blocks (524288).
  for (const std::size_t n : {0, 1, 65535, 65536, 65537, 589824, 1200000}) {
    SCOPED_TRACE(n);
    PairBlocks b;
    const auto pairs = numbered(n, 3);
    for (const auto& [x, y] : pairs)
      b.push(x, y);
    EXPECT_EQ(b.size(), n);
    expect_list(list_of(b), pairs);
  }
}

TEST(PairList, ClearKeepsTheMemoryAndForgetsThePairs) {
  PairBlocks b;
  for (const auto& [x, y] : numbered(70000, 1))
    b.push(x, y);
  std::vector<std::span<const FacePair>> before;
  b.views(before);
  // Fewer pairs, then more than before: each refill reads back exactly its own pairs.
  for (const std::size_t n : {std::size_t{10}, std::size_t{0}, std::size_t{600000}}) {
    SCOPED_TRACE(n);
    b.clear();
    EXPECT_EQ(b.size(), 0u);
    const auto pairs = numbered(n, static_cast<int>(n));
    for (const auto& [x, y] : pairs)
      b.push(x, y);
    expect_list(list_of(b), pairs);
    std::vector<std::span<const FacePair>> after;
    b.views(after);
    // The first block is the same memory as before clear().
    if (n > 0) {
      EXPECT_EQ(after.front().data(), before.front().data());
    }
  }
}

TEST(PairList, JoinsSeveralThreadsBlocksAndPlainSpans) {
  PairBlocks a, b, empty;
  const auto pa = numbered(5000, 11), pb = numbered(9000, 5), pc = numbered(17, 2);
  for (const auto& [x, y] : pa)
    a.push(x, y);
  for (const auto& [x, y] : pb)
    b.push(x, y);
  PairList l;
  l.add(a);
  l.add(empty);
  l.add(std::span<const FacePair>(pc));
  l.add(b);
  l.add(std::span<const FacePair>());
  std::vector<FacePair> expect = pa;
  expect.insert(expect.end(), pc.begin(), pc.end());
  expect.insert(expect.end(), pb.begin(), pb.end());
  expect_list(l, expect);
  expect_list(PairList(std::span<const FacePair>(pc)), pc);
  expect_list(PairList(), {});
}

}  // namespace
}  // namespace clothcd::pair_list_test
