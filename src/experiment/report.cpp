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

namespace clothcd::experiment {
namespace {

namespace fs = std::filesystem;
using detail::grouped;
using detail::pct;
using detail::reduction;

// The paper's Table 1 (average triangle pair tests) and Table 2 (ms: BVH construction, CD,
// total), PROVOT then PROPOSED.
struct PaperRow {
  const char* scene;
  int triangles;
  double pairs_provot, pairs_proposed;
  double bvh_provot, bvh_proposed, cd_provot, cd_proposed, total_provot, total_proposed;
};
constexpr PaperRow kPaper[] = {
    {"Ensemble 1", 18920, 39997.78, 30795.03, 3.03, 3.67, 17.17, 12.72, 20.12, 16.39},
    {"Ensemble 2", 34877, 87607.41, 60140.21, 8.52, 11.86, 37.77, 22.10, 46.29, 33.97},
    {"Onepiece 1", 20849, 50518.85, 39499.42, 3.96, 4.61, 18.01, 14.29, 21.97, 18.90},
    {"Onepiece 2", 61949, 165412.73, 122977.72, 11.93, 14.06, 62.69, 48.33, 74.62, 62.40},
};

double mean(const std::vector<double>& v) {
  return v.empty() ? std::nan("") : std::accumulate(v.begin(), v.end(), 0.0) / double(v.size());
}

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const double pos = q * double(v.size() - 1);
  const auto lo = static_cast<std::size_t>(pos);
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - double(lo)) * (v[hi] - v[lo]);
}

struct Agg {
  int calls = 0;
  std::vector<double> pairs, vf, ee, culled;
  double missed_vf = 0, missed_ee = 0, extra = 0, ref_vf = 0, ref_ee = 0;
  int steps_missing = 0;
};

struct ConfigKey {
  std::string build, culling, policy;
  auto operator<=>(const ConfigKey&) const = default;
};

// Configurations in table order: per build, the reference, then culling-major, policy-minor.
std::vector<ConfigKey> config_order(const ExperimentOptions& opt) {
  std::vector<ConfigKey> keys;
  for (BvhBuild b : opt.builds) {
    keys.push_back({build_name(b), "none", "-"});
    for (CullingRule c : opt.cullings) {
      if (c == CullingRule::None) continue;
      for (ConePolicy p : opt.policies)
        keys.push_back({build_name(b), culling_name(c), policy_name(p)});
    }
  }
  return keys;
}

struct SceneData {
  const Sequence* seq = nullptr;
  std::map<ConfigKey, Agg> agg;
  std::vector<StepRow> rows;
  std::vector<SpreadRow> spread;
  std::vector<TimingRow> timing;
};

SceneData collect(const Sequence& seq, const ExperimentOptions& opt) {
  SceneData d;
  d.seq = &seq;
  const auto order = config_order(opt);
  for (BvhBuild b : opt.builds) {
    const fs::path dir = opt.out / "runs" / seq.name;
    const fs::path file = dir / (build_name(b) + ".csv");
    const fs::path sfile = dir / (build_name(b) + ".spread.csv");
    if (fs::exists(file)) {
      for (auto& r : read_step_rows(file)) {
        if (r.step >= seq.steps()) continue;
        if (std::find(order.begin(), order.end(), ConfigKey{r.build, r.culling, r.policy}) ==
            order.end()) {
          continue;  // a configuration not asked for this time
        }
        d.rows.push_back(std::move(r));
      }
    }
    if (fs::exists(sfile)) {
      for (auto& r : read_spread_rows(sfile)) {
        if (r.step < seq.steps()) d.spread.push_back(std::move(r));
      }
    }
    const fs::path tfile = dir / (build_name(b) + ".timing.csv");
    if (fs::exists(tfile)) {
      for (auto& r : read_timing_rows(tfile)) {
        if (r.step >= seq.steps()) continue;
        if (r.culling != "none" &&
            std::find(order.begin(), order.end(), ConfigKey{r.build, r.culling, r.policy}) ==
                order.end()) {
          continue;
        }
        d.timing.push_back(std::move(r));
      }
    }
  }
  // The reference's pair counts per (build, step), for the misses table.
  std::map<std::pair<std::string, int>, const StepRow*> ref;
  for (const auto& r : d.rows) {
    if (r.culling == "none") ref[{r.build, r.step}] = &r;
  }
  for (const auto& r : d.rows) {
    Agg& a = d.agg[{r.build, r.culling, r.policy}];
    ++a.calls;
    a.pairs.push_back(r.triangle_pairs);
    a.vf.push_back(r.vf_tests);
    a.ee.push_back(r.ee_tests);
    a.culled.push_back(r.nodes_culled);
    a.missed_vf += r.missed_vf;
    a.missed_ee += r.missed_ee;
    a.extra += r.extra_vf + r.extra_ee;
    a.steps_missing += (r.missed_vf + r.missed_ee > 0) ? 1 : 0;
    if (const auto it = ref.find({r.build, r.step}); it != ref.end()) {
      a.ref_vf += it->second->vf_collisions;
      a.ref_ee += it->second->ee_collisions;
    }
  }
  return d;
}

