// Fuzzes the CCD query CSV parser: malformed text is rejected with InputError, never a crash.
#include <cstdlib>
#include <string_view>

#include "clothcd/ccd/query_csv.hpp"
#include "clothcd/core/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto queries = clothcd::parse_query_csv(text, "fuzz.csv");
    for (const auto& q : queries) {
      for (const auto& p : q.points) {
        if (!p.allFinite()) std::abort();  // the parser must reject non-finite values
      }
    }
  } catch (const clothcd::InputError&) {
  }
  return 0;
}
