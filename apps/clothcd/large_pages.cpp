// Large buffers of the command-line tool on transparent huge pages. A one-shot `clothcd detect`
// touches about 150 MB once (pair lists, feature boxes, the collision lists): with 4 KiB pages
// that is tens of thousands of page faults, a sixth of the process's time on cloth_ball, and
// 2 MiB pages cut them about sevenfold. Linux enables them only where asked (madvise mode, the
// usual default), so the replaceable global operator new asks for allocations of at least
// kLarge bytes. Everything still comes from malloc and goes back through free, so the library's
// own allocations and these mix freely. Where the kernel has no transparent huge pages, madvise
// fails and the memory stays on normal pages.
#include <sys/mman.h>

#include <cstddef>
#include <cstdlib>
#include <new>

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define CLOTHCD_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || \
    __has_feature(memory_sanitizer)
#define CLOTHCD_SANITIZED 1
#endif
#endif

// The sanitizers replace operator new themselves to track allocations: leave theirs in place.
#ifndef CLOTHCD_SANITIZED

// GCC flags free() in these definitions as mismatched with new: here it is the matching call.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif

namespace {

constexpr std::size_t kHugePage = std::size_t{2} << 20;
constexpr std::size_t kLarge = 2 * kHugePage;

void* allocate(std::size_t n) {
  if (n >= kLarge) {
    const std::size_t rounded = (n + kHugePage - 1) / kHugePage * kHugePage;
    if (void* p = std::aligned_alloc(kHugePage, rounded)) {
      madvise(p, rounded, MADV_HUGEPAGE);
      return p;
    }
    return nullptr;
  }
  return std::malloc(n == 0 ? 1 : n);
}

}  // namespace

void* operator new(std::size_t n) {
  for (;;) {
    if (void* p = allocate(n)) return p;
    std::new_handler h = std::get_new_handler();
    if (h == nullptr) throw std::bad_alloc();
    h();
  }
}

void* operator new[](std::size_t n) {
  return operator new(n);
}

void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return operator new(n);
  } catch (...) {
    return nullptr;
  }
}

void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  return operator new(n, std::nothrow);
}

void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}

#endif
