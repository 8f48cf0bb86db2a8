// The experiment's records gathered per scene and configuration, and their statistics.
#include "scene_data.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numeric>

#include "format.hpp"

namespace clothcd::experiment::detail {

namespace fs = std::filesystem;

std::string ordinal(int n) {
  const int t = n % 100;
  const char* suffix = (t >= 11 && t <= 13) ? "th"
                       : n % 10 == 1        ? "st"
                       : n % 10 == 2        ? "nd"
                       : n % 10 == 3        ? "rd"
                                            : "th";
  return fmt::format("{}{}", n, suffix);
}

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

}  // namespace clothcd::experiment::detail
