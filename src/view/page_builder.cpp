// The page file: the template, the description, and the data block compressed with zlib's gzip
// format, which the page inflates with the browser's own DecompressionStream.
#include "view/page_builder.hpp"

#include <fmt/format.h>
#include <zlib.h>

#include <bit>
#include <cstring>
#include <stdexcept>

#include "clothcd/core/atomic_file.hpp"

namespace clothcd::view::detail {
namespace {

static_assert(std::endian::native == std::endian::little,
              "the page reads its arrays as little-endian typed arrays");

std::string gzip(const std::string& in) {
  z_stream z{};
  // 15 + 16: a gzip header and trailer; level 6 is within 2% of 9's size here at half its time.
  if (deflateInit2(&z, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw std::runtime_error("zlib: deflateInit2 failed");
  std::string out(deflateBound(&z, static_cast<uLong>(in.size())), '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data()));
  z.avail_in = static_cast<uInt>(in.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  const int rc = deflate(&z, Z_FINISH);
  const std::size_t n = z.total_out;
  deflateEnd(&z);
  if (rc != Z_STREAM_END) throw std::runtime_error("zlib: deflate did not finish");
  out.resize(n);
  return out;
}

std::string base64(const std::string& in) {
  static constexpr char kDigits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  const auto* p = reinterpret_cast<const unsigned char*>(in.data());
  std::size_t i = 0;
  for (; i + 3 <= in.size(); i += 3) {
    const std::uint32_t v = (p[i] << 16) | (p[i + 1] << 8) | p[i + 2];
    for (int s = 18; s >= 0; s -= 6)
      out += kDigits[(v >> s) & 63];
  }
  if (const std::size_t rest = in.size() - i; rest > 0) {
    const std::uint32_t v = (p[i] << 16) | (rest == 2 ? p[i + 1] << 8 : 0);
    out += kDigits[(v >> 18) & 63];
    out += kDigits[(v >> 12) & 63];
    out += rest == 2 ? kDigits[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

// JSON inside a <script> element: "</" would end the element early, "<!--" would change how it
// is parsed. '<' occurs only inside JSON strings, where \u003c means the same.
std::string script_safe(const std::string& json) {
  std::string out;
  out.reserve(json.size());
  for (char c : json) {
    if (c == '<') {
      out += "\\u003c";
    } else {
      out += c;
    }
  }
  return out;
}

std::string html_escape(std::string_view s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

void replace_once(std::string& text, std::string_view key, const std::string& value) {
  const std::size_t at = text.find(key);
  if (at == std::string::npos) throw std::logic_error(fmt::format("viewer template lacks {}", key));
  text.replace(at, key.size(), value);
}

}  // namespace

template <typename T>
void DataBlock::put(std::string_view name, const char* type, std::span<const T> v) {
  bytes_.resize((bytes_.size() + 3) / 4 * 4, '\0');
  const std::size_t offset = bytes_.size();
  bytes_.resize(offset + v.size_bytes());
  if (!v.empty()) std::memcpy(bytes_.data() + offset, v.data(), v.size_bytes());
  layout_[std::string(name)] = {{"type", type}, {"offset", offset}, {"count", v.size()}};
}

template void DataBlock::put(std::string_view, const char*, std::span<const std::uint8_t>);
template void DataBlock::put(std::string_view, const char*, std::span<const std::uint16_t>);
template void DataBlock::put(std::string_view, const char*, std::span<const std::int32_t>);
template void DataBlock::put(std::string_view, const char*, std::span<const std::uint32_t>);
template void DataBlock::put(std::string_view, const char*, std::span<const float>);

void write_page(const std::filesystem::path& out, nlohmann::json meta, const DataBlock& block,
                PageSummary& summary) {
  meta["buffers"] = block.layout();
  meta["data_bytes"] = block.bytes().size();
  const std::string packed = gzip(block.bytes());
  std::string page(page_template());
  replace_once(page, "<!--CLOTHCD_TITLE-->", html_escape(meta.value("title", "clothcd view")));
  replace_once(page, "<!--CLOTHCD_META-->", script_safe(meta.dump()));
  replace_once(page, "<!--CLOTHCD_DATA-->", base64(packed));
  summary.data_bytes = block.bytes().size();
  summary.packed_bytes = packed.size();
  summary.bytes = page.size();
  write_file_atomic(out, page);
}

}  // namespace clothcd::view::detail
