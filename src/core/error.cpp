#include "clothcd/core/error.hpp"

#include <fmt/format.h>

namespace clothcd {

InputError input_error(std::string_view file, std::size_t line, std::string_view what) {
  if (line == 0) return InputError(fmt::format("{}: {}", file, what));
  return InputError(fmt::format("{}:{}: {}", file, line, what));
}

}  // namespace clothcd
