// The structures the map update takes, mirroring bearing_env/slam/kernels/state.py:
// MapState (a batch's per-map arrays, every one with the map axis first), Params (one
// update call's settings), Outputs (per-call statuses) and the constants they are sized by.
#pragma once

#include <cstdint>

#include <bearing_core/core/complex.hpp>
#include <bearing_core/core/views.hpp>

namespace bearing::slam {

// Capacities (bearing_env/slam/kernels/common.py; the Python constants are read from here).
inline constexpr int64_t CAPACITY = 128;        // most vertices a map region holds
inline constexpr int64_t MAX_EDGE_SAMPLES = 8;  // samples per edge, conservative transfer
inline constexpr int64_t FR_VERTICES = 4;       // a robot-frame region is at most a quadrangle
inline constexpr int64_t MAX_SAMPLES = FR_VERTICES * MAX_EDGE_SAMPLES;
inline constexpr int64_t MAX_PAIRS = MAX_SAMPLES * MAX_SAMPLES;
inline constexpr int64_t SCRATCH = 2 * CAPACITY + 8;
inline constexpr int64_t MAX_CLOUD = FR_VERTICES * MAX_PAIRS;
inline constexpr double MAX_FR_EXTENT = 1e4;
inline constexpr double RELATIVE_TOLERANCE = 1e-12;
inline constexpr int64_t MAX_WINDOW = 32;
// The smallest batch whose update is split over threads: below it, waking a worker gains
// nothing (2 cores, kept workers: 8 Khepera envs 5-10% slower on two threads; 16 envs and
// GreedyOneStep's 16 candidates level within the machine's noise; 64 envs 1.6x faster).
// Python reads it as kernels.PARALLEL_MIN_MAPS.
inline constexpr int64_t PARALLEL_MIN_MAPS = 32;
// The largest value a map's counters (n_updates, n_inconsistent, ...) may hold when a
// movement starts: beyond any run (2^62 movements), with room for one movement's
// increments, so that a corrupt state is refused (std::invalid_argument) instead of
// overflowing a signed counter.
inline constexpr int64_t MAX_COUNTER = int64_t{1} << 62;

enum FrStatus : int64_t { FR_BOUNDED = 0, FR_UNBOUNDED = 1, FR_EMPTY = 2, FR_MISSING = 3 };
enum FrameStatus : int8_t {
    FRAME_OK = 0,
    FRAME_L1_UNBOUNDED = 1,
    FRAME_L2_UNBOUNDED = 2,
    FRAME_L1_L2_OVERLAP = 3,
    FRAME_L1_L2_TOO_CLOSE = 4,
    FRAME_L1_MISSING = 5,
    FRAME_L2_MISSING = 6,
    FRAME_REJECTED = 7,
};
enum LandmarkStatus : int8_t {
    LANDMARK_UPDATED = 0,
    LANDMARK_UNBOUNDED = 1,
    LANDMARK_INCONSISTENT = 2,
    LANDMARK_SKIPPED = 3,
    LANDMARK_MISSING = 4,
};
// TRANSFER_CONSERVATIVE grows the sampled hull by the local bound (local_bound.hpp),
// TRANSFER_CONSERVATIVE_GLOBAL by the movement's one global radius (the bound of
// bearing_env 0.1, kept to reproduce its figures), TRANSFER_PAPER not at all.
enum Transfer : int64_t {
    TRANSFER_CONSERVATIVE = 0,
    TRANSFER_PAPER = 1,
    TRANSFER_CONSERVATIVE_GLOBAL = 2,
};

// Whether a transfer code is one of the above.
inline bool valid_transfer(int64_t transfer) {
    return transfer == TRANSFER_CONSERVATIVE || transfer == TRANSFER_PAPER ||
           transfer == TRANSFER_CONSERVATIVE_GLOBAL;
}
enum Inconsistency : int64_t { INCONSISTENCY_RESTART = 0, INCONSISTENCY_KEEP = 1 };
enum Fusion : int64_t { FUSION_INTERSECT = 0, FUSION_RELAXED = 1, FUSION_ROBUST = 2 };

// A batch's state: the fields of bearing_env.slam.kernels.State, in its order, as views
// of the batch's arrays (m: mapped landmarks, w: the relaxed window, levels: the robust
// fusion's levels, h: its history; 0-sized where the fusion does not use them). The one
// list of them: X(element type, dimensions, name) per field, in State's order; MapState,
// for_each_field and the bindings' field names are made from it.
#define BEARING_CORE_MAP_STATE(X)                                          \
    X(cplx, 3, vertices)                 /* (maps, m, CAPACITY) */         \
    X(int64_t, 2, counts)                /* (maps, m) */                   \
    X(double, 2, areas)                  /* (maps, m) */                   \
    X(cplx, 2, centroids)                /* (maps, m) */                   \
    X(cplx, 2, robot_vertices)           /* (maps, CAPACITY) */            \
    X(int64_t, 1, robot_counts)          /* (maps,) */                     \
    X(double, 1, robot_area)             /* (maps,) */                     \
    X(cplx, 1, robot_centroid)           /* (maps,) */                     \
    X(double, 1, robot_heading)          /* (maps,) */                     \
    X(int64_t, 1, n_updates)             /* (maps,) */                     \
    X(int64_t, 1, n_frame_changes)       /* (maps,) */                     \
    X(int64_t, 1, n_inconsistent)        /* (maps,) */                     \
    X(cplx, 4, window_vertices)          /* (maps, w, m, CAPACITY) */      \
    X(int64_t, 3, window_counts)         /* (maps, w, m) */                \
    X(bool, 3, window_inlier)            /* (maps, w, m) */                \
    X(bool, 2, window_rejected)          /* (maps, w) */                   \
    X(int64_t, 1, window_length)         /* (maps,) */                     \
    X(int64_t, 1, window_next)           /* (maps,) */                     \
    X(cplx, 3, base_vertices)            /* (maps, m, CAPACITY or 0) */    \
    X(int64_t, 2, base_counts)           /* (maps, m) */                   \
    X(int64_t, 2, n_dropped)             /* (maps, m) */                   \
    X(int64_t, 2, outliers)              /* (maps, m) */                   \
    X(cplx, 4, level_vertices)           /* (maps, m, levels, CAPACITY) */ \
    X(int64_t, 3, level_counts)          /* (maps, m, levels) */           \
    X(int64_t, 2, n_regions)             /* (maps, m) */                   \
    X(int64_t, 1, robot_fixed_at)        /* (maps,) */                     \
    X(double, 1, noise_scale)            /* (maps,) */                     \
    X(int64_t, 1, bound_events)          /* (maps,) */                     \
    X(cplx, 3, probe_vertices)           /* (maps, m, CAPACITY or 0) */    \
    X(int64_t, 2, probe_counts)          /* (maps, m) */                   \
    X(double, 4, history_frame_bearings) /* (maps, h, 2, 2) */             \
    X(double, 4, history_bearings)       /* (maps, h, 2, m) */             \
    X(int64_t, 1, history_length)        /* (maps,) */                     \
    X(int64_t, 1, history_next)          /* (maps,) */

struct MapState {
#define BEARING_CORE_DECLARE_FIELD(T, D, name) View<T, D> name;
    BEARING_CORE_MAP_STATE(BEARING_CORE_DECLARE_FIELD)
#undef BEARING_CORE_DECLARE_FIELD
};

// Call visit(name, view) for every field of `state`, in State's order.
template <class Visit>
void for_each_field(const MapState& state, Visit&& visit) {
#define BEARING_CORE_VISIT_FIELD(T, D, name) visit(#name, state.name);
    BEARING_CORE_MAP_STATE(BEARING_CORE_VISIT_FIELD)
#undef BEARING_CORE_VISIT_FIELD
}

// One update call's settings (bearing_env.slam.kernels.Params, same fields, same order).
struct Params {
    double epsilon = 0.0;          // bearing error bound, radians
    int64_t transfer = 0;          // Transfer
    int64_t edge_samples = 0;      // samples per edge of A_L1 and A_L2 (conservative)
    int64_t on_inconsistency = 0;  // Inconsistency
    int64_t fusion = 0;            // Fusion
    int64_t max_outliers = 0;      // relaxed fusion: most regions left out per landmark
    bool with_robot = false;       // also transfer the robot's position
    double risk = 0.0;             // robust fusion: the binomial tail the reported level leaves
    bool likely = false;           // robust fusion: report the likely set
    bool estimate_bound = false;   // robust fusion: estimate the noise bound
};

// Throws std::invalid_argument naming the first bad value of one update call's settings
// (MapSettings::params and the bindings' Params all pass through it; map_batch.cpp).
void validate(const Params& params);

// What one call did, per bearings row i (bearing_env.slam.kernels.Outputs).
struct Outputs {
    View1<int8_t> frame_status;     // (rows,)
    View2<int8_t> landmark_status;  // (rows, m)
    View1<int64_t> n_bad;           // (rows,)
};

// Map i of `to` becomes a copy of map rows[i] of `from` (rows may repeat), array by array:
// planners' copies of a map (state.cpp). The caller checks that the two states have the
// same shapes past the map axis and that rows fit both.
void copy_maps(const MapState& from, View1<const int64_t> rows, const MapState& to);

}  // namespace bearing::slam
