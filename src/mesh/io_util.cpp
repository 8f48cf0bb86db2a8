#include "io_util.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

#include "clothcd/core/atomic_file.hpp"
#include "clothcd/core/error.hpp"

namespace clothcd::io_detail {

namespace fs = std::filesystem;

std::string read_file(const fs::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (ec || !fs::exists(status)) throw input_error(name, 0, "cannot open: no such file");
  if (fs::is_directory(status)) throw input_error(name, 0, "cannot open: is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw input_error(name, 0, fmt::format("cannot open for reading: {}", std::strerror(errno)));
  }
  std::string data;
  const auto size = fs::file_size(path, ec);
  if (!ec) data.reserve(static_cast<std::size_t>(size));  // the real size, not a claimed one
  data.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (in.bad()) throw input_error(name, 0, "read error");
  return data;
}

void write_atomically(const fs::path& path, const std::function<void(std::ostream&)>& body) {
  try {
    write_file_atomic(path, body);
  } catch (const OutputError& e) {
    throw InputError(e.what());  // the mesh writers' contract: every failure is an InputError
  }
}

std::string lower_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace clothcd::io_detail
