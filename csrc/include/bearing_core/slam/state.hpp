// The structures the map update takes: MapState (a batch's per-map arrays, every one with the map
// axis first), Params (one update call's settings), Outputs (per-call statuses) and the constants
// they are sized by.
#pragma once

#include <cstdint>
#include <vector>

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

// The codes of the library, each enum declared once as E(name, value) per member (the
// bindings export them to Python as IntEnums, their members also at module level).
#define BEARING_CORE_ENUM_MEMBER(name, value) name = value,
#define BEARING_CORE_FR_STATUS(E) \
    E(FR_BOUNDED, 0)              \
    E(FR_UNBOUNDED, 1)            \
    E(FR_EMPTY, 2)                \
    E(FR_MISSING, 3)
#define BEARING_CORE_FRAME_STATUS(E) \
    E(FRAME_OK, 0)                   \
    E(FRAME_L1_UNBOUNDED, 1)         \
    E(FRAME_L2_UNBOUNDED, 2)         \
    E(FRAME_L1_L2_OVERLAP, 3)        \
    E(FRAME_L1_L2_TOO_CLOSE, 4)      \
    E(FRAME_L1_MISSING, 5)           \
    E(FRAME_L2_MISSING, 6)           \
    E(FRAME_REJECTED, 7)
#define BEARING_CORE_LANDMARK_STATUS(E) \
    E(LANDMARK_UPDATED, 0)              \
    E(LANDMARK_UNBOUNDED, 1)            \
    E(LANDMARK_INCONSISTENT, 2)         \
    E(LANDMARK_SKIPPED, 3)              \
    E(LANDMARK_MISSING, 4)
// TRANSFER_CONSERVATIVE grows the sampled hull by the local bound (local_bound.hpp),
// TRANSFER_CONSERVATIVE_GLOBAL by the movement's one global radius (the bound of
// bearing_env 0.1, kept to reproduce its figures), TRANSFER_PAPER not at all.
#define BEARING_CORE_TRANSFER(E) \
    E(TRANSFER_CONSERVATIVE, 0)  \
    E(TRANSFER_PAPER, 1)         \
    E(TRANSFER_CONSERVATIVE_GLOBAL, 2)
#define BEARING_CORE_INCONSISTENCY(E) \
    E(INCONSISTENCY_RESTART, 0)       \
    E(INCONSISTENCY_KEEP, 1)
#define BEARING_CORE_FUSION(E) \
    E(FUSION_INTERSECT, 0)     \
    E(FUSION_RELAXED, 1)       \
    E(FUSION_ROBUST, 2)

enum FrStatus : int64_t { BEARING_CORE_FR_STATUS(BEARING_CORE_ENUM_MEMBER) };
enum FrameStatus : int8_t { BEARING_CORE_FRAME_STATUS(BEARING_CORE_ENUM_MEMBER) };
enum LandmarkStatus : int8_t { BEARING_CORE_LANDMARK_STATUS(BEARING_CORE_ENUM_MEMBER) };
enum Transfer : int64_t { BEARING_CORE_TRANSFER(BEARING_CORE_ENUM_MEMBER) };
enum Inconsistency : int64_t { BEARING_CORE_INCONSISTENCY(BEARING_CORE_ENUM_MEMBER) };
enum Fusion : int64_t { BEARING_CORE_FUSION(BEARING_CORE_ENUM_MEMBER) };

