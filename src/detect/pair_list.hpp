#pragma once
// The triangle pairs the traversal hands to the narrow phase, stored per thread in blocks.
//
// Why blocks: one step of a large mesh finds millions of pairs (docs/detect.md, What it costs). A
// growing vector copies them at every doubling and touches about twice that memory, and merging
// the threads' vectors into one copies them again. Fresh memory is dear (each page is faulted in
// and zeroed), so the blocks are never moved, the narrow phase reads them where they are, and a
// detector keeps them for its next call.

#include <algorithm>
#include <cstddef>
#include <memory>
#include <new>
#include <span>
#include <utility>
#include <vector>

#if defined(__unix__)
#include <sys/mman.h>
#endif

namespace clothcd::detail {

using FacePair = std::pair<int, int>;

/// One thread's items, filled in order into blocks: the first of 64 Ki items (512 KiB of pairs,
/// enough for a garment-sized step), the others of kLarge items (512 Ki: 4 MiB of pairs, large
/// enough for the command-line tool to put them on huge pages, whose faults are fewer). clear()
/// empties them and keeps their memory; drain_into() moves them out and frees it.
template <class T, std::size_t kLarge = std::size_t{1} << 19, class Alloc = std::allocator<T>>
class Blocks {
 public:
  void push_back(const T& x) {
    if (cur_ == nullptr || cur_->size() == cur_->capacity()) next_block();
    cur_->push_back(x);
  }
  void clear() {
    for (std::size_t i = 0; i < used_; ++i)
      blocks_[i].clear();
    used_ = 0;
    cur_ = nullptr;
  }
  [[nodiscard]] std::size_t size() const {
    std::size_t n = 0;
    for (std::size_t i = 0; i < used_; ++i)
      n += blocks_[i].size();
    return n;
  }
  /// Appends a view of each non-empty block to `out`, in the order the items were pushed.
  void views(std::vector<std::span<const T>>& out) const {
    for (std::size_t i = 0; i < used_; ++i) {
      if (!blocks_[i].empty()) out.emplace_back(blocks_[i]);
    }
  }
  /// Appends the items to `out` in order, freeing each block once it is copied: at most one
  /// block more than the items is alive, where growing `out` block by block would copy them
  /// again at each doubling.
  void drain_into(std::vector<T>& out) {
    for (std::size_t i = 0; i < used_; ++i) {
      out.insert(out.end(), blocks_[i].begin(), blocks_[i].end());
      std::vector<T, Alloc>().swap(blocks_[i]);
    }
    blocks_.clear();
    used_ = 0;
    cur_ = nullptr;
  }

 private:
  static constexpr std::size_t kFirst = std::size_t{1} << 16;

  void next_block() {
    if (used_ == blocks_.size()) {
      blocks_.emplace_back();
      blocks_.back().reserve(used_ == 0 ? kFirst : kLarge);
    }
    cur_ = &blocks_[used_++];
  }

  std::vector<std::vector<T, Alloc>> blocks_;  // only the first used_ hold this call's items
  std::size_t used_ = 0;
  std::vector<T, Alloc>* cur_ = nullptr;  // blocks_[used_ - 1], or none yet
};

/// The traversal's pairs of one thread.
class PairBlocks : public Blocks<FacePair> {
 public:
  void push(int a, int b) { push_back({a, b}); }
};

/// An allocator that maps each allocation of more than 1 MiB from the system and unmaps it when
/// it is freed, so that its memory leaves the process at once (freed to the C allocator, it can
/// stay resident in an arena, for whatever the process allocates next).
template <class T>
struct MappedAllocator {
  using value_type = T;
  static constexpr std::size_t kMapped = std::size_t{1} << 20;

  MappedAllocator() = default;
  template <class U>
  MappedAllocator(const MappedAllocator<U>&) {}  // NOLINT: implicit, as allocators convert

  T* allocate(std::size_t n) {
#if defined(__unix__)
    if (n * sizeof(T) > kMapped) {
      void* p =
          mmap(nullptr, n * sizeof(T), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
      if (p == MAP_FAILED) throw std::bad_alloc();
      return static_cast<T*>(p);
    }
#endif
    return std::allocator<T>().allocate(n);
  }
  void deallocate(T* p, std::size_t n) {
#if defined(__unix__)
    if (n * sizeof(T) > kMapped) {
      munmap(p, n * sizeof(T));
      return;
    }
#endif
    std::allocator<T>().deallocate(p, n);
  }
  friend bool operator==(const MappedAllocator&, const MappedAllocator&) {
    return true;
  }
};

/// Blocks for items that drain_into() gathers: the first of 64 Ki items, from the C allocator
/// (a garment-sized query's), the others of 4 MiB, mapped (MappedAllocator), so that the gather
/// returns each block's memory as soon as it is copied and holds little more than the items
/// once.
template <class T>
using MappedBlocks = Blocks<T, (std::size_t{4} << 20) / sizeof(T), MappedAllocator<T>>;

/// Moves the items of every thread's blocks `member` (a pointer to a Blocks member of the
/// buffers) to the end of `out`, sized once for all of them.
template <class T, std::size_t kLarge, class Alloc, class Locals, class Buffer>
void drain_into(Locals& locals, Blocks<T, kLarge, Alloc> Buffer::*member, std::vector<T>& out) {
  std::size_t n = out.size();
  for (const auto& l : locals)
    n += (l.*member).size();
  out.reserve(n);
  for (auto& l : locals)
    (l.*member).drain_into(out);
}

/// A step's pairs as views of the blocks that hold them (or of any contiguous pair lists).
class PairList {
 public:
  PairList() = default;
  explicit PairList(std::span<const FacePair> pairs) { add(pairs); }

  void add(std::span<const FacePair> pairs) {
    if (pairs.empty()) return;
    parts_.push_back(pairs);
    size_ += pairs.size();
  }
  void add(const PairBlocks& b) {
    const std::size_t first = parts_.size();
    b.views(parts_);
    for (std::size_t i = first; i < parts_.size(); ++i)
      size_ += parts_[i].size();
  }
  [[nodiscard]] std::size_t size() const { return size_; }
  [[nodiscard]] bool empty() const { return size_ == 0; }

  /// The pairs in pieces of at most `piece` (the last of each view may be shorter), each with
  /// the index of its first pair in the list's order: work items for a parallel loop.
  struct Piece {
    std::span<const FacePair> pairs;
    std::size_t first = 0;
  };
  [[nodiscard]] std::vector<Piece> pieces(std::size_t piece) const {
    std::vector<Piece> out;
    std::size_t first = 0;
    for (const auto& p : parts_) {
      for (std::size_t i = 0; i < p.size(); i += piece) {
        out.push_back({p.subspan(i, std::min(piece, p.size() - i)), first + i});
      }
      first += p.size();
    }
    return out;
  }
  /// Calls f(index, pair) for every pair, in the list's order.
  template <class F>
  void for_each(F&& f) const {
    std::size_t i = 0;
    for (const auto& p : parts_) {
      for (const FacePair& q : p)
        f(i++, q);
    }
  }

 private:
  std::vector<std::span<const FacePair>> parts_;
  std::size_t size_ = 0;
};

}  // namespace clothcd::detail
