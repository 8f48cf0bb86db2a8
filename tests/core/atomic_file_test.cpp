// The shared atomic writer: whole replacement, no temporary left on any outcome, and errors that
// name the file and give the operating system's real reason.
#include "clothcd/core/atomic_file.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "support/file_size_limit.hpp"
#include "support/files.hpp"

namespace clothcd {
namespace {

namespace fs = std::filesystem;

struct TempDir {
  fs::path path =
      fs::temp_directory_path() / ("clothcd_atomic_" + std::to_string(::getpid()) + "_" +
                                   ::testing::UnitTest::GetInstance()->current_test_info()->name());
  TempDir() {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  [[nodiscard]] std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(path))
      out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }
};

using clothcd::test::slurp;

// The message of the OutputError `f` throws; fails the test when it throws nothing.
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const OutputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no OutputError";
  return {};
}

TEST(AtomicFile, ReplacesTheWholeFileAndLeavesNoTemporary) {
  TempDir dir;
  write_file_atomic(dir.path / "f.txt", std::string_view("first version, long"));
  write_file_atomic(dir.path / "f.txt", [](std::ostream& o) { o << "second"; });
  EXPECT_EQ(slurp(dir.path / "f.txt"), "second");
  write_file_atomic(dir.path / "empty", std::string_view());
  EXPECT_EQ(fs::file_size(dir.path / "empty"), 0u);
  EXPECT_EQ(dir.names(), (std::vector<std::string>{"empty", "f.txt"}));
}

TEST(AtomicFile, MissingFolderGivesTheReason) {
  TempDir dir;
  const std::string msg =
      error_of([&] { write_file_atomic(dir.path / "no" / "f.txt", std::string_view("x")); });
  EXPECT_NE(msg.find("cannot write '" + (dir.path / "no" / "f.txt").string() + "'"),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find(std::strerror(ENOENT)), std::string::npos) << msg;
  EXPECT_FALSE(fs::exists(dir.path / "no"));
}

// A failing rename used to report "Success": the error code was reused by the clean-up before the
// message read it. A folder in place of the target makes the rename itself fail (EISDIR).
TEST(AtomicFile, FailedRenameGivesItsOwnReason) {
  TempDir dir;
  fs::create_directory(dir.path / "d");
  fs::create_directory(dir.path / "d" / "inside");
  const std::string msg =
      error_of([&] { write_file_atomic(dir.path / "d", std::string_view("x")); });
  EXPECT_NE(msg.find("cannot rename"), std::string::npos) << msg;
  EXPECT_NE(msg.find(std::strerror(EISDIR)), std::string::npos) << msg;
  EXPECT_EQ(msg.find("Success"), std::string::npos) << msg;
  EXPECT_TRUE(fs::is_directory(dir.path / "d" / "inside"));
  EXPECT_EQ(dir.names(), (std::vector<std::string>{"d"}));
}

TEST(AtomicFile, FullDiskKeepsTheOldFile) {
  TempDir dir;
  write_file_atomic(dir.path / "f.txt", std::string_view("old"));
  {
    test::FileSizeLimit full(4096);
    ASSERT_TRUE(full.active());
    const std::string msg =
        error_of([&] { write_file_atomic(dir.path / "f.txt", std::string(1 << 16, 'x')); });
    EXPECT_NE(msg.find("f.txt"), std::string::npos) << msg;
    EXPECT_NE(msg.find("write failed"), std::string::npos) << msg;
    EXPECT_NE(msg.find(std::strerror(EFBIG)), std::string::npos) << msg;
  }
  EXPECT_EQ(slurp(dir.path / "f.txt"), "old");
  EXPECT_EQ(dir.names(), (std::vector<std::string>{"f.txt"}));
}

TEST(AtomicFile, ExceptionFromTheBodyWritesNothing) {
  TempDir dir;
  write_file_atomic(dir.path / "f.txt", std::string_view("old"));
  EXPECT_THROW(write_file_atomic(dir.path / "f.txt",
                                 [](std::ostream& o) {
                                   o << "half";
                                   throw std::logic_error("stop");
                                 }),
               std::logic_error);
  EXPECT_EQ(slurp(dir.path / "f.txt"), "old");
  EXPECT_EQ(dir.names(), (std::vector<std::string>{"f.txt"}));
}

TEST(AtomicFile, RecognisesItsTemporaryNames) {
  EXPECT_TRUE(is_atomic_write_temporary("frame_0003.obj.tmp-1234-0"));
  EXPECT_TRUE(is_atomic_write_temporary("frame_0003.obj.tmp-1234-17", "frame_0003.obj"));
  EXPECT_FALSE(is_atomic_write_temporary("frame_0003.obj.tmp-1234-17", "frame_0004.obj"));
  for (const char* name : {"frame_0003.obj", "frame_0003.obj.tmp", "x.tmp-12", "x.tmp-12-",
                           "x.tmp--3", "x.tmp-1a-2", ".tmp-1-2"}) {
    EXPECT_FALSE(is_atomic_write_temporary(name)) << name;
  }
}

}  // namespace
}  // namespace clothcd
