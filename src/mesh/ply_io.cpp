// PLY reading (ascii and both binary byte orders) and binary little-endian writing.
//
// No Debian package offers a PLY reader. This one reads the header, checks every claimed count
// against the bytes that follow before allocating, then walks the elements in order, skipping
// properties and elements it does not need with their exact sizes.

#include <fmt/format.h>

#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "clothcd/core/error.hpp"
#include "clothcd/mesh/io.hpp"
#include "io_util.hpp"

namespace clothcd {
namespace {

using io_detail::parse_double;
using io_detail::parse_int;

enum class Scalar { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };
enum class Format { Ascii, BinaryLittleEndian, BinaryBigEndian };

std::optional<Scalar> scalar_from_name(std::string_view name) {
  if (name == "char" || name == "int8") return Scalar::Int8;
  if (name == "uchar" || name == "uint8") return Scalar::UInt8;
  if (name == "short" || name == "int16") return Scalar::Int16;
  if (name == "ushort" || name == "uint16") return Scalar::UInt16;
  if (name == "int" || name == "int32") return Scalar::Int32;
  if (name == "uint" || name == "uint32") return Scalar::UInt32;
  if (name == "float" || name == "float32") return Scalar::Float32;
  if (name == "double" || name == "float64") return Scalar::Float64;
  return std::nullopt;
}

std::size_t scalar_size(Scalar s) {
  switch (s) {
    case Scalar::Int8:
    case Scalar::UInt8:
      return 1;
    case Scalar::Int16:
    case Scalar::UInt16:
      return 2;
    case Scalar::Int32:
    case Scalar::UInt32:
    case Scalar::Float32:
      return 4;
    case Scalar::Float64:
      return 8;
  }
  return 0;
}

bool is_integer(Scalar s) {
  return s != Scalar::Float32 && s != Scalar::Float64;
}

struct Property {
  std::string name;
  bool is_list = false;
  Scalar count_type = Scalar::UInt8;  // lists only
  Scalar type = Scalar::Float32;      // the value type (of the items for a list)
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

struct Header {
  Format format = Format::Ascii;
  std::vector<Element> elements;
  std::size_t body_offset = 0;  // first byte after "end_header\n"
  std::size_t body_line = 0;    // line number of the first body line (ascii)
};

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r'))
      ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r')
      ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

Header parse_header(const std::string& file, std::string_view data) {
  constexpr std::size_t kMaxHeader = 1 << 20;
  Header h;
  std::size_t pos = 0, line_no = 0;
  bool saw_format = false;
  while (true) {
    const std::size_t end = data.find('\n', pos);
    if (end == std::string_view::npos || end > kMaxHeader) {
      throw input_error(file, line_no + 1,
                        line_no == 0 ? "empty file or not a PLY file (expected 'ply')"
                                     : "header has no 'end_header' line");
    }
    ++line_no;
    const std::string_view line = data.substr(pos, end - pos);
    pos = end + 1;
    const auto tok = split(line);
    if (line_no == 1) {
      if (tok.size() != 1 || tok[0] != "ply") {
        throw input_error(file, 1, "not a PLY file: expected the first line to be 'ply'");
      }
      continue;
    }
    if (tok.empty() || tok[0] == "comment" || tok[0] == "obj_info") continue;
    if (tok[0] == "end_header") break;
    if (tok[0] == "format") {
      if (tok.size() != 3 || tok[2] != "1.0") {
        throw input_error(file, line_no,
                          "expected 'format <ascii|binary_little_endian|"
                          "binary_big_endian> 1.0'");
      }
      if (tok[1] == "ascii") {
        h.format = Format::Ascii;
      } else if (tok[1] == "binary_little_endian") {
        h.format = Format::BinaryLittleEndian;
      } else if (tok[1] == "binary_big_endian") {
        h.format = Format::BinaryBigEndian;
      } else {
        throw input_error(file, line_no, fmt::format("unknown PLY format '{}'", tok[1]));
      }
      saw_format = true;
    } else if (tok[0] == "element") {
      Element e;
      if (tok.size() != 3 || !parse_int(tok[2], e.count)) {
        throw input_error(file, line_no,
                          "expected 'element <name> <count>' with a non-negative integer count");
      }
      e.name = std::string(tok[1]);
      h.elements.push_back(std::move(e));
    } else if (tok[0] == "property") {
      if (h.elements.empty()) throw input_error(file, line_no, "property before any element");
      Property p;
      if (tok.size() == 5 && tok[1] == "list") {
        const auto count_type = scalar_from_name(tok[2]);
        const auto type = scalar_from_name(tok[3]);
        if (!count_type || !type || !is_integer(*count_type)) {
          throw input_error(file, line_no,
                            fmt::format("bad list property types '{} {}': expected an integer "
                                        "count type and a scalar item type",
                                        tok[2], tok[3]));
        }
        p.is_list = true;
        p.count_type = *count_type;
        p.type = *type;
        p.name = std::string(tok[4]);
      } else if (tok.size() == 3) {
        const auto type = scalar_from_name(tok[1]);
        if (!type) {
          throw input_error(file, line_no, fmt::format("unknown property type '{}'", tok[1]));
        }
        p.type = *type;
        p.name = std::string(tok[2]);
      } else {
        throw input_error(file, line_no,
                          "expected 'property <type> <name>' or 'property list <count type> "
                          "<item type> <name>'");
      }
      h.elements.back().properties.push_back(std::move(p));
    } else {
      throw input_error(file, line_no, fmt::format("unknown header keyword '{}'", tok[0]));
    }
  }
  if (!saw_format) throw input_error(file, 2, "header has no 'format' line");
  h.body_offset = pos;
  h.body_line = line_no + 1;
  return h;
}

// Where a value is read, for error messages: formatted only when one is thrown (a mesh has
// millions of values and no error).
struct Where {
  std::string_view element;
  std::uint64_t item = 0;
  std::string_view property;
  [[nodiscard]] std::string str() const {
    return fmt::format("{} {}, property '{}'", element, item, property);
  }
};

// Reads the body values of a binary file with bounds checks.
class BinarySource {
 public:
  BinarySource(std::string file, std::string_view body, bool big_endian)
      : file_(std::move(file)),
        body_(body),
        swap_(big_endian != (std::endian::native == std::endian::big)) {}

