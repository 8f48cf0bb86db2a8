#pragma once
// Reads a JSON file of the shared data (the cloth_ball candidate and ground-truth lists).

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

namespace clothcd::test {

inline nlohmann::json read_json(const std::filesystem::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

}  // namespace clothcd::test
