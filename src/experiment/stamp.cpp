// Provenance of the reports: what ran, on which commit and machine, when, under which load.
#include <fmt/format.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <memory>

#include "clothcd/experiment/experiment.hpp"

namespace clothcd::experiment {
namespace {

std::string shell_line(const std::string& cmd) {
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(::popen(cmd.c_str(), "r"), ::pclose);
  if (!pipe) return {};
  std::string out;
  std::array<char, 256> buf{};
  while (std::fgets(buf.data(), buf.size(), pipe.get()) != nullptr)
    out += buf.data();
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r'))
    out.pop_back();
  return out;
}

}  // namespace

std::string git_commit(const std::filesystem::path& dir) {
  const std::string d = dir.string();
  if (d.find('\'') != std::string::npos) return "unknown";
  const std::string head = shell_line(fmt::format("git -C '{}' rev-parse HEAD 2>/dev/null", d));
  if (head.empty()) return "unknown";
  const std::string dirty =
      shell_line(fmt::format("git -C '{}' status --porcelain --untracked-files=no 2>/dev/null", d));
  return dirty.empty() ? head : head + " (with uncommitted changes)";
}

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);) {
    if (line.starts_with("model name")) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
    }
  }
  return "unknown";
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  ::gmtime_r(&t, &tm);
  std::array<char, 64> buf{};
  std::strftime(buf.data(), buf.size(), "%Y-%m-%d %H:%M:%S UTC", &tm);
  return buf.data();
}

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  if (!(in >> a >> b >> c)) return "unknown";
  return fmt::format("{} {} {}", a, b, c);
}

std::string stamp(const std::string& command, const std::filesystem::path& source_dir,
                  const std::string& threads) {
  return fmt::format(
      "- command: `{}`\n- commit: {}\n- machine: {} cores ({}); worker threads: {}\n"
      "- started: {}; load average (1, 5, 15 min) at the start: {}\n",
      command, git_commit(source_dir), ::sysconf(_SC_NPROCESSORS_ONLN), cpu_model(), threads,
      utc_now(), load_average());
}

}  // namespace clothcd::experiment
