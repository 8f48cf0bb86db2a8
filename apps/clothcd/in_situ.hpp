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
};

/// Runs every scene under each setting (no culling, then the sound culling with PROVOT, PROPOSED
/// and EXACT cones), one frame of each setting in turn, and writes the Markdown report and a CSV
/// of the per-frame figures beside it. Throws std::runtime_error when two settings' cloth
/// positions differ after a frame (the culling must not change the motion); returns 0.
int run_in_situ(const InSituArgs& args);

}  // namespace clothcd::app