// Whether a transfer code is one of the above.
inline bool valid_transfer(int64_t transfer) {
    return transfer == TRANSFER_CONSERVATIVE || transfer == TRANSFER_PAPER ||
           transfer == TRANSFER_CONSERVATIVE_GLOBAL;
}
// A batch's state: the fields of bearing_env._core.State, as views of the batch's
// arrays, the map axis first. Declared once, in three groups: the arrays every fusion
// uses (MAP_ARRAYS), the relaxed fusion's window and bases (RELAXED_ARRAYS) and the
// robust fusion's levels and noise-bound estimate (ROBUST_ARRAYS); the robust fusion also
// uses OUTLIERS. X(element type, dimensions, name, shape rule, doc) per field
// (core/schema.hpp): m is the mapped landmarks (L1 and L2 excluded), w the relaxed
// window, levels the robust levels and h the bearing history (0 where the fusion does not
// use them); base_capacity and probe_capacity are CAPACITY or 0.
#define BEARING_CORE_MAP_ARRAYS(X)                                                   \
    X(cplx, 3, vertices, "maps m CAPACITY", "the landmarks' regions")                \
    X(int64_t, 2, counts, "maps m", "their vertex counts (0: not initialised)")      \
    X(double, 2, areas, "maps m", "their areas")                                     \
    X(cplx, 2, centroids, "maps m", "their centroids")                               \
    X(cplx, 2, robot_vertices, "maps CAPACITY", "the robot's region")                \
    X(int64_t, 1, robot_counts, "maps", "its vertex count")                          \
    X(double, 1, robot_area, "maps", "its area")                                     \
    X(cplx, 1, robot_centroid, "maps", "its centroid")                               \
    X(double, 1, robot_heading, "maps", "the robot's heading in the landmark frame") \
    X(int64_t, 1, n_updates, "maps", "movements fused")                              \
    X(int64_t, 1, n_frame_changes, "maps", "of which changed frames")                \
    X(int64_t, 1, n_inconsistent, "maps", "inconsistent landmark regions so far")
#define BEARING_CORE_RELAXED_ARRAYS(X)                                                   \
    X(cplx, 4, window_vertices, "maps w m CAPACITY", "the window's regions")             \
    X(int64_t, 3, window_counts, "maps w m", "their vertex counts")                      \
    X(bool, 3, window_inlier, "maps w m", "kept by the landmark's region")               \
    X(bool, 2, window_rejected, "maps w", "the movement is left out for every landmark") \
    X(int64_t, 1, window_length, "maps", "movements in the window")                      \
    X(int64_t, 1, window_next, "maps", "the slot the next movement goes to")             \
    X(cplx, 3, base_vertices, "maps m base_capacity", "inliers older than the window")   \
    X(int64_t, 2, base_counts, "maps m", "their vertex counts")                          \
    X(int64_t, 2, n_dropped, "maps m", "regions left out for good")                      \
    BEARING_CORE_OUTLIERS(X)
#define BEARING_CORE_OUTLIERS(X) \
    X(int64_t, 2, outliers, "maps m", "regions left out, window included")
#define BEARING_CORE_ROBUST_ARRAYS(X)                                                           \
    X(cplx, 4, level_vertices, "maps m levels CAPACITY", "the robust fusion's levels")          \
    X(int64_t, 3, level_counts, "maps m levels", "their vertex counts")                         \
    X(int64_t, 2, n_regions, "maps m", "regions fused into the robust levels")                  \
    X(int64_t, 1, robot_fixed_at, "maps", "the movement (n_updates) that set the robot region") \
    X(double, 1, noise_scale, "maps", "the bound fused with, over the nominal epsilon")         \
    X(int64_t, 1, bound_events, "maps", "times the probe found the bound too small")            \
    X(cplx, 3, probe_vertices, "maps m probe_capacity", "the probe's regions")                  \
    X(int64_t, 2, probe_counts, "maps m", "their vertex counts")                                \
    X(double, 4, history_frame_bearings, "maps h 2 2", "L1's and L2's bearings, at R1 then R2") \
    X(double, 4, history_bearings, "maps h 2 m", "the mapped landmarks', at R1 then R2")        \
    X(int64_t, 1, history_length, "maps", "movements in the history")                           \
    X(int64_t, 1, history_next, "maps", "the slot the next movement goes to")
#define BEARING_CORE_MAP_STATE(X) \
    BEARING_CORE_MAP_ARRAYS(X) BEARING_CORE_RELAXED_ARRAYS(X) BEARING_CORE_ROBUST_ARRAYS(X)

