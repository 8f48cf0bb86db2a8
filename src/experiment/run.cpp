// Runs every configuration over a sequence: one detector per BVH build (the build is fixed at
// construction; policy and culling change per call). The counting pass takes each step's
// unculled reference and every (policy, culling) from one SelfDetector::detect_each call; the
// timing pass times them with detect(), interleaved and repeated.
#include <fmt/format.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <numbers>
#include <optional>
#include <set>
#include <tuple>

#include "clothcd/bvh/bvh.hpp"
#include "clothcd/core/atomic_file.hpp"
#include "clothcd/core/error.hpp"
#include "clothcd/experiment/experiment.hpp"
#include "clothcd/research/detector.hpp"
#include "clothcd/research/refit.hpp"
#include "records.hpp"

namespace clothcd::experiment {

// The research options and detector: the unsound rules, optimal cones and detect_each.
using research::DetectOptions;
using research::SelfDetector;

namespace {

namespace fs = std::filesystem;
constexpr double kDeg = 180.0 / std::numbers::pi;

// The detector settings of the paper's measurements on one tree build: the NP filter alone before
// the kernels (no whole-triangle bound), so that the feature-test counts are its pipeline's.
DetectOptions paper_options(BvhBuild build) {
  DetectOptions o;
  o.build = build;
  o.distance_filter = false;
  return o;
}

std::vector<Eigen::Vector3d> points(const Positions& p) {
  std::vector<Eigen::Vector3d> out(static_cast<std::size_t>(p.rows()));
  for (Eigen::Index i = 0; i < p.rows(); ++i)
    out[static_cast<std::size_t>(i)] = p.row(i).transpose();
  return out;
}

// |a \ b| for sorted collision lists compared by their feature ids only (not the toi).
template <class T, class Key>
std::size_t count_missing(const std::vector<T>& a, const std::vector<T>& b, Key key) {
  std::size_t n = 0;
  auto j = b.begin();
  for (const T& x : a) {
    while (j != b.end() && key(*j) < key(x))
      ++j;
    if (j == b.end() || key(x) < key(*j)) ++n;
  }
  return n;
}

auto vf_key = [](const VertexFaceCollision& c) { return std::pair(c.vertex, c.face); };
auto ee_key = [](const EdgeEdgeCollision& c) { return std::pair(c.edge_a, c.edge_b); };

StepRow make_row(const Sequence& seq, BvhBuild build, int step, CullingRule c, const std::string& p,
                 const DetectResult& r, const DetectResult& ref) {
  const DetectStats& s = r.stats;
  StepRow row;
  row.scene = seq.name;
  row.build = build_name(build);
  row.culling = culling_name(c);
  row.policy = p;
  row.step = step;
  row.faces = static_cast<double>(seq.faces.size());
  row.triangle_pairs = double(s.triangle_pairs);
  row.vf_tests = double(s.vf_tests);
  row.ee_tests = double(s.ee_tests);
  row.vf_np_culled = double(s.vf_np_culled);
  row.ee_np_culled = double(s.ee_np_culled);
  row.box_tests = double(s.box_tests);
  row.cone_tests = double(s.cone_tests);
  row.nodes_culled = double(s.nodes_culled);
  row.contour_tests = double(s.contour_tests);
  row.contour_fails = double(s.contour_fails);
  row.vf_collisions = double(r.vf.size());
  row.ee_collisions = double(r.ee.size());
  row.missed_vf = double(count_missing(ref.vf, r.vf, vf_key));
  row.missed_ee = double(count_missing(ref.ee, r.ee, ee_key));
  row.extra_vf = double(count_missing(r.vf, ref.vf, vf_key));
  row.extra_ee = double(count_missing(r.ee, ref.ee, ee_key));
  row.ms_refit = 1e3 * s.time_refit;
  row.ms_traverse = 1e3 * s.time_traverse;
  row.ms_narrow = 1e3 * s.time_narrow;
  return row;
}

// The tracked node of Figure 5: at mid depth (or the first deeper level that has one), a node
// whose PROVOT cone at the first step is neither skinny nor saturated; of those, the one with the
// median angle, so the choice favours no policy.
std::pair<int, int> pick_node(const Bvh& bvh) {
  const auto& cones = bvh.cones();
  const auto& nodes = bvh.nodes();
  const auto& lv = bvh.level_offsets();
  for (int d = std::max(1, bvh.depth() / 2); d < bvh.depth(); ++d) {
    std::vector<std::pair<double, int>> cand;
    for (int i = lv[d]; i < lv[d + 1]; ++i) {
      if (!nodes[i].is_leaf() && !cones[i].saturated() && cones[i].half_angle > 1e-6) {
        cand.emplace_back(cones[i].half_angle, i);
      }
    }
    if (!cand.empty()) {
      std::sort(cand.begin(), cand.end());
      return {cand[cand.size() / 2].second, d};
    }
  }
  return {0, 0};  // everything saturated: track the root
}

int depth_of(const Bvh& bvh, int node) {
  const auto& lv = bvh.level_offsets();
  for (int d = 0; d + 1 < static_cast<int>(lv.size()); ++d) {
    if (node < lv[d + 1]) return d;
  }
  return -1;
}

std::vector<SpreadRow> spreads(const Sequence& seq, BvhBuild build, int step, Bvh& bvh,
                               const std::vector<ConePolicy>& policies, bool optimal,
                               const std::vector<Eigen::Vector3d>& v0,
                               const std::vector<Eigen::Vector3d>& v1, int node) {
  std::vector<ConeRule> all;
  if (optimal) all.push_back(ConeRule::Optimal);  // first: its domain is needed
  for (ConePolicy p : policies) {
    DetectOptions o;
    o.policy = p;
    all.push_back(research::cone_rule(o));
  }
  std::vector<char> domain;
  std::vector<SpreadRow> out;
  for (ConeRule p : all) {
    const auto t = std::chrono::steady_clock::now();
    research::refit(bvh, v0, v1, RefitOptions{}, p);
    const double ms =
        1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
    const auto& cones = bvh.cones();
    const auto& nodes = bvh.nodes();
    if (p == ConeRule::Optimal) {
      domain.assign(nodes.size(), 0);
      for (std::size_t i = 0; i < nodes.size(); ++i)
        domain[i] = !nodes[i].is_leaf() && !cones[i].saturated();
    }
    SpreadRow r;
    r.scene = seq.name;
    r.build = build_name(build);
    r.policy = policy_name(p);
    r.step = step;
    r.node = node;
    r.node_depth = depth_of(bvh, node);
    // A saturated cone may store more than pi/2 (propagated saturation); it means "90 or more".
    r.node_angle = cones[node].saturated() ? 90.0 : kDeg * cones[node].half_angle;
    double sum = 0, dsum = 0;
    int internal = 0, saturated = 0, dn = 0;
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      if (nodes[i].is_leaf()) continue;
      ++internal;
      const double a = cones[i].saturated() ? std::numbers::pi / 2 : cones[i].half_angle;
      sum += a;
      saturated += cones[i].saturated() ? 1 : 0;
      if (!domain.empty() && domain[i] != 0) {
        dsum += a;
        ++dn;
      }
    }
    r.internal_mean = internal > 0 ? kDeg * sum / internal : std::nan("");
    r.saturated_share = internal > 0 ? double(saturated) / internal : 0.0;
    r.opt_domain_mean = dn > 0 ? kDeg * dsum / dn : std::nan("");
    r.opt_domain_nodes = dn;
    r.ms_refit = ms;
    out.push_back(r);
  }
  return out;
}

double load1() {
  std::ifstream in("/proc/loadavg");
  double v = std::nan("");
  in >> v;
  return v;
}

TimingRow timing_row(const Sequence& seq, BvhBuild build, int step, CullingRule c, ConePolicy p,
                     int threads, int repeat, double load, const DetectStats& s) {
  TimingRow row;
  row.scene = seq.name;
  row.build = build_name(build);
  row.culling = culling_name(c);
  row.policy = c == CullingRule::None ? "-" : policy_name(p);
  row.step = step;
  row.threads = threads;
  row.repeat = repeat;
  row.load1 = load;
  row.ms_refit = 1e3 * s.time_refit;
  row.ms_traverse = 1e3 * s.time_traverse;
  row.ms_narrow = 1e3 * s.time_narrow;
  return row;
}

// The timing pass of one step (see ExperimentOptions::timing_every).
std::vector<TimingRow> time_step(const Sequence& seq, BvhBuild build, int step,
                                 const ExperimentOptions& opt, SelfDetector& det,
                                 const Positions& x0, const Positions& x1) {
  std::vector<std::pair<ConePolicy, CullingRule>> cfgs{{ConePolicy::Provot, CullingRule::None}};
  for (CullingRule c : opt.timing_cullings) {
    if (c == CullingRule::None) continue;
    for (ConePolicy p : opt.policies)
      cfgs.emplace_back(p, c);
  }
  const double load = load1();
  std::vector<TimingRow> out;
  const std::size_t n = cfgs.size();
  for (int rep = 0; rep < opt.timing_repeats; ++rep) {
    for (int t : opt.timing_threads) {
      const tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                                      static_cast<std::size_t>(std::max(1, t)));
      const int threads = static_cast<int>(
          tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
      for (std::size_t i = 0; i < n; ++i) {
        // Rotated per repeat: no configuration always runs first (cold caches) or last.
        const auto [p, c] = cfgs[(i + static_cast<std::size_t>(rep)) % n];
        DetectOptions o = paper_options(build);
        o.policy = p;
        research::set_culling_rule(o, c);
        det.set_options(o);
        const DetectResult r = det.detect(x0, x1);
        out.push_back(timing_row(seq, build, step, c, p, threads, rep, load, r.stats));
      }
    }
  }
  return out;
}

}  // namespace

