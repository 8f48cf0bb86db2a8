// Tables of the experiment (markdown) and the merged CSVs, from the per-(scene, build) runs.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <unistd.h>
#include <algorithm>
#include <cmath>

#include <cstdlib>
#include <map>
#include <numeric>
#include <set>
#include <tuple>

#include "clothcd/core/atomic_file.hpp"
#include "clothcd/experiment/experiment.hpp"
#include "format.hpp"
#include "records.hpp"
#include "scene_data.hpp"

namespace clothcd::experiment {
namespace {

namespace fs = std::filesystem;
using namespace detail;  // the records, their statistics and the number formats

std::string table1(const std::vector<SceneData>& data, const ExperimentOptions& opt) {
  std::string s =
      "# Table 1: average triangle pair tests per CD call\n\n"
      "A triangle pair test = a non-adjacent triangle pair reaching the narrow phase (its VF/EE "
      "elementary tests follow). Averages over every CD call (consecutive frame pair) of the "
      "scene; *vs PROVOT* = 1 - X / PROVOT under the same build and culling rule (positive = "
      "fewer tests); *vs none* = share of the unculled traversal's pairs removed by cone "
      "culling.\n\n"
      "### The paper (Han et al. 2021, Table 1; cone rule)\n\n"
      "| scene | triangles | PROVOT | PROPOSED | reduction |\n|---|---|---|---|---|\n";
  double red_sum = 0;
  for (const auto& p : kPaper) {
    const double r = reduction(p.pairs_proposed, p.pairs_provot);
    red_sum += r;
    s += fmt::format("| {} | {} | {} | {} | {} |\n", p.scene, grouped(p.triangles),
                     grouped(p.pairs_provot, 2), grouped(p.pairs_proposed, 2), pct(r));
  }
  s += fmt::format("| average | | | | {} (the paper states 25.45%) |\n\n",
                   pct(red_sum / std::size(kPaper)));

  s += "### Ours: reduction of triangle pair tests vs PROVOT, per rule (paper: +25.5% on "
       "average)\n\n| scene | triangles | build |";
  std::vector<std::pair<CullingRule, ConePolicy>> cols;
  for (CullingRule c : opt.cullings) {
    if (c == CullingRule::None) continue;
    for (ConePolicy p : opt.policies) {
      if (p == ConePolicy::Provot) continue;
      cols.emplace_back(c, p);
      s += fmt::format(" {} {} |", culling_name(c), policy_name(p));
    }
  }
  s += "\n|---|---|---|";
  for (std::size_t i = 0; i < cols.size(); ++i)
    s += "---|";
  s += "\n";
  for (const auto& d : data) {
    for (BvhBuild b : opt.builds) {
      s += fmt::format("| {} | {} | {} |", d.seq->name, grouped(double(d.seq->faces.size())),
                       build_name(b));
      for (const auto& [c, p] : cols) {
        const auto it = d.agg.find({build_name(b), culling_name(c), policy_name(p)});
        const auto base = d.agg.find({build_name(b), culling_name(c), "PROVOT"});
        const bool both = it != d.agg.end() && base != d.agg.end();
        s += fmt::format(
            " {} |", both ? pct(reduction(mean(it->second.pairs), mean(base->second.pairs))) : "-");
      }
      s += "\n";
    }
  }
  s += "\n";
  for (const auto& d : data) {
    s += scene_heading(d, opt);
    s += "| build | culling | policy | calls | triangle pairs | vs PROVOT | vs none | VF tests | "
         "EE tests | nodes culled |\n|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& k : config_order(opt)) {
      const auto it = d.agg.find(k);
      if (it == d.agg.end()) continue;
      const Agg& a = it->second;
      const auto base = d.agg.find({k.build, k.culling, "PROVOT"});
      const auto none = d.agg.find({k.build, "none", "-"});
      const double m = mean(a.pairs);
      s += fmt::format(
          "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", k.build, k.culling, k.policy,
          a.calls, grouped(m, 1),
          base != d.agg.end() && k.culling != "none" ? pct(reduction(m, mean(base->second.pairs)))
                                                     : "-",
          none != d.agg.end() && k.culling != "none" ? pct(reduction(m, mean(none->second.pairs)))
                                                     : "-",
          grouped(mean(a.vf), 1), grouped(mean(a.ee), 1), grouped(mean(a.culled), 1));
    }
    s += "\n";
  }
  return s;
}

std::string misses(const std::vector<SceneData>& data, const ExperimentOptions& opt) {
  std::string s =
      "# Missed collisions vs culling `none`\n\n"
      "Per configuration, summed over the CD calls: the unculled reference's collisions (VF and "
      "EE pairs, same build, same step) and how many of them the configuration did not report "
      "(exact pair sets, (vertex, face) and (edge, edge)). *extra* counts pairs reported that "
      "the reference did not (culling only removes work, so it must be 0). `sound` must miss "
      "nothing.\n\n";
  int sound_fail = 0, extra_fail = 0;
  for (const auto& d : data) {
    s += scene_heading(d, opt);
    s += "| build | culling | policy | calls | reference VF | reference EE | missed VF | missed "
         "EE | calls with misses | extra | |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& k : config_order(opt)) {
      const auto it = d.agg.find(k);
      if (it == d.agg.end() || k.culling == "none") continue;
      const Agg& a = it->second;
      std::string verdict;
      if (a.extra > 0) {
        verdict = "**extra pairs: bug**";
        ++extra_fail;
      }
      if (k.culling == "sound") {
        const bool ok = a.missed_vf + a.missed_ee == 0;
        verdict += ok ? "sound: 0 missed" : "**FAIL: sound missed collisions**";
        sound_fail += ok ? 0 : 1;
      } else if (a.missed_vf + a.missed_ee > 0) {
        verdict += "unsound here";
      }
      s += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", k.build,
                       k.culling, k.policy, a.calls, grouped(a.ref_vf), grouped(a.ref_ee),
                       grouped(a.missed_vf), grouped(a.missed_ee), a.steps_missing,
                       grouped(a.extra), verdict);
    }
    s += "\n";
  }
  s += fmt::format("Summary: {} sound configuration(s) with misses, {} with extra pairs.\n",
                   sound_fail, extra_fail);
  return s;
}

