#pragma once
/// @file
/// Atomic file output: every file clothcd writes (meshes, simulation frames and state, manifests,
/// JSON, CSV, PNG) goes through here, so a reader, a resumed run or a crash never sees a partial
/// file. The bytes go to a temporary file beside the target (`NAME.tmp-PID-N`, so concurrent
/// writers never share one), which is then renamed over the target. On failure the temporary file
/// is removed, the old target is left as it was, and OutputError names the target and gives the
/// operating system's reason (strerror of the failing call's errno).
///
/// A killed process leaves the target old or new, never partial, in any case. With `Durability::
/// sync` the temporary file is also flushed to the disk (fsync) before the rename, so that the
/// same holds after a machine crash or power loss; that costs a disk flush per file, so it is
/// for files that are a commit point others rely on (the simulator's frames, states and
/// manifest), not for every output.

#include <filesystem>
#include <functional>
#include <iosfwd>
#include <stdexcept>
#include <string>
#include <string_view>

namespace clothcd {

/// An output file could not be written: "cannot write 'PATH': what failed: OS reason".
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class Durability {
  ProcessCrash,  ///< atomic against a killed process (the page cache survives it)
  Sync,          ///< also against a machine crash: fsync before the rename
};

/// Writes `bytes` to `path` atomically (see the file comment). Throws OutputError.
void write_file_atomic(const std::filesystem::path& path, std::string_view bytes,
                       Durability durability = Durability::ProcessCrash);

/// Renders the file through `body` into memory first, then writes it as above; an exception from
/// `body` propagates before anything is written.
void write_file_atomic(const std::filesystem::path& path,
                       const std::function<void(std::ostream&)>& body,
                       Durability durability = Durability::ProcessCrash);

/// Whether `name` (a file name, no folder) is a temporary file of write_file_atomic for the target
/// `target_name` (any target when empty): what a killed writer can leave behind.
[[nodiscard]] bool is_atomic_write_temporary(std::string_view name,
                                             std::string_view target_name = {});

/// Fault injection for crash tests. When the environment variable CLOTHCD_FAULT is
/// `[stop:]STAGE:NAME[:N]`, the N-th (default 1st) time in this process that the writer reaches
/// STAGE for a target whose file name is NAME, the process sends itself SIGKILL (or SIGSTOP with
/// `stop:`). Stages: `partial` (half of the bytes are in the temporary file), `written` (all are,
/// before the rename), `renamed` (after the rename). Unset: nothing happens.
void fault_point(std::string_view stage, const std::filesystem::path& target);

}  // namespace clothcd