  std::int64_t read_int(Scalar s, const Where& where) {
    switch (s) {
      case Scalar::Int8:
        return get<std::int8_t>(where);
      case Scalar::UInt8:
        return get<std::uint8_t>(where);
      case Scalar::Int16:
        return get<std::int16_t>(where);
      case Scalar::UInt16:
        return get<std::uint16_t>(where);
      case Scalar::Int32:
        return get<std::int32_t>(where);
      case Scalar::UInt32:
        return get<std::uint32_t>(where);
      case Scalar::Float32:
      case Scalar::Float64:
        break;
    }
    throw input_error(file_, 0, fmt::format("{}: expected an integer type", where.str()));
  }

  double read_real(Scalar s, const Where& where) {
    if (s == Scalar::Float32) return get<float>(where);
    if (s == Scalar::Float64) return get<double>(where);
    return static_cast<double>(read_int(s, where));
  }

  void skip(Scalar s, const Where& where) {
    need(scalar_size(s), where);
    pos_ += scalar_size(s);
  }

  void finish() const {
    if (pos_ != body_.size()) {
      throw input_error(file_, 0,
                        fmt::format("{} unexpected bytes after the last element: the header's "
                                    "counts do not match the data",
                                    body_.size() - pos_));
    }
  }

  [[nodiscard]] std::string where_prefix() const { return {}; }

 private:
  void need(std::size_t n, const Where& where) const {
    if (body_.size() - pos_ < n) {
      throw input_error(file_, 0,
                        fmt::format("{}: truncated, the file ends {} bytes after the header "
                                    "(binary data shorter than the header claims)",
                                    where.str(), body_.size()));
    }
  }

