#pragma once
// Scenes from parsed JSON, for the library's own code and tests (nlohmann::json stays out of the
// public headers).

#include <nlohmann/json.hpp>

#include <filesystem>

#include "clothcd/sim/scene.hpp"

namespace clothcd::sim {

/// parse_scene_text on an already parsed document.
[[nodiscard]] Scene parse_scene(const nlohmann::json& j, const std::filesystem::path& file);

}  // namespace clothcd::sim
