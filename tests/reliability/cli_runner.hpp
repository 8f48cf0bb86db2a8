#pragma once
// Runs the built `clothcd` binary in a scratch folder and captures its exit code and output, for
// tests of what the command line answers to bad input and of what it leaves on disk.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

extern char** environ;

// The built binary's path, defined by the build where the command-line tool is built.
#ifndef CLOTHCD_CLI
#define CLOTHCD_CLI ""
#endif

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
    std::filesystem::remove(dir_.string() + ".stdout", ec);  // left by spawn() / wait()
    std::filesystem::remove(dir_.string() + ".stderr", ec);
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
    return run_shell(prefix + " '" CLOTHCD_CLI "' " + args);
  }

  /// Runs the shell command `command` in the scratch folder, capturing it like run().
  CliResult run_shell(const std::string& command) const {
    const auto out = dir_.string() + ".stdout", err = dir_.string() + ".stderr";
    const std::string cmd =
        "cd '" + dir_.string() + "' && " + command + " >'" + out + "' 2>'" + err + "'";
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

  /// Starts `clothcd ARGS...` in the background in the scratch folder, with `env` ("NAME=value")
  /// added to the environment; stdout and stderr go to files beside the folder.
  [[nodiscard]] pid_t spawn(const std::vector<std::string>& args,
                            const std::vector<std::string>& env = {}) const {
    std::vector<std::string> argv_s{CLOTHCD_CLI};
    argv_s.insert(argv_s.end(), args.begin(), args.end());
    std::vector<std::string> env_s = env;
    for (char** e = environ; *e != nullptr; ++e)
      env_s.emplace_back(*e);
    std::vector<char*> argv, envp;
    for (auto& a : argv_s)
      argv.push_back(a.data());
    for (auto& e : env_s)
      envp.push_back(e.data());
    argv.push_back(nullptr);
    envp.push_back(nullptr);
    const std::string out = dir_.string() + ".stdout", err = dir_.string() + ".stderr";
    const pid_t pid = ::fork();
    if (pid == 0) {
      // Only async-signal-safe calls from here on.
      const int o = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int e = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (::chdir(dir_.c_str()) != 0 || o < 0 || e < 0) ::_exit(126);
      ::dup2(o, 1);
      ::dup2(e, 2);
      ::execve(argv[0], argv.data(), envp.data());
      ::_exit(127);
    }
    return pid;
  }

  /// Waits for a spawned run to end; its exit status (128 + signal when killed) and output.
  [[nodiscard]] CliResult wait(pid_t pid) const {
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    CliResult r;
    if (WIFEXITED(status)) r.code = WEXITSTATUS(status);
    if (WIFSIGNALED(status)) r.code = 128 + WTERMSIG(status);
    r.out = slurp(dir_.string() + ".stdout");
    r.err = slurp(dir_.string() + ".stderr");
    return r;
  }

  /// Waits until a spawned run stops itself (SIGSTOP); false when it ended instead.
  [[nodiscard]] static bool wait_stopped(pid_t pid) {
    int status = 0;
    while (::waitpid(pid, &status, WUNTRACED) < 0 && errno == EINTR) {
    }
    return WIFSTOPPED(status);
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
