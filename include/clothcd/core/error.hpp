#pragma once
/// @file
/// The one exception type for bad input at clothcd's public boundary.

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace clothcd {

/// Bad input from a file or a caller: the message names the file, line or element and what was
/// expected, so a user can act on it. Numeric contract violations of the geometric kernels
/// (NaN/inf arguments) throw std::invalid_argument instead.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// "file:line: what" (line 0 omits the line).
[[nodiscard]] InputError input_error(std::string_view file, std::size_t line,
                                     std::string_view what);

}  // namespace clothcd
