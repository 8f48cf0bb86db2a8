#pragma once
// Internal: what the ccd module offers the detectors' narrow phase (src/detect), all in
// clothcd::ccd_detail: the batched filters and kernels over feature pairs (np_batch.hpp: the NP
// filter, the distance filter, the fast path's settling, the kernels after a kept NP verdict),
// the whole-triangle distance bounds, one pair at a time (face_bounds.hpp) and in batches
// (face_batch.hpp), the unchecked distances (distances.hpp), and a hit's time of impact refined
// by bisection, for the earliest-impact query (refine.hpp). Each batched form gives the scalar
// result bit for bit.

#include "ccd/distances.hpp"
#include "ccd/face_batch.hpp"
#include "ccd/face_bounds.hpp"
#include "ccd/np_batch.hpp"
#include "ccd/refine.hpp"