// "2nd", "3rd", "4th", "11th", "21st".
std::string ordinal(int n) {
  const int t = n % 100;
  const char* suffix = (t >= 11 && t <= 13) ? "th"
                       : n % 10 == 1        ? "st"
                       : n % 10 == 2        ? "nd"
                       : n % 10 == 3        ? "rd"
                                            : "th";
  return fmt::format("{}{}", n, suffix);
}

// CD calls run of a sequence (Sequence::every).
int calls_run(const Sequence& seq, const ExperimentOptions& /*opt*/) {
  const int e = std::max(1, seq.every);
  return (seq.steps() + e - 1) / e;
}

std::string calls_text(const Sequence& seq, const ExperimentOptions& opt) {
  const int run = calls_run(seq, opt);
  return run == seq.steps()
             ? fmt::format("{} CD calls", run)
             : fmt::format("{} of its {} CD calls: every {}", run, seq.steps(), ordinal(seq.every));
}

std::string scene_heading(const SceneData& d, const ExperimentOptions& opt) {
  return fmt::format("## {} ({} triangles, {})\n\nFrames: {}\n\n", d.seq->name,
                     grouped(double(d.seq->faces.size())), calls_text(*d.seq, opt), d.seq->source);
}

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

// Per (build, culling, policy, threads): the totals of the timing pass and, paired call by call
// (same step, repeat and thread count), the ratio to PROVOT under the same rule.
struct TimingAgg {
  std::vector<double> total, refit, cd, ratio;
  std::map<int, std::vector<double>> step_totals;  ///< the repeats of each timed step
};
using TimingKey = std::tuple<std::string, std::string, std::string, int>;

std::map<TimingKey, TimingAgg> timing_aggs(const SceneData& d) {
  std::map<std::tuple<std::string, std::string, int, int, int>, double> provot;
  for (const auto& r : d.timing) {
    if (r.policy == "PROVOT")
      provot[{r.build, r.culling, r.step, r.repeat, r.threads}] = r.ms_total();
  }
  std::map<TimingKey, TimingAgg> out;
  for (const auto& r : d.timing) {
    TimingAgg& a = out[{r.build, r.culling, r.policy, r.threads}];
    a.total.push_back(r.ms_total());
    a.step_totals[r.step].push_back(r.ms_total());
    a.refit.push_back(r.ms_refit);
    a.cd.push_back(r.ms_traverse + r.ms_narrow);
    const auto it = provot.find({r.build, r.culling, r.step, r.repeat, r.threads});
    if (r.culling != "none" && it != provot.end() && it->second > 0) {
      a.ratio.push_back(r.ms_total() / it->second);
    }
  }
  return out;
}

