// The buffers one thread of the map update works in (bearing_env/slam/kernels/state.py
// Scratch and update.py Buffers), as fixed-capacity arrays: no allocation per movement.
//
// A thread gets one Buffers per update_maps call (update.cpp keeps one per thread and
// reuses it); every polygon kernel writes only within these capacities, and every copy
// whose length depends on data is guarded by check_capacity.
#pragma once

#include <algorithm>
#include <cstdint>

#include <bearing_core/core/complex.hpp>
#include <bearing_core/core/errors.hpp>
#include <bearing_core/slam/local_bound.hpp>
#include <bearing_core/slam/state.hpp>

namespace bearing::slam {

// Most landmarks one movement's bearings hold, L1 and L2 included (so at most
// MAX_LANDMARKS - 2 mapped landmarks per map). The numba kernels sized these buffers by
// the call's landmark count; here they are fixed, and update_maps raises CapacityError
// for a wider batch. 256 is far above any env setting (tens of landmarks).
inline constexpr int64_t MAX_LANDMARKS = 256;

// Length of Scratch::fresh: a transfer's output, or a robot-frame point's cloud hull.
inline constexpr int64_t FRESH_CAPACITY = std::max(MAX_CLOUD + 1, SCRATCH);

// Polygon buffers of one thread (state.py Scratch, sized as new_scratch sizes them):
// `fresh` takes a transferred region, `fused` and `work` a clip's result and its working
// copy, `cloud` and `hull` a transfer's images and their hull, `acc` the relaxed
// fusion's union and `slots` the window slots it combines.
struct Scratch {
    cplx fresh[FRESH_CAPACITY];
    cplx fused[SCRATCH];
    cplx work[SCRATCH];
    cplx cloud[MAX_CLOUD];
    cplx hull[MAX_CLOUD + 1];
    cplx acc[SCRATCH];
    int64_t slots[MAX_WINDOW];
};

// What one thread of the update works in for one movement (update.py Buffers): the FR
// regions (fr, fr_count, fr_status), the sampled hypotheses (h1, inv_d), the relaxed
// fusion's new-region counts, the FR robot point, a movement's bearings read back from
// a map's history (start, end), the local bound's sub-squares and the polygon scratch.
struct Buffers {
    cplx fr[MAX_LANDMARKS][FR_VERTICES];
    int64_t fr_count[MAX_LANDMARKS];
    int64_t fr_status[MAX_LANDMARKS];
    cplx h1[MAX_PAIRS];
    cplx inv_d[MAX_PAIRS];
    int64_t fresh_counts[MAX_LANDMARKS];
    cplx robot_point[1];
    double start[MAX_LANDMARKS];
    double end[MAX_LANDMARKS];
    SubSquares sub;  // the movement's sub-squares (TRANSFER_CONSERVATIVE only)
    Scratch scratch;
};

// This thread's buffers: allocated (and zeroed) on the thread's first use, then reused:
// one allocation per thread, none per call or movement. The update and the single-step
// kernels' bindings use them, never two at once on one thread.
Buffers& thread_buffers();

// Copy poly[:n] into a buffer of `capacity` points, raising CapacityError if it does not
// fit (numba's kernels, unchecked, would have written past the buffer).
inline void copy_polygon(const cplx* source, int64_t n, cplx* out, int64_t capacity,
                         const char* what) {
    check_capacity(what, n, capacity);
    for (int64_t v = 0; v < n; ++v) out[v] = source[v];
}

}  // namespace bearing::slam
