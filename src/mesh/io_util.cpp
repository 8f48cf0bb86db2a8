#include "io_util.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

#include <unistd.h>

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
  const std::string name = path.string();
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw input_error(name, 0, "cannot write: is a directory");
  // Unique per process and call, in the target's folder so the rename stays on one file system.
  static std::atomic<unsigned> counter{0};
  fs::path tmp = path;
  tmp += fmt::format(".tmp-{}-{}", static_cast<long>(::getpid()), counter++);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      throw input_error(
          name, 0,
          fmt::format("cannot write (temporary file {}): {}", tmp.string(), std::strerror(errno)));
    }
    try {
      body(out);
    } catch (...) {
      out.close();
      fs::remove(tmp, ec);
      throw;
    }
    out.flush();
    const bool wrote = static_cast<bool>(out);
    out.close();
    if (!wrote || out.fail()) {
      const int err = errno;
      fs::remove(tmp, ec);
      throw input_error(name, 0,
                        fmt::format("write failed (disk full or I/O error?): {}",
                                    err != 0 ? std::strerror(err) : "stream error"));
    }
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw input_error(name, 0, fmt::format("cannot replace the file: {}", ec.message()));
  }
}

std::string lower_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace clothcd::io_detail