  template <class T>
  T get(const Where& where) {
    need(sizeof(T), where);
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, body_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    if (swap_) {
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i)
        std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
    }
    T value;
    std::memcpy(&value, bytes, sizeof(T));
    return value;
  }

  std::string file_;
  std::string_view body_;
  std::size_t pos_ = 0;
  bool swap_ = false;
};

// Reads the body values of an ascii file as a stream of whitespace-separated tokens.
class AsciiSource {
 public:
  AsciiSource(std::string file, std::string_view body, std::size_t first_line)
      : file_(std::move(file)), body_(body), line_(first_line) {}

  std::int64_t read_int(Scalar s, const Where& where) {
    const std::string_view tok = next(where);
    std::int64_t v = 0;
    if (!parse_int(tok, v)) {
      throw input_error(file_, token_line_,
                        fmt::format("{}: '{}' is not an integer", where.str(), tok));
    }
    check_range(s, v, tok, where);
    return v;
  }

  double read_real(Scalar s, const Where& where) {
    if (is_integer(s)) return static_cast<double>(read_int(s, where));
    const std::string_view tok = next(where);
    double v = 0;
    if (!parse_double(tok, v)) {
      throw input_error(file_, token_line_,
                        fmt::format("{}: '{}' is not a number", where.str(), tok));
    }
    return v;
  }

  void skip(Scalar s, const Where& where) { (void)read_real(s, where); }

  void finish() {
    skip_space();
    if (pos_ < body_.size()) {
      throw input_error(file_, line_,
                        "unexpected data after the last element: the header's counts do not "
                        "match the data");
    }
  }

  [[nodiscard]] std::size_t line() const { return token_line_; }

 private:
  void skip_space() {
    while (pos_ < body_.size()) {
      const char c = body_[pos_];
      if (c == '\n') {
        ++line_;
      } else if (c != ' ' && c != '\t' && c != '\r') {
        break;
      }
      ++pos_;
    }
  }

  std::string_view next(const Where& where) {
    skip_space();
    if (pos_ >= body_.size()) {
      throw input_error(file_, line_,
                        fmt::format("{}: the file ends early (fewer values than the header "
                                    "claims)",
                                    where.str()));
    }
    const std::size_t start = pos_;
    while (pos_ < body_.size() && body_[pos_] != ' ' && body_[pos_] != '\t' &&
           body_[pos_] != '\r' && body_[pos_] != '\n') {
      ++pos_;
    }
    token_line_ = line_;
    return body_.substr(start, pos_ - start);
  }

  void check_range(Scalar s, std::int64_t v, std::string_view tok, const Where& where) {
    std::int64_t lo = 0, hi = 0;
    switch (s) {
      case Scalar::Int8:
        lo = -128, hi = 127;
        break;
      case Scalar::UInt8:
        hi = 255;
        break;
      case Scalar::Int16:
        lo = -32768, hi = 32767;
        break;
      case Scalar::UInt16:
        hi = 65535;
        break;
      case Scalar::Int32:
        lo = std::numeric_limits<std::int32_t>::min(),
        hi = std::numeric_limits<std::int32_t>::max();
        break;
      default:
        hi = std::numeric_limits<std::uint32_t>::max();
        break;
    }
    if (v < lo || v > hi) {
      throw input_error(file_, token_line_,
                        fmt::format("{}: '{}' does not fit the declared type", where.str(), tok));
    }
  }

