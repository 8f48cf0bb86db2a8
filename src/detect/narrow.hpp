#pragma once
// Feature-level tests shared by the detector and the brute-force oracle, so both put every VF and
// EE pair through exactly the same box test, NP filter and kernel, in data-flow order:
// feature_batches.hpp (per-thread queues and counters), feature_context.hpp (the step's settings,
// filters and kernels), feature_boxes.hpp (swept feature boxes and their tests), ownership.hpp
// (R-triangle ownership and the owned feature pairs of a triangle pair). The detectors' pair loop
// over them is pair_loop.hpp.

#include "detect/ownership.hpp"
