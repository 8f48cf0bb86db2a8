#pragma once
// JSON outputs of the subcommands go through the shared atomic writer
// (clothcd/core/atomic_file.hpp) as the mesh writers do, failures being InputErrors like theirs: no
// partial or empty JSON is ever left, and the error gives the operating system's reason.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <ostream>

#include "mesh/io_util.hpp"

namespace clothcd::app {

inline void write_json_atomically(const std::filesystem::path& file, const nlohmann::json& j,
                                  int indent) {
  io_detail::write_atomically(file, [&](std::ostream& out) { out << j.dump(indent) << '\n'; });
}

}  // namespace clothcd::app