std::string table2(const std::vector<SceneData>& data, const ExperimentOptions& opt) {
  std::string s =
      "# Table 2: average time per CD call (ms)\n\n"
      "refit = swept boxes + normal cones (the paper's \"BVH construction\"; ours refits a tree "
      "built once), CD = self traversal + narrow phase (VF/EE tests with the NP filter and the "
      "CCD kernels), total = refit + CD; *vs PROVOT* = 1 - total / PROVOT's total under the "
      "same build, culling rule and thread count. Means over the calls of the timing pass, as "
      "the paper gives means, plus the median of the total: the CD calls it times (see "
      "timing.md), each configuration repeated and interleaved with the others on the same "
      "frames, at each thread count. Compare within a scene; timing.md gives the spreads, the "
      "machine's load and the ratios paired call by call. The counting pass (Table 1) "
      "measures no time: it counts all configurations of a call with one narrow phase.\n\n"
      "### The paper (Han et al. 2021, Table 2; Intel Core i9-9900)\n\n"
      "| scene | BVH PROVOT | BVH PROPOSED | CD PROVOT | CD PROPOSED | total PROVOT | total "
      "PROPOSED | reduction |\n|---|---|---|---|---|---|---|---|\n";
  double red_sum = 0;
  for (const auto& p : kPaper) {
    const double r = reduction(p.total_proposed, p.total_provot);
    red_sum += r;
    s += fmt::format("| {} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {} |\n", p.scene,
                     p.bvh_provot, p.bvh_proposed, p.cd_provot, p.cd_proposed, p.total_provot,
                     p.total_proposed, pct(r));
  }
  s += fmt::format("| average | | | | | | | {} (the paper states 18.24%) |\n\n",
                   pct(red_sum / std::size(kPaper)));
  for (const auto& d : data) {
    if (d.timing.empty()) continue;
    s += scene_heading(d, opt);
    s += "| build | culling | policy | threads | calls | refit | CD | total | median total | vs "
         "PROVOT |\n|---|---|---|---|---|---|---|---|---|---|\n";
    const auto agg = timing_aggs(d);
    for (const auto& k : config_order(opt)) {
      for (int t = 1; t <= 1024; ++t) {
        const auto it = agg.find({k.build, k.culling, k.policy, t});
        if (it == agg.end()) continue;
        const TimingAgg& a = it->second;
        const auto base = agg.find({k.build, k.culling, "PROVOT", t});
        s += fmt::format("| {} | {} | {} | {} | {} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {} |\n",
                         k.build, k.culling, k.policy, t, a.total.size(), mean(a.refit), mean(a.cd),
                         mean(a.total), median(a.total),
                         base != agg.end() && k.culling != "none"
                             ? pct(reduction(mean(a.total), mean(base->second.total)))
                             : "-");
      }
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

// A figure is flagged noisy when the same call, repeated, varies by more than a fifth of its
// median (the steps differ in cost by themselves, so the spread over all calls would not say).
constexpr double kNoisy = 0.2;

// Median over the timed steps of (max - min) / median of that step's repeats.
double repeat_spread(const TimingAgg& a) {
  std::vector<double> v;
  for (const auto& [step, t] : a.step_totals) {
    const double m = median(t);
    if (t.size() >= 2 && m > 0)
      v.push_back((*std::max_element(t.begin(), t.end()) - *std::min_element(t.begin(), t.end())) /
                  m);
  }
  return median(v);
}

bool noisy(const std::vector<double>& v) {
  const double m = median(v);
  return !(m > 0) || (quantile(v, 0.75) - quantile(v, 0.25)) > kNoisy * m;
}

std::string timing_table(const std::vector<SceneData>& data, const ExperimentOptions& opt) {
  std::string s = fmt::format(
      "# Timings per CD call (ms): medians over repeated, interleaved calls\n\n"
      "The timing pass runs on {} that the experiment runs: each configuration "
      "(the unculled reference and every policy under the timed rules) {} times under each thread "
      "count, repeat by repeat, thread count by thread count, with the configurations in an "
      "order rotated per repeat, all on the same frame pair. *total* = refit + traversal + "
      "narrow phase; p25-p75 = interquartile range over those calls (the steps differ in cost by "
      "themselves); *repeat spread* = the median over the timed steps of (max - min) / median of "
      "one step's repeats, the noise of the machine; */ PROVOT* = median of "
      "the ratio to PROVOT's total of the same call (same step, repeat and thread count, same "
      "build and rule): below 1 = faster. A row is marked *noisy* when its repeat spread "
      "exceeds {:.0f}%. *load* = the 1-minute load average read before "
      "each timed step (min-max); on a machine with as many cores as threads in use, anything "
      "above the thread count means other processes shared the cores.\n\n",
      opt.timing_every == 1 ? std::string("every CD call")
                            : fmt::format("every {} CD call", ordinal(opt.timing_every)),
      opt.timing_repeats, 100 * kNoisy);
  bool any = false;
  for (const auto& d : data) {
    if (d.timing.empty()) continue;
    any = true;
    std::set<int> steps;
    double lo = 1e300, hi = -1e300;
    for (const auto& r : d.timing) {
      steps.insert(r.step);
      lo = std::min(lo, r.load1);
      hi = std::max(hi, r.load1);
    }
    s += scene_heading(d, opt);
    s += fmt::format(
        "Timed steps: {} ({}); load {:.2f}-{:.2f}.\n\n", steps.size(),
        steps.size() <= 12 ? fmt::format("{}", fmt::join(steps, ", ")) : "see timing.csv", lo, hi);
    if (const long cores = ::sysconf(_SC_NPROCESSORS_ONLN); cores > 0 && hi > double(cores)) {
      s += fmt::format(
          "**Shared machine: the load reached {:.2f} on {} cores while this scene was timed, so "
          "other processes took turns on the cores; every time below is noisy, the ratios to "
          "PROVOT (paired call by call) less so.**\n\n",
          hi, cores);
    }
    s += "| build | culling | policy | threads | calls | median total | p25-p75 | repeat spread | "
         "median refit | median CD | / PROVOT | "
         "|\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    const auto agg = timing_aggs(d);
    for (const auto& k : config_order(opt)) {
      for (int t = 1; t <= 1024; ++t) {
        const auto it = agg.find({k.build, k.culling, k.policy, t});
        if (it == agg.end()) continue;
        const TimingAgg& a = it->second;
        const double spread = repeat_spread(a);
        const bool n = !(spread <= kNoisy);
        s += fmt::format(
            "| {} | {} | {} | {} | {} | {:.2f} | {:.2f}-{:.2f} | {} | {:.2f} | {:.2f} | {} | {} "
            "|\n",
            k.build, k.culling, k.policy, t, a.total.size(), median(a.total),
            quantile(a.total, 0.25), quantile(a.total, 0.75),
            std::isnan(spread) ? std::string("-") : fmt::format("{:.0f}%", 100 * spread),
            median(a.refit), median(a.cd),
            a.ratio.empty() ? std::string("-") : fmt::format("{:.3f}", median(a.ratio)),
            n ? "noisy" : "");
      }
    }
    s += "\n";
  }
  if (!any) s += "No timing pass was run (`--timing-every`).\n";
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
