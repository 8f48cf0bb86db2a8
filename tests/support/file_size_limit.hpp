#pragma once
// Simulates a full disk for the current process: a soft RLIMIT_FSIZE makes every write past
// `bytes` fail (EFBIG) through the same stream-failure paths as ENOSPC. Unlike writing to
// /dev/full it works as root (an atomic writer's temporary file beside /dev/full is a regular file
// on /dev, so as root nothing fails there and the rename would replace the device).
// SIGXFSZ is ignored meanwhile, otherwise the first failing write would kill the process.

#include <sys/resource.h>

#include <csignal>

namespace clothcd::test {

class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &saved_);
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit lim = saved_;
    lim.rlim_cur = bytes;
    ok_ = ::setrlimit(RLIMIT_FSIZE, &lim) == 0;
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &saved_);
    std::signal(SIGXFSZ, old_handler_);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;

  /// False when the limit could not be set (the test should then fail, not pass silently).
  [[nodiscard]] bool active() const { return ok_; }

 private:
  rlimit saved_{};
  void (*old_handler_)(int) = SIG_DFL;
  bool ok_ = false;
};

}  // namespace clothcd::test
