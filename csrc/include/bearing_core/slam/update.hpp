// One movement per map for a batch of maps (bearing_env/slam/kernels/update.py): the
// entry point the env step and the bindings call.
#pragma once

#include <cstdint>

#include <bearing_core/slam/state.hpp>

namespace bearing::slam {

struct Buffers;      // slam/scratch.hpp
struct FrameChange;  // slam/frames.hpp

// One movement's frame code (FramePlan's status) and, when it is FRAME_OK, its change of
// frames from A_L1 = a1[:n1] and A_L2 = a2[:n2] as `transfer` makes it: the hypotheses
// sampled into buf.h1 and buf.inv_d and, for TRANSFER_CONSERVATIVE, the sub-squares
// planned into buf.sub. The update and the transfer_polygon binding both use it.
int64_t change_of_frames(const cplx* a1, int64_t n1, const cplx* a2, int64_t n2, int64_t transfer,
                         int64_t edge_samples, Buffers& buf, FrameChange& frame);

// Fuse one movement into each map rows[i] (bearings row i), in place, reporting to out
// row i. With threads > 1 the rows are split into `threads` contiguous blocks, one per
// thread, exactly as numba's update_maps_parallel split them; every map is computed by
// the same code either way, so the result does not depend on the thread count.
// bearings_start and bearings_end are (rows, n_landmarks), C-contiguous.
void update_maps(View2<const double> bearings_start, View2<const double> bearings_end,
                 View1<const int64_t> rows, const Params& params, const MapState& state,
                 const Outputs& out, int64_t threads);

}  // namespace bearing::slam

// ---- Added by the update port: the batch helpers of update.py (check_indices,
// ---- none_infinite, contains_points), for the bindings.
namespace bearing::slam {

// Outcomes of check_indices.
#define BEARING_CORE_INDEX_CHECK(E) E(INDEX_OK, 0) E(INDEX_OUT_OF_RANGE, 1) E(INDEX_REPEATED, 2)
enum IndexCheck : int64_t { BEARING_CORE_INDEX_CHECK(BEARING_CORE_ENUM_MEMBER) };

// Whether indices[:n] are in [0, size) (and, if distinct, none repeats). `seen` holds
// `size` flags (only used when distinct; the caller provides it).
int64_t check_indices(const int64_t* indices, int64_t n, int64_t size, bool distinct, bool* seen);

// out(i, j): region j of map rows[i] contains points(i, j) (relative tolerance).
void contains_points(View3<const cplx> vertices, View2<const int64_t> counts,
                     View1<const int64_t> rows, View2<const cplx> points, double relative,
                     View2<bool> out);

}  // namespace bearing::slam