  std::string file_;
  std::string_view body_;
  std::size_t pos_ = 0;
  std::size_t line_ = 1;
  std::size_t token_line_ = 1;
};

// Rejects header counts the file cannot possibly hold, before anything is allocated.
void check_counts_against_size(const std::string& file, const Header& h, std::size_t body_size) {
  long double needed = 0;
  for (const Element& e : h.elements) {
    std::size_t per_item = 0;
    for (const Property& p : e.properties) {
      // Smallest encoding: a list's count alone (binary), one digit and a separator (ascii).
      per_item += h.format == Format::Ascii ? 2 : scalar_size(p.is_list ? p.count_type : p.type);
    }
    needed += static_cast<long double>(per_item) * static_cast<long double>(e.count);
    if (h.format == Format::Ascii && per_item > 0) needed -= 1;  // no separator after the last
    if (needed > static_cast<long double>(body_size)) {
      throw input_error(file, 0,
                        fmt::format("header claims {} '{}' elements, which need more than the "
                                    "{} bytes that follow the header (wrong count or truncated "
                                    "file)",
                                    e.count, e.name, body_size));
    }
  }
}

struct MeshLayout {
  int vertex_element = -1, face_element = -1;
  int x = -1, y = -1, z = -1, indices = -1;
};

MeshLayout find_layout(const std::string& file, const Header& h) {
  MeshLayout m;
  for (int i = 0; i < static_cast<int>(h.elements.size()); ++i) {
    const Element& e = h.elements[i];
    if (e.name == "vertex" && m.vertex_element < 0) {
      m.vertex_element = i;
      for (int p = 0; p < static_cast<int>(e.properties.size()); ++p) {
        const Property& prop = e.properties[p];
        if (prop.is_list) continue;
        if (prop.name == "x") m.x = p;
        if (prop.name == "y") m.y = p;
        if (prop.name == "z") m.z = p;
      }
    } else if (e.name == "face" && m.face_element < 0) {
      m.face_element = i;
      for (int p = 0; p < static_cast<int>(e.properties.size()); ++p) {
        const Property& prop = e.properties[p];
        if (prop.is_list && (prop.name == "vertex_indices" || prop.name == "vertex_index")) {
          m.indices = p;
        }
      }
    }
  }
  if (m.vertex_element < 0) throw input_error(file, 0, "no 'vertex' element in the header");
  if (m.x < 0 || m.y < 0 || m.z < 0) {
    throw input_error(file, 0, "the 'vertex' element lacks scalar x, y and z properties");
  }
  if (m.face_element < 0) {
    throw input_error(file, 0, "no 'face' element: expected a triangle mesh, not a point cloud");
  }
  if (m.indices < 0) {
    throw input_error(file, 0, "the 'face' element lacks a 'vertex_indices' list property");
  }
  const Property& idx = h.elements[m.face_element].properties[m.indices];
  if (!is_integer(idx.type)) {
    throw input_error(file, 0, "face vertex indices must have an integer type");
  }
  if (h.elements[m.vertex_element].count >
          static_cast<std::uint64_t>(std::numeric_limits<int>::max()) ||
      h.elements[m.face_element].count >
          static_cast<std::uint64_t>(std::numeric_limits<int>::max() / 3)) {
    throw input_error(file, 0, "too many vertices or faces for 32-bit indices");
  }
  if (h.elements[m.face_element].count == 0) {
    throw input_error(file, 0, "contains no faces: expected a triangle mesh");
  }
  return m;
}

template <class Source>
TriangleMesh read_body(const std::string& file, const Header& h, const MeshLayout& m, Source& src) {
  TriangleMesh mesh;
  const auto nv = static_cast<std::int64_t>(h.elements[m.vertex_element].count);
  mesh.vertices.reserve(static_cast<std::size_t>(nv));
  mesh.faces.reserve(static_cast<std::size_t>(h.elements[m.face_element].count));
  const auto locate = [&](std::string_view what) {
    if constexpr (std::is_same_v<Source, AsciiSource>) {
      return input_error(file, src.line(), what);
    } else {
      return input_error(file, 0, what);
    }
  };
  Where where;
  std::vector<std::int64_t> polygon;
  for (int ei = 0; ei < static_cast<int>(h.elements.size()); ++ei) {
    const Element& e = h.elements[ei];
    for (std::uint64_t item = 0; item < e.count; ++item) {
      double xyz[3] = {0, 0, 0};
      for (int pi = 0; pi < static_cast<int>(e.properties.size()); ++pi) {
        const Property& p = e.properties[pi];
        where = {e.name, item, p.name};
        if (!p.is_list) {
          if (ei == m.vertex_element && (pi == m.x || pi == m.y || pi == m.z)) {
            xyz[pi == m.x ? 0 : pi == m.y ? 1 : 2] = src.read_real(p.type, where);
          } else {
            src.skip(p.type, where);
          }
          continue;
        }
        const std::int64_t n = src.read_int(p.count_type, where);
        if (n < 0) throw locate(fmt::format("{}: negative list length {}", where.str(), n));
        if (ei == m.face_element && pi == m.indices) {
          if (n < 3) {
            throw locate(
                fmt::format("{}: a face has {} vertices, expected at least 3", where.str(), n));
          }
          polygon.clear();
          for (std::int64_t c = 0; c < n; ++c) {
            const std::int64_t v = src.read_int(p.type, where);
            if (v < 0 || v >= nv) {
              throw locate(
                  fmt::format("{}: vertex index {} is out of range, expected 0 <= "
                              "index < {}",
                              where.str(), v, nv));
            }
            for (std::int64_t u : polygon) {
              if (u == v) throw locate(fmt::format("{}: repeats vertex {}", where.str(), v));
            }
            polygon.push_back(v);
          }
          for (std::size_t c = 1; c + 1 < polygon.size(); ++c) {
            mesh.faces.push_back({static_cast<int>(polygon[0]), static_cast<int>(polygon[c]),
                                  static_cast<int>(polygon[c + 1])});
          }
        } else {
          for (std::int64_t c = 0; c < n; ++c)
            src.skip(p.type, where);
        }
      }
      if (ei == m.vertex_element) {
        if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2])) {
          throw locate(fmt::format("vertex {}: non-finite coordinate ({}, {}, {})", item, xyz[0],
                                   xyz[1], xyz[2]));
        }
        mesh.vertices.emplace_back(xyz[0], xyz[1], xyz[2]);
      }
    }
  }
  src.finish();
  return mesh;
}

}  // namespace

