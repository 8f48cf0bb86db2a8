// Names of the configurations and the CSV form of the records.
#include "records.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "clothcd/core/error.hpp"
#include "clothcd/detect/names.hpp"

namespace clothcd::experiment {

// The research options: the unsound rules and the optimal cones.
using research::DetectOptions;

namespace {

struct StepCol {
  const char* name;
  double StepRow::*member;
};
constexpr StepCol kStepCols[] = {
    {"faces", &StepRow::faces},
    {"triangle_pairs", &StepRow::triangle_pairs},
    {"vf_tests", &StepRow::vf_tests},
    {"ee_tests", &StepRow::ee_tests},
    {"vf_np_culled", &StepRow::vf_np_culled},
    {"ee_np_culled", &StepRow::ee_np_culled},
    {"box_tests", &StepRow::box_tests},
    {"cone_tests", &StepRow::cone_tests},
    {"nodes_culled", &StepRow::nodes_culled},
    {"contour_tests", &StepRow::contour_tests},
    {"contour_fails", &StepRow::contour_fails},
    {"vf_collisions", &StepRow::vf_collisions},
    {"ee_collisions", &StepRow::ee_collisions},
    {"missed_vf", &StepRow::missed_vf},
    {"missed_ee", &StepRow::missed_ee},
    {"extra_vf", &StepRow::extra_vf},
    {"extra_ee", &StepRow::extra_ee},
    {"ms_refit", &StepRow::ms_refit},
    {"ms_traverse", &StepRow::ms_traverse},
    {"ms_narrow", &StepRow::ms_narrow},
};

// Splits one CSV line (no quoting).
std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ','))
    out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

// A CSV table addressed by column name; throws InputError naming the file and line.
class Table {
 public:
  explicit Table(const std::filesystem::path& path) : path_(path.string()) {
    std::ifstream in(path);
    if (!in) throw input_error(path_, 0, "cannot read file");
    std::string line;
    if (!std::getline(in, line)) throw input_error(path_, 1, "empty file: expected a header");
    const auto head = split(line);
    for (std::size_t i = 0; i < head.size(); ++i)
      cols_[head[i]] = i;
    std::size_t no = 1;
    while (std::getline(in, line)) {
      ++no;
      if (line.empty()) continue;
      auto cells = split(line);
      if (cells.size() != head.size()) {
        throw input_error(path_, no,
                          fmt::format("{} cells, expected {}", cells.size(), head.size()));
      }
      rows_.push_back(std::move(cells));
      lines_.push_back(no);
    }
  }
  [[nodiscard]] std::size_t size() const { return rows_.size(); }
  [[nodiscard]] const std::string& text(std::size_t r, const std::string& col) const {
    const auto it = cols_.find(col);
    if (it == cols_.end()) throw input_error(path_, 1, fmt::format("no column '{}'", col));
    return rows_[r][it->second];
  }
  [[nodiscard]] double number(std::size_t r, const std::string& col) const {
    const std::string& t = text(r, col);
    if (t == "nan") return std::nan("");
    try {
      std::size_t used = 0;
      const double v = std::stod(t, &used);
      if (used == t.size()) return v;
    } catch (const std::exception&) {
    }
    throw input_error(path_, lines_[r], fmt::format("column '{}': '{}' is not a number", col, t));
  }

 private:
  std::string path_;
  std::map<std::string, std::size_t> cols_;
  std::vector<std::vector<std::string>> rows_;
  std::vector<std::size_t> lines_;
};

std::string num(double v) {
  return std::isnan(v) ? std::string("nan") : fmt::format("{}", v);
}

}  // namespace

// The paper's tables spell the policies in capitals (PROVOT, PROPOSED, ...).
std::string policy_name(ConeRule p) {
  std::string s(research::to_string(p));
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return s;
}
std::string policy_name(ConePolicy p) {
  DetectOptions o;
  o.policy = p;
  return policy_name(research::cone_rule(o));
}
std::string culling_name(CullingRule c) {
  return std::string(research::to_string(c));
}
std::string build_name(BvhBuild b) {
  return std::string(to_string(b));
}
ConePolicy parse_policy(const std::string& s, const std::string& option) {
  const ConeRule rule = research::parse_cone_rule(s, option);
  if (rule == ConeRule::Optimal) {
    throw InputError(option + ": OPTIMAL is for spread angles only (see --optimal-every)");
  }
  DetectOptions o;
  research::set_cone_rule(o, rule);
  return o.policy;
}
CullingRule parse_culling(const std::string& s, const std::string& option) {
  return research::parse_culling_rule(s, option);
}
BvhBuild parse_build(const std::string& s, const std::string& option) {
  return parse_bvh_build(s, option);
}