std::string spread_table(const std::vector<SceneData>& data, const ExperimentOptions& opt) {
  std::string s =
      "# Spread angles (degrees)\n\n"
      "Every column is a mean over the steps on which OPTIMAL cones were computed (every "
      "`--optimal-every` steps; *steps* says how many). "
      "*node*: the tracked node of fig5 (mid depth, non-saturated PROVOT cone at the first "
      "step; the median such angle). *vs OPTIMAL*: "
      "on the steps with OPTIMAL cones (every `--optimal-every` steps), the mean half-angle over "
      "the internal nodes whose OPTIMAL cone is not saturated, divided by OPTIMAL's mean there. "
      "*internal mean*: over all internal nodes, saturated cones counted as 90.\n\n";
  for (const auto& d : data) {
    s += scene_heading(d, opt);
    s += "| build | policy | node (depth) | node angle | internal mean | saturated share | "
         "mean on OPTIMAL domain | vs OPTIMAL | refit ms | steps |\n"
         "|---|---|---|---|---|---|---|---|---|---|\n";
    for (BvhBuild b : opt.builds) {
      std::vector<std::string> policies;
      for (ConePolicy p : opt.policies)
        policies.push_back(policy_name(p));
      policies.push_back("OPTIMAL");
      // OPTIMAL's domain mean per step, to pair each policy with it step by step.
      std::map<int, double> opt_mean;
      for (const auto& r : d.spread) {
        if (r.build == build_name(b) && r.policy == "OPTIMAL") opt_mean[r.step] = r.opt_domain_mean;
      }
      for (const auto& p : policies) {
        std::vector<double> node, internal, sat, dom, dom_opt, ms;
        int id = -1, depth = -1;
        for (const auto& r : d.spread) {
          if (r.build != build_name(b) || r.policy != p) continue;
          // Only the OPTIMAL steps, when there are any, so every column compares like with like.
          if (!opt_mean.empty() && !opt_mean.contains(r.step)) continue;
          id = r.node;
          depth = r.node_depth;
          node.push_back(r.node_angle);
          internal.push_back(r.internal_mean);
          sat.push_back(r.saturated_share);
          ms.push_back(r.ms_refit);
          if (const auto it = opt_mean.find(r.step);
              it != opt_mean.end() && !std::isnan(r.opt_domain_mean)) {
            dom.push_back(r.opt_domain_mean);
            dom_opt.push_back(it->second);
          }
        }
        if (node.empty()) continue;
        s += fmt::format(
            "| {} | {} | {} ({}) | {:.2f} | {:.2f} | {:.1f}% | {} | {} | {:.1f} | {} "
            "|\n",
            build_name(b), p, id, depth, mean(node), mean(internal), 100 * mean(sat),
            dom.empty() ? "-" : fmt::format("{:.2f}", mean(dom)),
            dom.empty() ? "-" : fmt::format("{:.3f}", mean(dom) / mean(dom_opt)), mean(ms),
            node.size());
      }
    }
    s += "\n";
  }
  return s;
}

