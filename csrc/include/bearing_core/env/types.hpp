// What the env kernels take: a group's Settings, the envs' BatchState, the Inputs they
// make with the group's map update settings and map state, the Report a step writes and
// the robot map's encoded arrays (bearing_env/envs/robot_map.py, encode_map's). Each
// struct's fields are declared once, as an X-macro (core/schema.hpp).
#pragma once

#include <cstdint>

#include <bearing_core/core/complex.hpp>
#include <bearing_core/core/views.hpp>
#include <bearing_core/sim/sensing.hpp>
#include <bearing_core/slam/state.hpp>

namespace bearing::env {

// The flat observation's block sizes (bearing_env/envs/observations.py: the lengths of
// ROBOT_FEATURES, LANDMARK_FEATURES, BEARING_FEATURES, SHAPE_FEATURES) and the shape
// block's elongation limit (ELONGATION_LIMIT).
inline constexpr int64_t ROBOT_FEATURES = 9;
inline constexpr int64_t LANDMARK_FEATURES = 5;
inline constexpr int64_t BEARING_FEATURES = 3;
inline constexpr int64_t SHAPE_FEATURES = 3;
inline constexpr double ELONGATION_LIMIT = 10.0;

// Outcomes of step_rows (kernels.STEP_*).
#define BEARING_CORE_STEP_STATUS(E) \
    E(STEP_DONE, 0) E(STEP_NEEDS_NOISE, 1) E(STEP_NEEDS_TRAJECTORY, 2)
enum StepStatus : int64_t { BEARING_CORE_STEP_STATUS(BEARING_CORE_ENUM_MEMBER) };
// Outcomes of decode_continuous (kernels.ACTIONS_*).
#define BEARING_CORE_ACTIONS_STATUS(E) \
    E(ACTIONS_OK, 0) E(ACTIONS_NOT_FINITE, 1) E(ACTIONS_OUTSIDE, 2)
enum ActionsStatus : int64_t { BEARING_CORE_ACTIONS_STATUS(BEARING_CORE_ENUM_MEMBER) };

// A group's settings (bearing_env._core.Settings): S(type, name, default, doc) per
// number, then the obstacles' two arrays (X, as a struct of arrays' fields), declared once.
#define BEARING_CORE_SETTINGS(S)                                                         \
    S(int64_t, n, 0, "landmarks of the group's rows")                                    \
    S(int64_t, n_slots, 0, "the observation's landmark slots (max_landmarks)")           \
    S(bool, shape_features, false, "the flat vector ends with the regions' shapes")      \
    S(int64_t, appended, 0, "columns after the blocks, left 0 (the planner features)")   \
    S(double, width, 0.0, "the arena's width, metres")                                   \
    S(double, height, 0.0, "the arena's height, metres")                                 \
    S(double, margin, 0.0, "the wall margin, metres")                                    \
    S(double, min_baseline, 0.0, "shortest move that changes frames, metres")            \
    S(bool, log_area, false, "the reward's potential sums log-areas (else areas)")       \
    S(double, floor, 0.0, "areas are floored here before taking logs")                   \
    S(double, cap, 0.0, "and capped here (area_cap)")                                    \
    S(double, target_area, 0.0, "success: every landmark's area at most this")           \
    S(int64_t, max_moves, 0, "moves before the episode is truncated")                    \
    S(double, path_cost, 0.0, "reward cost per metre")                                   \
    S(double, move_cost, 0.0, "reward cost per move")                                    \
    S(double, coordinate_limit, 0.0, "FL coordinates are clipped to +-this")             \
    S(double, tolerance, 0.0, "relative tolerance of the info's containment test")       \
    S(double, half_fov, 0.0, "half the sensor's field of view, radians (pi: panoramic)") \
    S(double, max_range, 0.0, "the sensor's range, metres (inf: no limit)")
#define BEARING_CORE_SETTINGS_ARRAYS(X)                                              \
    X(double, 2, obstacle_vertices, "vertices 2", "the obstacles' vertices, packed") \
    X(int64_t, 1, obstacle_starts, "polygons", "where each obstacle starts, and the end")

struct Settings {
    BEARING_CORE_SETTINGS(BEARING_CORE_DECLARE_SETTING)
    BEARING_CORE_SETTINGS_ARRAYS(BEARING_CORE_DECLARE_FIELD)