std::vector<StepRow> read_step_rows(const std::filesystem::path& csv) {
  const Table t(csv);
  std::vector<StepRow> rows(t.size());
  for (std::size_t r = 0; r < t.size(); ++r) {
    StepRow& row = rows[r];
    row.scene = t.text(r, "scene");
    row.step = static_cast<int>(t.number(r, "step"));
    row.build = t.text(r, "build");
    row.culling = t.text(r, "culling");
    row.policy = t.text(r, "policy");
    for (const auto& c : kStepCols)
      row.*c.member = t.number(r, c.name);
  }
  return rows;
}

std::vector<SpreadRow> read_spread_rows(const std::filesystem::path& csv) {
  const Table t(csv);
  std::vector<SpreadRow> rows(t.size());
  for (std::size_t r = 0; r < t.size(); ++r) {
    SpreadRow& row = rows[r];
    row.scene = t.text(r, "scene");
    row.step = static_cast<int>(t.number(r, "step"));
    row.build = t.text(r, "build");
    row.policy = t.text(r, "policy");
    row.node = static_cast<int>(t.number(r, "node"));
    row.node_depth = static_cast<int>(t.number(r, "node_depth"));
    row.node_angle = t.number(r, "node_angle_deg");
    row.internal_mean = t.number(r, "internal_mean_deg");
    row.saturated_share = t.number(r, "saturated_share");
    row.opt_domain_mean = t.number(r, "opt_domain_mean_deg");
    row.opt_domain_nodes = static_cast<int>(t.number(r, "opt_domain_nodes"));
    row.ms_refit = t.number(r, "ms_refit");
  }
  return rows;
}

std::vector<TimingRow> read_timing_rows(const std::filesystem::path& csv) {
  const Table t(csv);
  std::vector<TimingRow> rows(t.size());
  for (std::size_t r = 0; r < t.size(); ++r) {
    TimingRow& row = rows[r];
    row.scene = t.text(r, "scene");
    row.step = static_cast<int>(t.number(r, "step"));
    row.build = t.text(r, "build");
    row.culling = t.text(r, "culling");
    row.policy = t.text(r, "policy");
    row.threads = static_cast<int>(t.number(r, "threads"));
    row.repeat = static_cast<int>(t.number(r, "repeat"));
    row.load1 = t.number(r, "load1");
    row.ms_refit = t.number(r, "ms_refit");
    row.ms_traverse = t.number(r, "ms_traverse");
    row.ms_narrow = t.number(r, "ms_narrow");
  }
  return rows;
}

namespace detail {

std::map<std::pair<std::string, std::string>, InSituTotals> read_in_situ(
    const std::filesystem::path& csv) {
  const Table t(csv);
  std::map<std::pair<std::string, std::string>, InSituTotals> out;
  for (std::size_t r = 0; r < t.size(); ++r) {
    InSituTotals& s = out[{t.text(r, "scene"), t.text(r, "setting")}];
    ++s.frames;
    s.substeps += t.number(r, "substeps");
    s.calls += t.number(r, "self_ccd_calls");
    s.triangle_pairs += t.number(r, "triangle_pairs");
    s.nodes_culled += t.number(r, "nodes_culled");
    s.refit_s += t.number(r, "refit_s");
    s.traversal_s += t.number(r, "traversal_s");
    s.narrow_s += t.number(r, "narrow_s");
  }
  return out;
}

std::string timing_rows_csv(const std::vector<TimingRow>& rows) {
  std::string out =
      "scene,step,build,culling,policy,threads,repeat,load1,ms_refit,ms_traverse,ms_narrow,"
      "ms_total\n";
  for (const auto& r : rows) {
    out += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{}\n", r.scene, r.step, r.build, r.culling,
                       r.policy, r.threads, r.repeat, num(r.load1), num(r.ms_refit),
                       num(r.ms_traverse), num(r.ms_narrow), num(r.ms_total()));
  }
  return out;
}

std::string step_rows_csv(const std::vector<StepRow>& rows) {
  std::string out = "scene,step,build,culling,policy";
  for (const auto& c : kStepCols)
    out += fmt::format(",{}", c.name);
  out += ",ms_cd,ms_total\n";
  for (const auto& r : rows) {
    out += fmt::format("{},{},{},{},{}", r.scene, r.step, r.build, r.culling, r.policy);
    for (const auto& c : kStepCols) {
      out += ',';
      out += num(r.*c.member);
    }
    out += fmt::format(",{},{}\n", num(r.ms_cd()), num(r.ms_total()));
  }
  return out;
}

std::string spread_rows_csv(const std::vector<SpreadRow>& rows) {
  std::string out =
      "scene,step,build,policy,node,node_depth,node_angle_deg,internal_mean_deg,saturated_share,"
      "opt_domain_mean_deg,opt_domain_nodes,ms_refit\n";
  for (const auto& r : rows) {
    out += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{}\n", r.scene, r.step, r.build, r.policy,
                       r.node, r.node_depth, num(r.node_angle), num(r.internal_mean),
                       num(r.saturated_share), num(r.opt_domain_mean), r.opt_domain_nodes,
                       num(r.ms_refit));
  }
  return out;
}

}  // namespace detail
}  // namespace clothcd::experiment
