#pragma once
// Runs the built `clothcd` binary in a scratch folder and captures its exit code and output, for
// tests of what the command line answers to bad input and of what it leaves on disk.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace clothcd::test {

struct CliResult {
  int code = -1;  ///< exit status; 128 + signal when killed
  std::string out, err;
};

class CliScratch {
 public:
  CliScratch() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           (std::string("clothcd-cli-") + info->test_suite_name() + "-" + info->name() + "-" +
            std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  ~CliScratch() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  CliScratch(const CliScratch&) = delete;
  CliScratch& operator=(const CliScratch&) = delete;

  [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }
  [[nodiscard]] std::filesystem::path operator/(const std::string& name) const {
    return dir_ / name;
  }

  std::filesystem::path write(const std::string& name, const std::string& text) const {
    const auto p = dir_ / name;
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }

  /// Runs `clothcd ARGS` with the scratch folder as working directory. `prefix` is shell code run
  /// first (e.g. a `ulimit`). Output goes to files outside the scratch folder's listing.
  CliResult run(const std::string& args, const std::string& prefix = "") const {
    const auto out = dir_.string() + ".stdout", err = dir_.string() + ".stderr";
    const std::string cmd = "cd '" + dir_.string() + "' && " + prefix + " '" CLOTHCD_CLI "' " +
                            args + " >'" + out + "' 2>'" + err + "'";
    const int status = std::system(cmd.c_str());
    CliResult r;
    if (WIFEXITED(status)) r.code = WEXITSTATUS(status);
    if (WIFSIGNALED(status)) r.code = 128 + WTERMSIG(status);
    r.out = slurp(out);
    r.err = slurp(err);
    std::filesystem::remove(out);
    std::filesystem::remove(err);
    return r;
  }

  /// Every file name under the scratch folder (relative), sorted.
  [[nodiscard]] std::vector<std::string> files() const {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::recursive_directory_iterator(dir_)) {
      if (e.is_regular_file()) names.push_back(e.path().lexically_relative(dir_).string());
    }
    std::sort(names.begin(), names.end());
    return names;
  }

  static std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }

 private:
  std::filesystem::path dir_;
};

}  // namespace clothcd::test