// A struct's member for each field of an X-macro, and its visitor.
#define BEARING_CORE_DECLARE_FIELD(T, D, name, rule, doc) View<T, D> name;
#define BEARING_CORE_VISIT_FIELD(T, D, name, rule, doc) visit(#name, rule, s.name);
#define BEARING_CORE_FIELD_DOC(T, D, name, rule, doc) doc,
// for_each_field(s, visit) calls visit(name, shape rule, view) for every field of s (the
// struct's X-macro FIELDS), in order; field_docs(s) are the fields' docs, in order.
#define BEARING_CORE_VISITOR(Struct, FIELDS)                    \
    template <class Visit>                                      \
    void for_each_field(const Struct& s, Visit&& visit) {       \
        FIELDS(BEARING_CORE_VISIT_FIELD)                        \
    }                                                           \
    template <class Visit>                                      \
    void for_each_field(Struct& s, Visit&& visit) {             \
        FIELDS(BEARING_CORE_VISIT_FIELD)                        \
    }                                                           \
    inline std::vector<const char*> field_docs(const Struct&) { \
        return {FIELDS(BEARING_CORE_FIELD_DOC)};                \
    }

struct MapState {
    BEARING_CORE_MAP_STATE(BEARING_CORE_DECLARE_FIELD)
};
BEARING_CORE_VISITOR(MapState, BEARING_CORE_MAP_STATE)

// The map update's settings that a map's settings (MapSettings) and one update call's
// (Params) share: S(type, name, default, doc) per setting, declared once.
#define BEARING_CORE_UPDATE_SETTINGS(S)                                                         \
    S(double, epsilon, 0.0, "bearing error bound, radians")                                     \
    S(::bearing::slam::Transfer, transfer, ::bearing::slam::TRANSFER_CONSERVATIVE,              \
      "how a region is moved between frames")                                                   \
    S(int64_t, edge_samples, 3, "samples per edge of A_L1 and A_L2 (conservative transfer)")    \
    S(::bearing::slam::Inconsistency, on_inconsistency, ::bearing::slam::INCONSISTENCY_RESTART, \
      "what an empty intersection does")                                                        \
    S(::bearing::slam::Fusion, fusion, ::bearing::slam::FUSION_INTERSECT,                       \
      "how a landmark's regions are fused")                                                     \
    S(int64_t, max_outliers, 2, "relaxed fusion: most regions left out per landmark")           \
    S(double, risk, 0.05, "robust fusion: the binomial tail the reported level leaves")         \
    S(bool, likely, false, "robust fusion: report the likely set")                              \
    S(bool, estimate_bound, true, "robust fusion: estimate the noise bound")
// One update call's settings: the shared ones and whether the robot is transferred.
#define BEARING_CORE_PARAMS(S) \
    BEARING_CORE_UPDATE_SETTINGS(S) S(bool, with_robot, false, "also transfer the robot's position")
#define BEARING_CORE_DECLARE_SETTING(T, name, value, doc) T name = value;

struct Params {
    BEARING_CORE_PARAMS(BEARING_CORE_DECLARE_SETTING)
};

// Throws std::invalid_argument naming the first bad value of one update call's settings
// (MapSettings::params and the bindings' Params all pass through it; map_batch.cpp).
void validate(const Params& params);

// What one call did, per bearings row i (bearing_env._core.Outputs).
#define BEARING_CORE_OUTPUTS(X)                                                     \
    X(int8_t, 1, frame_status, "rows", "a FrameStatus per row")                     \
    X(int8_t, 2, landmark_status, "rows m", "a LandmarkStatus per mapped landmark") \
    X(int64_t, 1, n_bad, "rows", "landmarks found inconsistent by this movement")
struct Outputs {
    BEARING_CORE_OUTPUTS(BEARING_CORE_DECLARE_FIELD)
};
BEARING_CORE_VISITOR(Outputs, BEARING_CORE_OUTPUTS)

// Map i of `to` becomes a copy of map rows[i] of `from` (rows may repeat), array by array:
// planners' copies of a map (state.cpp). The caller checks that the two states have the
// same shapes past the map axis and that rows fit both.
void copy_maps(const MapState& from, View1<const int64_t> rows, const MapState& to);

}  // namespace bearing::slam
