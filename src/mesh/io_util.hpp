#pragma once
// Shared pieces of the mesh readers and writers: whole-file reads with clear errors, strict number
// parsing, and the atomic write-then-rename.

#include <charconv>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <string>
#include <string_view>

namespace clothcd::io_detail {

/// The file's bytes; InputError when it is missing, a folder, or unreadable.
std::string read_file(const std::filesystem::path& path);

/// Strict parse of the whole token (a leading '+' allowed); false on anything else.
inline bool parse_double(std::string_view token, double& out) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), out);
  return ec == std::errc() && ptr == token.data() + token.size();
}

template <class Int>
bool parse_int(std::string_view token, Int& out) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), out);
  return ec == std::errc() && ptr == token.data() + token.size();
}

/// write_file_atomic (clothcd/core/atomic_file.hpp), with its OutputError turned into an
/// InputError naming `path` and the operating system's reason.
void write_atomically(const std::filesystem::path& path,
                      const std::function<void(std::ostream&)>& body);

/// Lower-case extension with the dot (".obj").
std::string lower_extension(const std::filesystem::path& path);

}  // namespace clothcd::io_detail
