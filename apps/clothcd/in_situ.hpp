#pragma once
// `clothcd experiment --in-situ`: the self CCD's culling settings compared inside the simulator,
// on the same motion (see in_situ.cpp).

#include <string>
#include <vector>

namespace clothcd::app {

struct InSituArgs {
  std::vector<std::string> scenes;  ///< scene .json files
  int frames = 6;                   ///< frames per scene (at most the scene's own count)
  std::string out;                  ///< the Markdown file, or a folder for in_situ.md
  int threads = 0;                  ///< 0: all cores
  std::string command;              ///< the command line, for the report's header
  /// Only rewrite the in-situ sections of table1.md and table2.md beside `out` from the
  /// in_situ.csv there (experiment::update_in_situ_sections); simulate nothing.
  bool tables_only = false;
};

/// Runs every scene under each setting (no culling, then the sound culling with PROVOT, PROPOSED
/// and EXACT cones), one frame of each setting in turn, and writes the Markdown report and a CSV
/// of the per-frame figures beside it. Throws std::runtime_error when two settings' cloth
/// positions differ after a frame (the culling must not change the motion); returns 0. Then
/// also rewrites the in-situ sections of table1.md and table2.md beside the report, where they
/// exist (experiment::update_in_situ_sections).
int run_in_situ(const InSituArgs& args);

}  // namespace clothcd::app