void run_sequence(const Sequence& seq, const ExperimentOptions& opt,
                  const std::function<void(const Progress&)>& on_progress, int done_before,
                  int total) {
  const fs::path dir = opt.out / "runs" / seq.name;
  fs::create_directories(dir);
  int done = done_before;
  const int every = std::max(1, seq.every);
  const int run_steps = (seq.steps() + every - 1) / every;
  if (total <= 0) total = run_steps * static_cast<int>(opt.builds.size());
  for (BvhBuild build : opt.builds) {
    const fs::path file = dir / (build_name(build) + ".csv");
    const fs::path sfile = dir / (build_name(build) + ".spread.csv");
    const fs::path tfile = dir / (build_name(build) + ".timing.csv");
    std::vector<TimingRow> trows =
        fs::exists(tfile) ? read_timing_rows(tfile) : std::vector<TimingRow>{};
    std::set<int> have_timing;
    for (const auto& r : trows)
      have_timing.insert(r.step);
    std::vector<StepRow> rows = fs::exists(file) ? read_step_rows(file) : std::vector<StepRow>{};
    std::vector<SpreadRow> srows =
        fs::exists(sfile) ? read_spread_rows(sfile) : std::vector<SpreadRow>{};
    std::set<std::tuple<int, std::string, std::string>> have;
    for (const auto& r : rows)
      have.emplace(r.step, r.culling, r.policy);
    std::set<std::pair<int, std::string>> have_spread;
    int node = srows.empty() ? -1 : srows.front().node;
    for (const auto& r : srows)
      have_spread.emplace(r.step, r.policy);

    std::optional<SelfDetector> det;
    std::optional<Bvh> bvh;
    std::vector<Eigen::Vector3d> ref_points;
    auto ensure = [&] {
      if (det) return;
      const DetectOptions o = paper_options(build);
      det.emplace(seq.faces, seq.num_vertices, seq.frames[0], o);
      ref_points = points(seq.frames[0]);
      bvh.emplace(det->topology(), ref_points, build);
      // The spread angles must describe the detector's tree: same build, same reference.
      if (bvh->prim_ids() != det->bvh().prim_ids() ||
          bvh->nodes().size() != det->bvh().nodes().size()) {
        throw std::logic_error("experiment: the spread-angle BVH differs from the detector's");
      }
      if (node < 0) {
        RefitOptions ro;
        ro.policy = ConePolicy::Provot;
        const auto p0 = points(seq.frames[0]), p1 = points(seq.frames[1]);
        bvh->refit(p0, p1, ro);
        node = pick_node(*bvh).first;
      }
    };

    for (int step = 0; step < seq.steps(); step += every) {
      std::vector<std::pair<ConePolicy, CullingRule>> todo;
      for (ConePolicy p : opt.policies) {
        for (CullingRule c : opt.cullings) {
          if (c == CullingRule::None) continue;
          if (!have.contains({step, culling_name(c), policy_name(p)})) todo.emplace_back(p, c);
        }
      }
      const bool need_none = !have.contains({step, "none", "-"});
      const bool optimal_step = opt.optimal_every > 0 && (step / every) % opt.optimal_every == 0 &&
                                (opt.optimal_max_faces <= 0 ||
                                 static_cast<int>(seq.faces.size()) <= opt.optimal_max_faces);
      bool need_spread = optimal_step && !have_spread.contains({step, "OPTIMAL"});
      for (ConePolicy p : opt.policies)
        need_spread = need_spread || !have_spread.contains({step, policy_name(p)});
      const bool need_timing =
          opt.timing_every > 0 && opt.timing_repeats > 0 && !opt.timing_threads.empty() &&
          (step / every) % opt.timing_every == 0 && !have_timing.contains(step);
      const std::string what =
          fmt::format("{} {} step {}/{}", seq.name, build_name(build), step + 1, seq.steps());
      if (todo.empty() && !need_none && !need_spread && !need_timing) {
        ++done;
        if (on_progress) on_progress({done, total, false, what});
        continue;
      }
      ensure();
      const Positions& x0 = seq.frames[static_cast<std::size_t>(step)];
      const Positions& x1 = seq.frames[static_cast<std::size_t>(step) + 1];
      if (need_none || !todo.empty()) {
        // The unculled reference first, then every (policy, rule): one detect_each call counts
        // them all with one narrow phase (their times come from the timing pass).
        std::vector<DetectOptions> cfgs{paper_options(build)};
        cfgs[0].culling = Culling::None;
        for (const auto& [p, c] : todo) {
          DetectOptions o = cfgs[0];
          o.policy = p;
          research::set_culling_rule(o, c);
          cfgs.push_back(o);
        }
        const std::vector<DetectResult> found = det->detect_each(x0, x1, cfgs);
        const DetectResult& ref = found[0];
        if (need_none) {
          rows.push_back(make_row(seq, build, step, CullingRule::None, "-", ref, ref));
          have.emplace(step, "none", "-");
        }
        for (std::size_t k = 0; k < todo.size(); ++k) {
          const auto [p, c] = todo[k];
          rows.push_back(make_row(seq, build, step, c, policy_name(p), found[k + 1], ref));
          have.emplace(step, culling_name(c), policy_name(p));
        }
      }
      if (need_spread) {
        std::erase_if(srows, [&](const SpreadRow& r) { return r.step == step; });
        const auto p0 = points(x0), p1 = points(x1);
        for (auto& r : spreads(seq, build, step, *bvh, opt.policies, optimal_step, p0, p1, node)) {
          have_spread.emplace(step, r.policy);
          srows.push_back(std::move(r));
        }
      }
      if (need_timing) {
        for (auto& r : time_step(seq, build, step, opt, *det, x0, x1))
          trows.push_back(std::move(r));
        have_timing.insert(step);
        write_file_atomic(tfile, detail::timing_rows_csv(trows));
      }
      std::stable_sort(rows.begin(), rows.end(),
                       [](const StepRow& a, const StepRow& b) { return a.step < b.step; });
      std::stable_sort(srows.begin(), srows.end(),
                       [](const SpreadRow& a, const SpreadRow& b) { return a.step < b.step; });
      // Spread first: the step counts as done once its detection rows are on disk.
      write_file_atomic(sfile, detail::spread_rows_csv(srows));
      write_file_atomic(file, detail::step_rows_csv(rows));
      ++done;
      if (on_progress) on_progress({done, total, true, what});
    }
  }
}

}  // namespace clothcd::experiment
