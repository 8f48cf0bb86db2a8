// The plot script of the experiment harness (fig5.png, fig6.png) on a tiny procedural run; needs
// /usr/bin/python3 with matplotlib (Debian's python3-matplotlib) and skips without it. Labelled
// slow: importing matplotlib takes seconds on a loaded machine.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "clothcd/experiment/experiment.hpp"

namespace {

namespace fs = std::filesystem;
using namespace clothcd::experiment;

TEST(Experiment, PlotScript) {
  if (!fs::exists("/usr/bin/python3") ||
      std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "/usr/bin/python3 with matplotlib not found (apt-get install "
                    "python3-matplotlib)";
  }
  const Sequence seq = folding_sheet(8, 4);
  ExperimentOptions opt;
  opt.out = fs::temp_directory_path() /
            ("clothcd_experiment_plot_test_" +
             std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  fs::remove_all(opt.out);
  opt.optimal_every = 2;
  run_sequence(seq, opt);
  write_reports({seq}, opt);
  EXPECT_EQ(run_plots(opt.out, CLOTHCD_PLOT_SCRIPT), "");
  for (const char* f : {"fig5.png", "fig6.png"}) {
    ASSERT_TRUE(fs::exists(opt.out / f)) << f;
    EXPECT_GT(fs::file_size(opt.out / f), 10000u) << f;
  }
  EXPECT_NE(run_plots(opt.out, opt.out / "no_such_script.py"), "");
  fs::remove_all(opt.out);
}

}  // namespace
