// Table 2 and the timing report: the timing pass's calls, per configuration and thread count.
#include <fmt/format.h>

#include <set>
#include <string>
#include <vector>

#include "format.hpp"
#include "scene_data.hpp"

namespace clothcd::experiment::detail {

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

}  // namespace clothcd::experiment::detail
