// Fusing one movement's region of a landmark into a map (bearing_env/slam/kernels/
// fusion.py, ported function for function, private helpers included): the strict
// intersection (intersect_landmark) and the relaxed fusion's window and bases
// (relaxed_movement). Both work on map `row` of a MapState in place, in the buffers of a
// Scratch: the movement's new region arrives in scratch.fresh.
#pragma once

#include <cstdint>
#include <utility>

#include <bearing_core/slam/scratch.hpp>
#include <bearing_core/slam/state.hpp>

namespace bearing::slam {

// Intersect scratch.fresh[:n_new] into landmark j's region of map row; false when they
// miss each other (the region is then kept if `keep`, else restarted from the new one).
bool intersect_landmark(const MapState& state, int64_t row, int64_t j, int64_t n_new, bool keep,
                        Scratch& scratch);

// The convex hull of acc[:n_acc] and poly[:n_poly] into acc (which holds acc_capacity
// points), reduced to CAPACITY vertices; returns its count.
int64_t merge_hull(cplx* acc, int64_t n_acc, int64_t acc_capacity, const cplx* poly, int64_t n_poly,
                   cplx* cloud, cplx* hull);

// The window slots (oldest first) holding a region of landmark j from a movement not
// rejected, into out (MAX_WINDOW); returns how many.
int64_t window_slots(const MapState& state, int64_t row, int64_t j, int64_t* out);

// (n, in_first): the intersection of the base (if used) and the kept regions of
// scratch.slots[:k] (those not `discarded`), in scratch.fused if in_first else fresh.
std::pair<int64_t, bool> intersect_kept(const MapState& state, int64_t row, int64_t j, int64_t k,
                                        const bool* discarded, bool use_base, Scratch& scratch);

// The hull of the union over every choice of q left-out slots into scratch.acc.
int64_t relaxed_union(const MapState& state, int64_t row, int64_t j, int64_t k, bool use_base,
                      int64_t q, Scratch& scratch);

// (n, q): the q-relaxed region for the smallest q <= max_outliers, into scratch.acc.
std::pair<int64_t, int64_t> relaxed_region(const MapState& state, int64_t row, int64_t j, int64_t k,
                                           bool use_base, int64_t max_outliers, Scratch& scratch);

// Landmark j's region from its base and window, from scratch.
void solve_landmark(const MapState& state, int64_t row, int64_t j, const Params& params,
                    Scratch& scratch);

// Fold the oldest movement of a full window into the bases.
void age_out_oldest(const MapState& state, int64_t row, Scratch& scratch);

// Whether landmark j's region leaves out none of its window regions.
bool keeps_every_region(const MapState& state, int64_t row, int64_t j);

// Reject the window movements that are outliers for most of their landmarks (repeated).
void reject_outlier_movements(const MapState& state, int64_t row, const Params& params,
                              Scratch& scratch);

// Fuse the movement just written into window slot window_next[row] - 1 (its regions'
// counts are fresh_counts[:m]) with the relaxed intersection, marking inconsistent
// landmarks in out.landmark_status row i; returns whether the movement was rejected.
bool relaxed_movement(const MapState& state, int64_t row, const int64_t* fresh_counts,
                      const Params& params, const Outputs& out, int64_t i, Scratch& scratch);

}  // namespace bearing::slam
