// The robust fusion (bearing_env/slam/kernels/robust.py, ported function for function):
// nested relaxed sets per landmark (levels), the contamination rate and the binomial
// level, the probe that tests the noise bound, the bearing history and the bound's growth.
#pragma once

#include <cstdint>

#include <bearing_core/core/pymath.hpp>
#include <bearing_core/slam/frames.hpp>
#include <bearing_core/slam/scratch.hpp>
#include <bearing_core/slam/state.hpp>

namespace bearing::slam {

// Levels X(0..6) per landmark: at most 6 regions are left out.
inline constexpr int64_t ROBUST_LEVELS = 7;
// The contamination prior: PRIOR_CONTRADICTIONS contradictions in PRIOR_REGIONS regions.
inline constexpr double PRIOR_CONTRADICTIONS = 0.001;
inline constexpr double PRIOR_REGIONS = 10.0;
// Contaminated regions per contradiction seen.
inline constexpr double UNSEEN_FACTOR = 2.0;
// The probe's bound, as a share of the bound in use.
inline constexpr double PROBE_SHRINK = 0.8;
// The factor a map's bound grows by on each piece of evidence that it is too small.
inline constexpr double BOUND_GROWTH = 1.1;
// The largest bound a map grows to, over the nominal epsilon.
inline constexpr double MAX_NOISE_SCALE = 4.0;
// The largest bound a map grows to, radians.
inline constexpr double MAX_BOUND = 0.25 * PI;
// Movements whose bearings each map keeps, to rebuild its regions at a new bound.
inline constexpr int64_t HISTORY = 16;

// The world model's constants by name, X(name) each (state.hpp's, scratch.hpp's and the
// above), for a consumer that exports or prints them (the Python module reads them so).
#define BEARING_CORE_SLAM_CONSTANTS(X) \
    X(CAPACITY)                        \
    X(MAX_EDGE_SAMPLES)                \
    X(FR_VERTICES)                     \
    X(MAX_SAMPLES)                     \
    X(MAX_PAIRS)                       \
    X(SCRATCH)                         \
    X(MAX_CLOUD)                       \
    X(MAX_FR_EXTENT)                   \
    X(RELATIVE_TOLERANCE)              \
    X(MAX_WINDOW)                      \
    X(PARALLEL_MIN_MAPS)               \
    X(MAX_LANDMARKS)                   \
    X(ROBUST_LEVELS)                   \
    X(HISTORY)                         \
    X(PROBE_SHRINK)                    \
    X(BOUND_GROWTH)                    \
    X(MAX_NOISE_SCALE)                 \
    X(MAX_BOUND)                       \
    X(PRIOR_CONTRADICTIONS)            \
    X(PRIOR_REGIONS)                   \
    X(UNSEEN_FACTOR)

// The smallest q (at most q_cap) with P(Bin(n, p) > q) < risk.
int64_t binomial_q(int64_t n, double p, double risk, int64_t q_cap);
// Map row's estimated share of contaminated regions.
double contamination(const MapState& state, int64_t row);
// Fuse scratch.fresh[:n_new] into landmark j's levels.
void update_levels(const MapState& state, int64_t row, int64_t j, int64_t n_new, Scratch& scratch);
// Fuse scratch.fresh[:n_new] into landmark j (rate: the map's contamination before this
// movement); false when it contradicts the landmark's regions.
bool robust_landmark(const MapState& state, int64_t row, int64_t j, int64_t n_new, double rate,
                     const Params& params, Scratch& scratch);
// Whether the movement's start, seen through its change of frames, misses the map's
// robot region (set by the previous movement).
bool frame_contradicts_robot(const MapState& state, int64_t row, const FrameChange& frame,
                             Scratch& scratch);
// Intersect the probe's new region scratch.fresh[:n_new] into its region of landmark j;
// false when they miss each other (the old one is kept).
bool probe_landmark(const MapState& state, int64_t row, int64_t j, int64_t n_new, Scratch& scratch);
// How many times map row's bound has grown.
int64_t bound_growths(const MapState& state, int64_t row);
// Grow map row's bound by BOUND_GROWTH when its probe's evidence warrants; returns
// whether it grew.
bool grow_bound(const MapState& state, int64_t row, double epsilon);
// Keep one movement's bearings (start, end: every landmark, L1 and L2 first) in map
// row's history.
void push_history(const MapState& state, int64_t row, const double* start, const double* end);
// The bearings of map row's k-th oldest kept movement, into start and end.
void history_movement(const MapState& state, int64_t row, int64_t k, double* start, double* end);
// Clear map row's regions, levels, probe and robot region.
void forget_regions(const MapState& state, int64_t row);

}  // namespace bearing::slam
