// `clothcd ccd-queries PATH...`: runs the CCD kernels on query CSV files with ground truth and
// reports false negatives/positives and timings per file.
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "atomic_json.hpp"
#include "clothcd/ccd/query_csv.hpp"
#include "clothcd/core/error.hpp"
#include "command.hpp"

// A namespace of its own: the commands are compiled together (unity build).
namespace {
namespace ccd_queries_command {

namespace fs = std::filesystem;
using clothcd::QueryKind;

struct Row {
  std::string path;
  std::size_t queries = 0, positives = 0, tp = 0, fn = 0, fp = 0;
  double seconds = 0;
  std::vector<double> times;  // per query, seconds
};

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

nlohmann::json to_json(const Row& r, bool with_path) {
  nlohmann::json j;
  if (with_path) j["path"] = r.path;
  j["queries"] = r.queries;
  j["positives"] = r.positives;
  j["true_positives"] = r.tp;
  j["false_negatives"] = r.fn;
  j["false_positives"] = r.fp;
  j["seconds"] = r.seconds;
  return j;
}

struct Args {
  std::vector<std::string> paths;
  std::string json;
  std::string type;
  double thickness = 0;
  double tolerance = clothcd::CcdOptions{}.tolerance;
  bool no_fast_path = false;
  bool list_misses = false;
};

int run(const Args& args) {
  std::vector<fs::path> inputs(args.paths.begin(), args.paths.end());
  const auto files = clothcd::find_query_files(inputs);
  if (files.empty()) throw clothcd::input_error(args.paths.front(), 0, "no .csv files found");
  clothcd::CcdOptions opt;
  opt.thickness = args.thickness;
  opt.tolerance = args.tolerance;
  opt.fast_path = !args.no_fast_path;

  // Read and validate everything first, so a malformed file fails before any timing.
  std::vector<clothcd::QueryFile> data;
  for (const auto& f : files) {
    QueryKind kind;
    if (args.type == "vf") {
      kind = QueryKind::VertexFace;
    } else if (args.type == "ee") {
      kind = QueryKind::EdgeEdge;
    } else if (auto k = clothcd::query_kind_from_path(f)) {
      kind = *k;
    } else {
      throw clothcd::input_error(
          f.string(), 0,
          "cannot tell VF from EE: no 'vertex-face' or 'edge-edge' folder in the "
          "path; pass --type vf|ee");
    }
    data.push_back(clothcd::read_query_csv(f, kind));
  }

  std::vector<Row> rows;
  Row total;
  total.path = "total";
  for (const auto& file : data) {
    Row r;
    r.path = file.path.string();
    for (const auto& q : file.queries) {
      const auto start = std::chrono::steady_clock::now();
      const clothcd::CcdResult res = clothcd::run_query(file.kind, q, opt);
      const double s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      r.times.push_back(s);
      r.seconds += s;
      ++r.queries;
      r.positives += q.truth;
      r.tp += q.truth && res.hit;
      r.fn += q.truth && !res.hit;
      r.fp += !q.truth && res.hit;
      if (args.list_misses && q.truth != res.hit) {
        fmt::print(stderr, "{}:{}: {} (truth {}, path {}, boxes {})\n", r.path, q.first_line,
                   q.truth ? "false negative" : "false positive", int(q.truth),
                   static_cast<int>(res.path), res.boxes);
      }
    }
    total.queries += r.queries;
    total.positives += r.positives;
    total.tp += r.tp;
    total.fn += r.fn;
    total.fp += r.fp;
    total.seconds += r.seconds;
    total.times.insert(total.times.end(), r.times.begin(), r.times.end());
    rows.push_back(std::move(r));
  }

  std::size_t width = 5;
  for (const auto& r : rows)
    width = std::max(width, r.path.size());
  fmt::print("{:<{}} {:>8} {:>9} {:>8} {:>6} {:>6} {:>10} {:>11}\n", "file", width, "queries",
             "positives", "true_pos", "FN", "FP", "total_s", "median_us");
  auto print_row = [&](const Row& r) {
    fmt::print("{:<{}} {:>8} {:>9} {:>8} {:>6} {:>6} {:>10.4f} {:>11.3f}\n", r.path, width,
               r.queries, r.positives, r.tp, r.fn, r.fp, r.seconds, median(r.times) * 1e6);
  };
  for (const auto& r : rows)
    print_row(r);
  print_row(total);

  if (!args.json.empty()) {
    nlohmann::json j;
    j["files"] = nlohmann::json::array();
    for (const auto& r : rows)
      j["files"].push_back(to_json(r, true));
    j["total"] = to_json(total, false);
    clothcd::app::write_json_atomically(args.json, j, 2);
  }
  if (total.fn > 0) {
    fmt::print(stderr, "clothcd: {} false negative(s)\n", total.fn);
    return 1;
  }
  return 0;
}

const bool registered = clothcd::app::register_command(
    "ccd-queries", "Run the CCD kernels on query CSV files with ground truth (FN, FP, time)",
    [](CLI::App& sub) {
      auto args = std::make_shared<Args>();
      sub.add_option("paths", args->paths, "CSV files or folders (searched recursively)")
          ->required();
      sub.add_option("--json", args->json, "also write the figures to this JSON file");
      sub.add_option("--type", args->type, "query kind for every file (default: from the folder)")
          ->check(CLI::IsMember({"vf", "ee"}));
      sub.add_option("--thickness", args->thickness, "minimum separation (default 0)");
      sub.add_option("--tolerance", args->tolerance,
                     "inclusion solver tolerance, relative to the query extent");
      sub.add_flag("--no-fast-path", args->no_fast_path, "inclusion solver only");
      sub.add_flag("--list-misses", args->list_misses,
                   "print each false negative/positive to stderr");
      return [args] { return run(*args); };
    });

}  // namespace ccd_queries_command
}  // namespace
