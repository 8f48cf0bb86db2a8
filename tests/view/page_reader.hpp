#pragma once
// Reads a page of `clothcd view` back as the page's script does: its description (JSON) and the
// typed arrays of its data block (base64, gzip), for tests of what the page holds.

#include <gtest/gtest.h>
#include <zlib.h>
#include <Eigen/Core>

#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace clothcd::test {

struct PageData {
  nlohmann::json meta;
  std::string block;

  /// Every frame of mesh `name` ("cloth", "body") decoded as the page's script decodes it:
  /// frame 0 as is, then zigzag-coded differences from the straight-line guess, modulo 2^16.
  [[nodiscard]] std::vector<std::vector<Eigen::Vector3d>> frames(const std::string& name) const {
    const auto& mesh = meta.at("meshes").at(name);
    const std::size_t n3 = mesh.at("vertices").get<std::size_t>() * 3;
    const auto low = array<std::uint8_t>(name + "_low");
    const auto high = array<std::uint8_t>(name + "_high");
    std::vector<std::uint16_t> q(n3, 0), velocity(n3, 0);
    std::vector<std::vector<Eigen::Vector3d>> out;
    for (std::size_t k = 0; k * n3 < low.size(); ++k) {
      out.emplace_back(n3 / 3);
      for (std::size_t i = 0; i < n3; ++i) {
        const unsigned code = low[k * n3 + i] | (high[k * n3 + i] << 8);
        if (k == 0) {
          q[i] = static_cast<std::uint16_t>(code);
        } else {
          const int s =
              (code & 1u) != 0 ? -static_cast<int>(code >> 1) - 1 : static_cast<int>(code >> 1);
          velocity[i] = static_cast<std::uint16_t>(velocity[i] + s);
          q[i] = static_cast<std::uint16_t>(q[i] + velocity[i]);
        }
        out.back()[i / 3][i % 3] =
            mesh.at("origin")[i % 3].get<double>() + q[i] * mesh.at("step")[i % 3].get<double>();
      }
    }
    return out;
  }

  template <typename T>
  [[nodiscard]] std::vector<T> array(const std::string& name) const {
    const auto& b = meta.at("buffers").at(name);
    std::vector<T> out(b.at("count").get<std::size_t>());
    const auto offset = b.at("offset").get<std::size_t>();
    if (offset % 4 != 0 || offset + out.size() * sizeof(T) > block.size())
      throw std::runtime_error("buffer " + name + " is misplaced");
    std::memcpy(out.data(), block.data() + offset, out.size() * sizeof(T));
    return out;
  }
};

inline std::string element_text(const std::string& page, const std::string& id) {
  const std::string open = "<script id=\"" + id + "\"";
  const auto at = page.find(open);
  if (at == std::string::npos) throw std::runtime_error("no element " + id);
  const auto start = page.find('>', at) + 1;
  return page.substr(start, page.find("</script>", start) - start);
}

inline std::string unbase64(const std::string& in) {
  std::string out;
  std::uint32_t acc = 0;
  int bits = 0;
  for (char c : in) {
    int v;
    if (c >= 'A' && c <= 'Z')
      v = c - 'A';
    else if (c >= 'a' && c <= 'z')
      v = c - 'a' + 26;
    else if (c >= '0' && c <= '9')
      v = c - '0' + 52;
    else if (c == '+')
      v = 62;
    else if (c == '/')
      v = 63;
    else
      continue;  // '=' padding, white space
    acc = (acc << 6) | static_cast<std::uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((acc >> bits) & 0xffu);
    }
  }
  return out;
}

inline std::string gunzip(const std::string& in, std::size_t size) {
  std::string out(size, '\0');
  z_stream z{};
  if (inflateInit2(&z, 15 + 16) != Z_OK) throw std::runtime_error("inflateInit2");
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data()));
  z.avail_in = static_cast<uInt>(in.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  const int rc = inflate(&z, Z_FINISH);
  const std::size_t n = z.total_out;
  inflateEnd(&z);
  if (rc != Z_STREAM_END || n != size) throw std::runtime_error("the data block does not inflate");
  return out;
}

inline PageData read_page(const std::string& html) {
  PageData p;
  p.meta = nlohmann::json::parse(element_text(html, "clothcd-meta"));
  p.block = gunzip(unbase64(element_text(html, "clothcd-data")),
                   p.meta.at("data_bytes").get<std::size_t>());
  return p;
}

}  // namespace clothcd::test
