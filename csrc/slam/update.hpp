// One movement per map for a batch of maps (bearing_env/slam/kernels/update.py): the
// entry point the env step and the bindings call.
#pragma once

#include <cstdint>

#include "slam/state.hpp"

namespace bearing::slam {

// Fuse one movement into each map rows[i] (bearings row i), in place, reporting to out
// row i. With threads > 1 the rows are split into `threads` contiguous blocks, one per
// thread, exactly as numba's update_maps_parallel split them; every map is computed by
// the same code either way, so the result does not depend on the thread count.
// bearings_start and bearings_end are (rows, n_landmarks), C-contiguous.
void update_maps(View2<const double> bearings_start, View2<const double> bearings_end,
                 View1<const int64_t> rows, const Params& params, const MapState& state,
                 const Outputs& out, int64_t threads);

}  // namespace bearing::slam