// Self-crossing pairs of the frames, per scene.
std::string sequences_table(const std::vector<SceneData>& data, const ExperimentOptions& opt) {
  std::string s =
      "| scene | triangles | frames | CD calls | CD calls run | crossing pairs in the frames "
      "(sum, max per frame) | counted by |\n|---|---|---|---|---|---|---|\n";
  for (const auto& d : data) {
    const auto& c = d.seq->crossings;
    std::string crossing = "not counted";
    if (!c.empty()) {
      long long sum = 0, mx = 0;
      for (long long v : c) {
        sum += v;
        mx = std::max(mx, v);
      }
      crossing = fmt::format("{}, {}", grouped(double(sum)), grouped(double(mx)));
    }
    s += fmt::format("| {} | {} | {} | {} | {} | {} | {} |\n", d.seq->name,
                     grouped(double(d.seq->faces.size())), d.seq->frames.size(), d.seq->steps(),
                     calls_run(*d.seq, opt), crossing,
                     d.seq->crossings_how.empty() ? "-" : d.seq->crossings_how);
  }
  return s + "\n";
}

}  // namespace

// The closing-note view: per scene, build and rule, PROPOSED's and EXACT's reductions vs PROVOT
// (pairs and mean total time) and what each policy missed against `none`.
std::string summary(const std::vector<SceneData>& data, const ExperimentOptions& opt) {
  std::string s =
      "# Summary: PROPOSED and EXACT against PROVOT\n\n"
      "Per scene, BVH build and culling rule: the reduction in triangle pair tests per CD call "
      "(1 - X / PROVOT, positive = fewer; table1.md), in time (*timed 1 / 2 thr*: 1 - the "
      "median ratio to PROVOT's total in the timing pass, paired call by call at 1 and 2 "
      "threads; timing.md, `*` = noisy there, `-` = the rule was not timed), and the collisions "
      "each policy missed against the unculled reference, summed over the calls (misses.md). "
      "Spread angles relative to OPTIMAL: spread.md.\n\n"
      "## The sequences\n\n" +
      sequences_table(data, opt) +
      "## PROPOSED and EXACT against PROVOT\n\n"
      "| scene | calls | build | rule | pairs PROPOSED | pairs EXACT | timed PROPOSED 1 / 2 thr "
      "| timed EXACT 1 / 2 thr | missed PROVOT / PROPOSED / EXACT (of reference) "
      "|\n|---|---|---|---|---|---|---|---|---|\n";
  auto find = [](const SceneData& d, const ConfigKey& k) -> const Agg* {
    const auto it = d.agg.find(k);
    return it == d.agg.end() ? nullptr : &it->second;
  };
  for (const auto& d : data) {
    const auto tagg = timing_aggs(d);
    for (BvhBuild b : opt.builds) {
      for (CullingRule c : opt.cullings) {
        if (c == CullingRule::None) continue;
        const std::string bn = build_name(b), cn = culling_name(c);
        auto timed = [&](const char* policy, int t) -> std::string {
          const auto it = tagg.find({bn, cn, policy, t});
          if (it == tagg.end() || it->second.ratio.empty()) return "-";
          return pct(1.0 - median(it->second.ratio)) + (noisy(it->second.ratio) ? "*" : "");
        };
        const Agg* base = find(d, {bn, cn, "PROVOT"});
        if (base == nullptr) continue;
        auto red = [&](const char* policy, auto&& field) -> std::string {
          const Agg* a = find(d, {bn, cn, policy});
          return a != nullptr ? pct(reduction(mean(field(*a)), mean(field(*base)))) : "-";
        };
        auto pairs = [](const Agg& a) { return a.pairs; };
        auto missed = [&](const char* policy) -> std::string {
          const Agg* a = find(d, {bn, cn, policy});
          return a != nullptr ? grouped(a->missed_vf + a->missed_ee) : "-";
        };
        s += fmt::format(
            "| {} | {} | {} | {} | {} | {} | {} / {} | {} / {} | {} / {} / {} (of {}) |\n",
            d.seq->name, base->calls, bn, cn, red("PROPOSED", pairs), red("EXACT", pairs),
            timed("PROPOSED", 1), timed("PROPOSED", 2), timed("EXACT", 1), timed("EXACT", 2),
            missed("PROVOT"), missed("PROPOSED"), missed("EXACT"),
            grouped(base->ref_vf + base->ref_ee));
      }
    }
  }
  return s;
}