TriangleMesh read_ply(const std::filesystem::path& path) {
  const std::string file = path.string();
  const std::string data = io_detail::read_file(path);
  const Header h = parse_header(file, data);
  const std::string_view body = std::string_view(data).substr(h.body_offset);
  check_counts_against_size(file, h, body.size());
  const MeshLayout layout = find_layout(file, h);
  if (h.format == Format::Ascii) {
    AsciiSource src(file, body, h.body_line);
    return read_body(file, h, layout, src);
  }
  BinarySource src(file, body, h.format == Format::BinaryBigEndian);
  return read_body(file, h, layout, src);
}

void write_ply(const std::filesystem::path& path, const TriangleMesh& mesh) {
  validate_mesh(mesh, path.string());
  io_detail::write_atomically(path, [&](std::ostream& out) {
    out << "ply\nformat binary_little_endian 1.0\ncomment written by clothcd\n"
        << "element vertex " << mesh.num_vertices() << "\n"
        << "property double x\nproperty double y\nproperty double z\n"
        << "element face " << mesh.num_faces() << "\n"
        << "property list uchar int vertex_indices\nend_header\n";
    std::vector<char> buf;
    const auto put = [&](const auto& value) {
      char bytes[sizeof(value)];
      std::memcpy(bytes, &value, sizeof(value));
      if constexpr (std::endian::native == std::endian::big) {
        for (std::size_t i = 0; i < sizeof(value) / 2; ++i) {
          std::swap(bytes[i], bytes[sizeof(value) - 1 - i]);
        }
      }
      buf.insert(buf.end(), bytes, bytes + sizeof(value));
    };
    const auto flush = [&] {
      out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
      buf.clear();
    };
    for (const auto& v : mesh.vertices) {
      put(v.x()), put(v.y()), put(v.z());
      if (buf.size() > (1u << 16)) flush();
    }
    for (const auto& f : mesh.faces) {
      put(std::uint8_t{3});
      put(std::int32_t{f[0]}), put(std::int32_t{f[1]}), put(std::int32_t{f[2]});
      if (buf.size() > (1u << 16)) flush();
    }
    flush();
  });
}

}  // namespace clothcd
