#pragma once
// JSON outputs of the subcommands go through the mesh writers' atomic write: a temporary file
// beside the target, checked after writing and after closing (where a full disk shows), renamed
// over the target, and removed on any failure, so no partial or empty JSON is ever left.

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
