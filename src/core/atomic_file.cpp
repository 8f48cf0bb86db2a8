// The one atomic file writer: POSIX calls, so that each failure's errno is read right where it
// happened (a stream's failure bit carries no reason, and later calls overwrite errno).
#include "clothcd/core/atomic_file.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <optional>
#include <sstream>

namespace clothcd {
namespace {

namespace fs = std::filesystem;

std::string reason(int err) {
  std::string r = std::strerror(err);
  if (err == ENOSPC || err == EDQUOT) r += " (disk full)";
  if (err == EFBIG) r += " (file size limit)";
  return r;
}

[[noreturn]] void fail(const fs::path& path, std::string_view what, int err) {
  throw OutputError(fmt::format("cannot write '{}': {}: {}", path.string(), what, reason(err)));
}

struct Fault {
  bool stop = false;
  std::string stage, name;
  int nth = 1;
  int seen = 0;
};

std::optional<Fault> parse_fault(const char* text) {
  if (text == nullptr || *text == '\0') return std::nullopt;
  std::string_view s = text;
  Fault f;
  if (s.starts_with("stop:")) {
    f.stop = true;
    s.remove_prefix(5);
  }
  const auto colon = s.find(':');
  if (colon == std::string_view::npos) return std::nullopt;
  f.stage = s.substr(0, colon);
  std::string_view rest = s.substr(colon + 1);
  if (const auto last = rest.rfind(':'); last != std::string_view::npos) {
    f.nth = std::atoi(std::string(rest.substr(last + 1)).c_str());
    rest = rest.substr(0, last);
  }
  f.name = rest;
  return f;
}

}  // namespace

void fault_point(std::string_view stage, const fs::path& target) {
  static std::mutex mutex;
  static std::optional<Fault> fault = parse_fault(std::getenv("CLOTHCD_FAULT"));
  if (!fault) return;
  std::lock_guard lock(mutex);
  if (stage != fault->stage || target.filename() != fault->name) return;
  if (++fault->seen != fault->nth) return;
  std::raise(fault->stop ? SIGSTOP : SIGKILL);
}

bool is_atomic_write_temporary(std::string_view name, std::string_view target_name) {
  const auto at = name.rfind(".tmp-");
  if (at == std::string_view::npos || at == 0) return false;
  if (!target_name.empty() && name.substr(0, at) != target_name) return false;
  // ".tmp-PID-N"
  const std::string_view tail = name.substr(at + 5);
  const auto dash = tail.find('-');
  if (dash == 0 || dash == std::string_view::npos || dash + 1 == tail.size()) return false;
  for (std::size_t i = 0; i < tail.size(); ++i) {
    if (i != dash && (tail[i] < '0' || tail[i] > '9')) return false;
  }
  return true;
}

void write_file_atomic(const fs::path& path, std::string_view bytes, Durability durability) {
  static std::atomic<unsigned> counter{0};
  fs::path tmp = path;
  tmp += fmt::format(".tmp-{}-{}", static_cast<long>(::getpid()), counter++);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) fail(path, fmt::format("cannot create temporary file '{}'", tmp.string()), errno);
  // Removes the temporary file and reports `err`, the errno of the call that failed.
  auto abandon = [&](std::string_view what, int err, bool open) {
    if (open) ::close(fd);
    ::unlink(tmp.c_str());
    fail(path, what, err);
  };
  std::size_t done = 0;
  const std::size_t half = bytes.size() / 2;
  bool reached_half = false;
  while (done < bytes.size() || !reached_half) {
    if (!reached_half && done >= half) {
      reached_half = true;
      fault_point("partial", path);
      continue;
    }
    const std::size_t end = reached_half ? bytes.size() : half;
    const ssize_t n = ::write(fd, bytes.data() + done, end - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      abandon("write failed", errno, true);
    }
    done += static_cast<std::size_t>(n);
  }
  // Otherwise, after a machine crash, the rename may have reached the disk before the data.
  if (durability == Durability::Sync && ::fsync(fd) != 0) {
    abandon("write failed (fsync)", errno, true);
  }
  if (::close(fd) != 0) abandon("write failed (close)", errno, false);
  fault_point("written", path);
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    abandon(fmt::format("cannot rename '{}' over it", tmp.filename().string()), errno, false);
  }
  fault_point("renamed", path);
}

void write_file_atomic(const fs::path& path, const std::function<void(std::ostream&)>& body,
                       Durability durability) {
  std::ostringstream out(std::ios::binary);
  body(out);
  write_file_atomic(path, out.view(), durability);
}

}  // namespace clothcd
