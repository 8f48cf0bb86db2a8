#pragma once
// Number formats shared by the experiment's Markdown tables.

#include <fmt/format.h>

#include <cmath>
#include <string>

namespace clothcd::experiment::detail {

/// 12,345.6: thousands grouped, `decimals` after the point; "-" for NaN.
inline std::string grouped(double v, int decimals = 0) {
  if (std::isnan(v)) return "-";
  std::string s = fmt::format("{:.{}f}", std::abs(v), decimals);
  const auto dot = s.find('.');
  std::string head = s.substr(0, dot), tail = dot == std::string::npos ? "" : s.substr(dot);
  std::string out;
  for (std::size_t i = 0; i < head.size(); ++i) {
    if (i > 0 && (head.size() - i) % 3 == 0) out += ',';
    out += head[i];
  }
  return (v < 0 ? "-" : "") + out + tail;
}

/// +12.3%: a signed percentage; "-" for NaN.
inline std::string pct(double v) {
  return std::isnan(v) ? std::string("-") : fmt::format("{:+.1f}%", 100.0 * v);
}

/// 1 - x / base, NaN when the base is zero.
inline double reduction(double x, double base) {
  return base > 0 ? 1.0 - x / base : std::nan("");
}

}  // namespace clothcd::experiment::detail