void write_reports(const std::vector<Sequence>& scenes, const ExperimentOptions& opt) {
  std::vector<SceneData> data;
  data.reserve(scenes.size());
  for (const auto& seq : scenes)
    data.push_back(collect(seq, opt));
  std::vector<StepRow> rows;
  std::vector<SpreadRow> spread;
  for (const auto& d : data) {
    rows.insert(rows.end(), d.rows.begin(), d.rows.end());
    spread.insert(spread.end(), d.spread.begin(), d.spread.end());
  }
  std::vector<TimingRow> timing;
  for (const auto& d : data)
    timing.insert(timing.end(), d.timing.begin(), d.timing.end());
  write_file_atomic(opt.out / "steps.csv", detail::step_rows_csv(rows));
  write_file_atomic(opt.out / "spread.csv", detail::spread_rows_csv(spread));
  write_file_atomic(opt.out / "timing.csv", detail::timing_rows_csv(timing));
  // The provenance goes right under each report's title line.
  const std::string stamp_lines =
      opt.stamp.empty()
          ? std::string()
          : opt.stamp + fmt::format("- written: load average (1, 5, 15 min) {}\n", load_average());
  auto stamped = [&](std::string text) {
    if (stamp_lines.empty()) return text;
    const auto eol = text.find("\n\n");
    return eol == std::string::npos
               ? stamp_lines + text
               : text.substr(0, eol + 2) + stamp_lines + "\n" + text.substr(eol + 2);
  };
  // The simulator's own per-substep figures, when an in-situ run wrote them beside the tables.
  std::string pairs_in_situ, times_in_situ;
  if (const fs::path csv = opt.out / "in_situ.csv"; fs::exists(csv)) {
    const auto totals = detail::read_in_situ(csv);
    pairs_in_situ = detail::in_situ_pairs_section(totals);
    times_in_situ = detail::in_situ_times_section(totals);
  }
  write_file_atomic(opt.out / "table1.md", stamped(table1(data, opt) + pairs_in_situ));
  write_file_atomic(opt.out / "table2.md", stamped(table2(data, opt) + times_in_situ));
  write_file_atomic(opt.out / "timing.md", stamped(timing_table(data, opt)));
  write_file_atomic(opt.out / "misses.md", stamped(misses(data, opt)));
  write_file_atomic(opt.out / "spread.md", stamped(spread_table(data, opt)));
  write_file_atomic(opt.out / "summary.md", stamped(summary(data, opt)));
}

std::string run_plots(const fs::path& out, const fs::path& script, const std::string& python) {
  if (!fs::exists(script)) return fmt::format("plot script {} not found", script.string());
  // Quoting: paths come from the command line; single quotes with embedded ones escaped.
  auto quote = [](const std::string& s) {
    std::string q = "'";
    for (char c : s)
      q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
  };
  const std::string cmd =
      fmt::format("{} {} {} 2>&1", quote(python), quote(script.string()), quote(out.string()));
  const int rc = std::system(cmd.c_str());
  if (rc != 0) {
    return fmt::format("'{}' failed (exit status {}); is python3-matplotlib installed for {}?", cmd,
                       rc, python);
  }
  return {};
}

}  // namespace clothcd::experiment
