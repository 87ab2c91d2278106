// What the env kernels take (bearing_env/envs/kernels.py): a group's Settings, the envs'
// BatchState (bearing_env/envs/state.py, its KERNEL_ARRAYS), the Inputs they make with
// the group's map update settings and map state, the Report a step writes and the robot
// map's encoded arrays (bearing_env/envs/robot_map.py, encode_map's).
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
enum StepStatus : int64_t { STEP_DONE = 0, STEP_NEEDS_NOISE = 1, STEP_NEEDS_TRAJECTORY = 2 };
// Outcomes of decode_continuous (kernels.ACTIONS_*).
enum ActionsStatus : int64_t { ACTIONS_OK = 0, ACTIONS_NOT_FINITE = 1, ACTIONS_OUTSIDE = 2 };

// A group's settings (kernels.Settings, same fields, same order).
struct Settings {
    int64_t n = 0;                // landmarks of the group's rows
    int64_t n_slots = 0;          // the observation's landmark slots (max_landmarks)
    bool shape_features = false;  // the flat vector ends with the regions' shapes
    double width = 0.0;           // the arena, metres
    double height = 0.0;
    double margin = 0.0;        // the wall margin
    double min_baseline = 0.0;  // shortest move that changes frames
    bool log_area = false;      // the reward's potential sums log-areas (else areas)
    double floor = 0.0;         // areas are floored here before taking logs
    double cap = 0.0;           // and capped here (area_cap)
    double target_area = 0.0;   // success: every landmark's area at most this
    int64_t max_moves = 0;
    double path_cost = 0.0;         // per metre
    double move_cost = 0.0;         // per move
    double coordinate_limit = 0.0;  // FL coordinates are clipped to +-this
    double tolerance = 0.0;         // relative tolerance of the info's containment test
    double half_fov = 0.0;          // half the sensor's field of view, radians
    double max_range = 0.0;         // the sensor's range, metres
    sim::Obstacles obstacles;       // obstacle_vertices, obstacle_starts
};

// The envs' state (state.BatchState's KERNEL_ARRAYS, in their order), one row per env.
struct BatchState {
    View1<int64_t> n_landmarks;        // (N,)
    View3<double> landmarks;           // (N, slots, 2)
    View2<double> positions;           // (N, 2)
    View1<double> headings;            // (N,)
    View1<cplx> frame_origin;          // (N,)
    View1<cplx> frame_unit;            // (N,)
    View2<cplx> landmarks_fl;          // (N, slots - 2)
    View1<int64_t> moves;              // (N,)
    View1<double> potentials;          // (N,)
    View2<double> latest_bearings;     // (N, slots)
    View2<double> start_bearings;      // (N, slots)
    View2<double> start_positions;     // (N, 2)
    View1<bool> frame_changed;         // (N,)
    View1<bool> blocked;               // (N,)
    View1<bool> done;                  // (N,)
    View1<int64_t> trajectory_length;  // (N,)
    View2<double> noise_offsets;       // (N, values)
    View2<bool> noise_is_outlier;      // (N, values)
    View2<double> noise_replacement;   // (N, values)
    View1<int64_t> noise_used;         // (N,)
    View1<int64_t> noise_filled;       // (N,)
};

// What a group's kernels read and write besides their per-call arrays (kernels.Inputs).
struct Inputs {
    Settings settings;
    slam::Params params;  // the group's map update settings (the robot transferred)
    slam::MapState maps;  // the group's map batch
    BatchState state;     // the envs' state
};

// What a step (or a reset) of a group gives, per row (kernels.Report, same order).
struct Report {
    View2<float> observations;            // (rows, observation size)
    View1<double> rewards;                // (rows,)
    View1<bool> terminated;               // (rows,)
    View1<bool> truncated;                // (rows,)
    View1<bool> frame_changed;            // (rows,)
    View1<int64_t> inconsistent;          // (rows,)
    View1<double> path_length;            // (rows,)
    View1<double> uncertainty;            // (rows,)
    View1<double> path_cost;              // (rows,)
    View1<double> move_cost;              // (rows,)
    View2<double> landmark_area;          // (rows, n - 2)
    View2<double> landmark_error;         // (rows, n - 2)
    View2<bool> landmark_contains_truth;  // (rows, n - 2)
    View1<double> total_area;             // (rows,)
    View1<double> robot_error;            // (rows,)
    View2<int64_t> outliers;              // (rows, n - 2)

    // The first `size` rows (C-contiguous: a prefix of every array).
    Report first(int64_t size) const;
};

// The robot map's arrays as robot_map.encode_map gives them (MAP_ARRAYS, same order).
struct Encoded {
    View3<cplx> vertices;            // (rows, slots, capacity)
    View2<int64_t> counts;           // (rows, slots)
    View2<double> areas;             // (rows, slots)
    View2<cplx> centroids;           // (rows, slots)
    View2<cplx> robot_vertices;      // (rows, capacity)
    View1<int64_t> robot_counts;     // (rows,)
    View1<double> robot_area;        // (rows,)
    View1<cplx> robot_centroid;      // (rows,)
    View1<double> robot_heading;     // (rows,)
    View1<int64_t> n_updates;        // (rows,)
    View1<int64_t> n_frame_changes;  // (rows,)
    View1<int64_t> n_inconsistent;   // (rows,)

    Encoded first(int64_t size) const;
};

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
