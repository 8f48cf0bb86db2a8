#pragma once
// The parts both page kinds share: the binary block of typed arrays the page decodes, and the
// assembly of the HTML file (the viewer's template, the page's description as JSON, the block
// gzip-compressed and base64-encoded) written through the atomic writer.

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "clothcd/view/page.hpp"

namespace clothcd::view {
using Vec3 = Eigen::Vector3d;
}  // namespace clothcd::view

namespace clothcd::view::detail {

/// Typed arrays in one byte block, each at an offset that is a multiple of 4 (so the page views
/// them in place); `layout()` names each one's type, offset and element count for the page.
class DataBlock {
 public:
  void add(std::string_view name, std::span<const std::uint8_t> v) { put(name, "u8", v); }
  void add(std::string_view name, std::span<const std::uint16_t> v) { put(name, "u16", v); }
  void add(std::string_view name, std::span<const std::int32_t> v) { put(name, "i32", v); }
  void add(std::string_view name, std::span<const std::uint32_t> v) { put(name, "u32", v); }
  void add(std::string_view name, std::span<const float> v) { put(name, "f32", v); }

  [[nodiscard]] const std::string& bytes() const { return bytes_; }
  [[nodiscard]] const nlohmann::json& layout() const { return layout_; }

 private:
  template <typename T>
  void put(std::string_view name, const char* type, std::span<const T> v);

  std::string bytes_;
  nlohmann::json layout_ = nlohmann::json::object();
};

/// Writes the page (see page.hpp) and fills `summary`'s byte counts. `meta` describes the page to
/// the viewer; its `buffers` key is set to the block's layout here.
void write_page(const std::filesystem::path& out, nlohmann::json meta, const DataBlock& block,
                PageSummary& summary);

/// The page text (the viewer's template with the script inlined), generated at build time.
[[nodiscard]] std::string_view page_template();

}  // namespace clothcd::view::detail
