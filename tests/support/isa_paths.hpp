#pragma once
// The vectorised bodies that a test compares with the scalar one: which of them this processor
// ran and which it lacks, said in the test's output (once per body and path in a process) and
// recorded as properties of the test, so that a run on a machine without AVX-512 shows what it
// left untested.

#include <gtest/gtest.h>

#include <cstdio>
#include <mutex>
#include <set>
#include <string>

#include "ccd/np_batch.hpp"

namespace clothcd::test {

/// Path ids of the *_with functions (0 scalar, 1 SSE2, 2 AVX2, 3 AVX-512F), and 4 for the
/// dispatching function, which runs the widest the processor has.
inline const char* isa_name(int isa) {
  static const char* const names[] = {"scalar", "SSE2", "AVX2", "AVX-512F"};
  if (isa == 4) isa = ccd_detail::batch_isa();
  return isa >= 0 && isa < 4 ? names[isa] : "unknown";
}

/// Notes that `body` ran on path `isa` and was compared (ran), or could not run there.
inline void note_isa(const char* body, int isa, bool ran) {
  static std::mutex m;
  static std::set<std::string> said;
  const std::string path = isa == 4 ? std::string("dispatch (") + isa_name(4) + ")" : isa_name(isa);
  {
    const std::lock_guard<std::mutex> lock(m);
    if (!said.insert(std::string(body) + " " + path).second) return;
  }
  std::printf("[ vector   ] %s, %s: %s\n", body, path.c_str(),
              ran ? "compared with the scalar body" : "NOT RUN, this processor lacks it");
  std::fflush(stdout);
  testing::Test::RecordProperty(std::string(body) + " " + path, ran ? "compared" : "not run");
}

}  // namespace clothcd::test