    sim::Obstacles obstacles() const {
        return {{obstacle_vertices.data, obstacle_vertices.shape},
                {obstacle_starts.data, obstacle_starts.shape}};
    }
};
BEARING_CORE_VISITOR(Settings, BEARING_CORE_SETTINGS_ARRAYS)

// The envs' state (bearing_env.envs.state.BatchState's arrays that the step takes), one
// row per env (N); slots is the most landmarks a row has, values a row's noise buffer.
#define BEARING_CORE_BATCH_STATE(X)                                                            \
    X(int64_t, 1, n_landmarks, "N", "landmarks in each row's current episode")                 \
    X(double, 3, landmarks, "N slots 2", "true landmark positions, metres; L1 first")          \
    X(double, 2, positions, "N 2", "true robot positions, metres")                             \
    X(double, 1, headings, "N", "true robot headings, radians CCW from +x")                    \
    X(cplx, 1, frame_origin, "N", "each row's FL frame: FL = (world - origin) / unit")         \
    X(cplx, 1, frame_unit, "N", "(fixed per episode)")                                         \
    X(cplx, 2, landmarks_fl, "N slots-2", "true FL positions of landmarks L3.., for the info") \
    X(int64_t, 1, moves, "N", "moves made this episode")                                       \
    X(double, 1, potentials, "N", "the potential after the latest move")                       \
    X(double, 2, latest_bearings, "N slots", "the latest reading, relative to the heading")    \
    X(double, 2, start_bearings, "N slots", "the last movement's first reading (NaN before)")  \
    X(double, 2, start_positions, "N 2", "and its start position (NaN before)")                \
    X(bool, 1, frame_changed, "N", "the last movement changed frames (updated the map)")       \
    X(bool, 1, blocked, "N", "the wall stopped the last movement")                             \
    X(bool, 1, done, "N", "the episode has ended and needs a reset")                           \
    X(int64_t, 1, trajectory_length, "N", "trajectory positions recorded since the reset")     \
    X(double, 2, noise_offsets, "N values", "movement noise drawn ahead: each value's offset") \
    X(bool, 2, noise_is_outlier, "N values", "whether it is an outlier (or a miss)")           \
    X(double, 2, noise_replacement, "N values", "and its replacement bearing")                 \
    X(int64_t, 1, noise_used, "N", "noise values spent")                                       \
    X(int64_t, 1, noise_filled, "N", "of the ones drawn")

struct BatchState {
    BEARING_CORE_BATCH_STATE(BEARING_CORE_DECLARE_FIELD)
};
BEARING_CORE_VISITOR(BatchState, BEARING_CORE_BATCH_STATE)

// What a group's kernels read and write besides their per-call arrays (kernels.Inputs).
struct Inputs {
    Settings settings;
    slam::Params params;  // the group's map update settings (the robot transferred)
    slam::MapState maps;  // the group's map batch
    BatchState state;     // the envs' state
};

// What a step (or a reset) of a group gives, per row (bearing_env._core.Report): the
// observations, the rewards and episode ends, and the infos' arrays (the reward parts sum
// to the reward); m is the group's mapped landmarks, obs the observation's size.
#define BEARING_CORE_REPORT(X)                                                           \
    X(float, 2, observations, "rows obs", "the flat observations")                       \
    X(double, 1, rewards, "rows", "the rewards")                                         \
    X(bool, 1, terminated, "rows", "the episode ended (every area at most target_area)") \
    X(bool, 1, truncated, "rows", "the episode reached max_moves")                       \
    X(bool, 1, frame_changed, "rows", "the movement changed frames")                     \
    X(int64_t, 1, inconsistent, "rows", "landmarks found inconsistent by the movement")  \
    X(double, 1, path_length, "rows", "the movement's length, metres")                   \
    X(double, 1, uncertainty, "rows", "the reward's uncertainty part")                   \
    X(double, 1, path_cost, "rows", "the reward's path cost")                            \
    X(double, 1, move_cost, "rows", "the reward's move cost")                            \
    X(double, 2, landmark_area, "rows m", "each mapped landmark's area")                 \
    X(double, 2, landmark_error, "rows m", "its estimate's distance to the truth")       \
    X(bool, 2, landmark_contains_truth, "rows m", "its region contains the truth")       \
    X(double, 1, total_area, "rows", "the landmarks' total area")                        \
    X(double, 1, robot_error, "rows", "the robot estimate's distance to the truth")      \
    X(int64_t, 2, outliers, "rows m", "regions left out per landmark")

struct Report {
    BEARING_CORE_REPORT(BEARING_CORE_DECLARE_FIELD)

    // The first `size` rows (C-contiguous: a prefix of every array).
    Report first(int64_t size) const;
};
BEARING_CORE_VISITOR(Report, BEARING_CORE_REPORT)

// The robot map's arrays as robot_map.encode_map gives them: the state's MAP_ARRAYS, for
// some rows (maps: rows), their landmark slots padded (m: slots).
struct Encoded {
    BEARING_CORE_MAP_ARRAYS(BEARING_CORE_DECLARE_FIELD)

    Encoded first(int64_t size) const;
};
BEARING_CORE_VISITOR(Encoded, BEARING_CORE_MAP_ARRAYS)

// encode_window's arrays (the state's RELAXED_ARRAYS) and encode_levels' (OUTLIERS and
// ROBUST_ARRAYS), for some rows, their landmark slots padded.
struct Window {
    BEARING_CORE_RELAXED_ARRAYS(BEARING_CORE_DECLARE_FIELD)
};
BEARING_CORE_VISITOR(Window, BEARING_CORE_RELAXED_ARRAYS)
#define BEARING_CORE_LEVELS(X) BEARING_CORE_OUTLIERS(X) BEARING_CORE_ROBUST_ARRAYS(X)
struct Levels {
    BEARING_CORE_LEVELS(BEARING_CORE_DECLARE_FIELD)
};
BEARING_CORE_VISITOR(Levels, BEARING_CORE_LEVELS)

// The first `size` rows of every array of a struct of arrays (C-contiguous: a prefix).
template <class Struct>
Struct first_rows(const Struct& arrays, int64_t size) {
    Struct out = arrays;
    for_each_field(out, [size](const char*, const char*, auto& view) { view.shape[0] = size; });
    return out;
}

// The step's per-call buffers, made once per group (numba made them on every call): the
// readings of each row (start, end: (capacity, n)), the moving rows' indices and map rows,
// and the map update's outputs. Every use is guarded by check_capacity.
struct StepBuffers {
    View2<double> start;
    View2<double> end;
    View1<int64_t> moving;
    View1<int64_t> moving_rows;
    slam::Outputs out;  // frame_status (capacity,), landmark_status (capacity, n - 2), n_bad
};

}  // namespace bearing::env
