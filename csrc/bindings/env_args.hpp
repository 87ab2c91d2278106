// Checked arguments of the env kernels (bind_env.cpp): a group's Settings, the map update's
// Params and MapState, the envs' BatchState, read from their Python objects once.
#pragma once

#include <nanobind/nanobind.h>

#include <array>
#include <cmath>
#include <string>
#include <type_traits>
#include <vector>

#include <bearing_core/env/types.hpp>
#include <bearing_core/slam/scratch.hpp>
#include <bearing_core/slam/state.hpp>
#include "bindings/arrays.hpp"
#include "bindings/sim_args.hpp"

namespace bearing::bindings {

// The Python objects a native object's views point into, kept alive with it.
using Kept = std::vector<nb::object>;

// The view of attribute `name` of obj, its array kept.
template <class T, int D>
void field_of(nb::handle obj, const char* name, View<T, D>& out, Kept& kept,
              const std::array<int64_t, D>& expect = {}) {
    if (!nb::hasattr(obj, name)) {
        type_error(std::string("expected an object with the array attribute '") + name + "', got " +
                   nb::type_name(obj.type()).c_str());
    }
    nb::object value = obj.attr(name);
    out = view_of<T, D>(value, name, expect);
    kept.push_back(std::move(value));
}

template <class T>
T scalar_of(nb::handle obj, const char* name) {
    if (!nb::hasattr(obj, name)) {
        type_error(std::string("expected an object with the attribute '") + name + "', got " +
                   nb::type_name(obj.type()).c_str());
    }
    T value;
    if (!nb::try_cast(obj.attr(name), value)) {
        type_error(std::string(name) + " has the wrong type (" +
                   nb::type_name(obj.attr(name).type()).c_str() + ")");
    }
    return value;
}

// A group's settings from a kernels.Settings (any object with its fields).
inline env::Settings settings_of(nb::handle obj, Kept& kept) {
    env::Settings s;
    s.n = scalar_of<int64_t>(obj, "n");
    s.n_slots = scalar_of<int64_t>(obj, "n_slots");
    s.shape_features = scalar_of<bool>(obj, "shape_features");
    s.width = scalar_of<double>(obj, "width");
    s.height = scalar_of<double>(obj, "height");
    s.margin = scalar_of<double>(obj, "margin");
    s.min_baseline = scalar_of<double>(obj, "min_baseline");
    s.log_area = scalar_of<bool>(obj, "log_area");
    s.floor = scalar_of<double>(obj, "floor");
    s.cap = scalar_of<double>(obj, "cap");
    s.target_area = scalar_of<double>(obj, "target_area");
    s.max_moves = scalar_of<int64_t>(obj, "max_moves");
    s.path_cost = scalar_of<double>(obj, "path_cost");
    s.move_cost = scalar_of<double>(obj, "move_cost");
    s.coordinate_limit = scalar_of<double>(obj, "coordinate_limit");
    s.tolerance = scalar_of<double>(obj, "tolerance");
    s.half_fov = scalar_of<double>(obj, "half_fov");
    s.max_range = scalar_of<double>(obj, "max_range");
    nb::object vertices = obj.attr("obstacle_vertices"), starts = obj.attr("obstacle_starts");
    s.obstacles = obstacles_of(vertices, starts, "obstacle_vertices", "obstacle_starts");
    kept.push_back(std::move(vertices));
    kept.push_back(std::move(starts));
    if (s.n < 2) value_error("settings.n must be at least 2, got " + std::to_string(s.n));
    if (s.n_slots < s.n) {
        value_error("settings.n_slots (" + std::to_string(s.n_slots) +
                    ") must be at least settings.n (" + std::to_string(s.n) + ")");
    }
    // Far above any env's slots (max_landmarks is at most 1024), and low enough that the
    // observation's size (about 8 floats a slot) is computed without overflow.
    constexpr int64_t MAX_SLOTS = int64_t{1} << 20;
    if (s.n_slots > MAX_SLOTS) {
        value_error("settings.n_slots (" + std::to_string(s.n_slots) + ") must be at most " +
                    std::to_string(MAX_SLOTS));
    }
    return s;
}

// The map update's settings: the native Params (bound by the slam part), or any object
// with kernels.Params's fields (the numba namedtuple).
inline slam::Params params_of(nb::handle obj) {
    slam::Params native;
    if (nb::try_cast(obj, native)) return native;
    slam::Params p;
    p.epsilon = scalar_of<double>(obj, "epsilon");
    p.transfer = scalar_of<int64_t>(obj, "transfer");
    p.edge_samples = scalar_of<int64_t>(obj, "edge_samples");
    p.on_inconsistency = scalar_of<int64_t>(obj, "on_inconsistency");
    p.fusion = scalar_of<int64_t>(obj, "fusion");
    p.max_outliers = scalar_of<int64_t>(obj, "max_outliers");
    p.with_robot = scalar_of<bool>(obj, "with_robot");
    p.risk = scalar_of<double>(obj, "risk");
    p.likely = scalar_of<bool>(obj, "likely");
    p.estimate_bound = scalar_of<bool>(obj, "estimate_bound");
    // The ranges the native Params checks (the update's buffers are sized by them).
    const bool valid =
        std::isfinite(p.epsilon) && p.epsilon > 0.0 && slam::valid_transfer(p.transfer) &&
        p.edge_samples >= 1 && p.edge_samples <= slam::MAX_EDGE_SAMPLES &&
        (p.on_inconsistency == slam::INCONSISTENCY_RESTART ||
         p.on_inconsistency == slam::INCONSISTENCY_KEEP) &&
        (p.fusion == slam::FUSION_INTERSECT || p.fusion == slam::FUSION_RELAXED ||
         p.fusion == slam::FUSION_ROBUST) &&
        p.max_outliers >= 0 && p.max_outliers < slam::MAX_WINDOW && std::isfinite(p.risk);
    if (!valid) value_error("params are out of range (see bearing_env._core.Params)");
    return p;
}

// kernels.State's fields, in order.
inline constexpr const char* STATE_FIELDS[34] = {"vertices",
                                                 "counts",
                                                 "areas",
                                                 "centroids",
                                                 "robot_vertices",
                                                 "robot_counts",
                                                 "robot_area",
                                                 "robot_centroid",
                                                 "robot_heading",
                                                 "n_updates",
                                                 "n_frame_changes",
                                                 "n_inconsistent",
                                                 "window_vertices",
                                                 "window_counts",
                                                 "window_inlier",
                                                 "window_rejected",
                                                 "window_length",
                                                 "window_next",
                                                 "base_vertices",
                                                 "base_counts",
                                                 "n_dropped",
                                                 "outliers",
                                                 "level_vertices",
                                                 "level_counts",
                                                 "n_regions",
                                                 "robot_fixed_at",
                                                 "noise_scale",
                                                 "bound_events",
                                                 "probe_vertices",
                                                 "probe_counts",
                                                 "history_frame_bearings",
                                                 "history_bearings",
                                                 "history_length",
                                                 "history_next"};

// Field k of a map state given as a State tuple (by position) or as an object with the
// arrays as attributes (a BatchedPolygonSLAM), its array kept.
template <class T, int D>
void state_field(nb::handle obj, bool by_position, size_t k, View<T, D>& out, Kept& kept,
                 const typename std::common_type<std::array<int64_t, D>>::type& expect) {
    const char* name = STATE_FIELDS[k];
    if (!by_position && !nb::hasattr(obj, name)) {
        type_error(std::string("maps must be a MapState, a bearing_env.slam.kernels.State or "
                               "an object with its arrays; it has no '") +
                   name + "'");
    }
    nb::object value = by_position ? nb::borrow(obj[k]) : obj.attr(name);
    const std::string label = std::string("maps.") + name;
    out = view_of<T, D>(value, label.c_str(), expect);
    kept.push_back(std::move(value));
}

// A map batch's state: the native MapState (bind_slam_update.cpp: its State tuple, .state),
// a kernels.State tuple, or any object with State's 34 arrays as attributes (a
// BatchedPolygonSLAM); checked as the native update's bindings check it (M maps, m mapped
// landmarks, vertex axes of CAPACITY, the window and landmark counts the update's buffers
// hold).
inline slam::MapState map_state_of(nb::handle obj, Kept& kept) {
    nb::object source = nb::borrow(obj);
    if (!nb::isinstance<nb::tuple>(source) && !nb::hasattr(source, "vertices") &&
        nb::hasattr(source, "state")) {
        source = source.attr("state");
    }
    const bool by_position = nb::isinstance<nb::tuple>(source);
    if (by_position && nb::len(source) != 34) {
        value_error("maps must hold the 34 arrays of bearing_env.slam.kernels.State, not " +
                    std::to_string(nb::len(source)));
    }
    kept.push_back(source);
    const int64_t C = slam::CAPACITY;
    slam::MapState s;
    size_t k = 0;
    auto get = [&](auto& view, const auto& expect) {
        state_field(source, by_position, k++, view, kept, expect);
    };
    using A1 = std::array<int64_t, 1>;
    using A2 = std::array<int64_t, 2>;
    using A3 = std::array<int64_t, 3>;
    using A4 = std::array<int64_t, 4>;
    get(s.vertices, A3{-1, -1, C});
    const int64_t M = s.vertices.shape[0], m = s.vertices.shape[1];
    get(s.counts, A2{M, m});
    get(s.areas, A2{M, m});
    get(s.centroids, A2{M, m});
    get(s.robot_vertices, A2{M, C});
    get(s.robot_counts, A1{M});
    get(s.robot_area, A1{M});
    get(s.robot_centroid, A1{M});
    get(s.robot_heading, A1{M});
    get(s.n_updates, A1{M});
    get(s.n_frame_changes, A1{M});
    get(s.n_inconsistent, A1{M});
    get(s.window_vertices, A4{M, -1, m, C});
    const int64_t w = s.window_vertices.shape[1];
    get(s.window_counts, A3{M, w, m});
    get(s.window_inlier, A3{M, w, m});
    get(s.window_rejected, A2{M, w});
    get(s.window_length, A1{M});
    get(s.window_next, A1{M});
    get(s.base_vertices, A3{M, m, -1});
    get(s.base_counts, A2{M, m});
    get(s.n_dropped, A2{M, m});
    get(s.outliers, A2{M, m});
    get(s.level_vertices, A4{M, m, -1, C});
    const int64_t levels = s.level_vertices.shape[2];
    get(s.level_counts, A3{M, m, levels});
    get(s.n_regions, A2{M, m});
    get(s.robot_fixed_at, A1{M});
    get(s.noise_scale, A1{M});
    get(s.bound_events, A1{M});
    get(s.probe_vertices, A3{M, m, -1});
    get(s.probe_counts, A2{M, m});
    get(s.history_frame_bearings, A4{M, -1, 2, 2});
    const int64_t h = s.history_frame_bearings.shape[1];
    get(s.history_bearings, A4{M, h, 2, m});
    get(s.history_length, A1{M});
    get(s.history_next, A1{M});
    // view_of skips axes of expected length 0 (0 = any): spell those out.
    const std::array<int64_t, 34> firsts{s.vertices.shape[0],
                                         s.counts.shape[0],
                                         s.areas.shape[0],
                                         s.centroids.shape[0],
                                         s.robot_vertices.shape[0],
                                         s.robot_counts.shape[0],
                                         s.robot_area.shape[0],
                                         s.robot_centroid.shape[0],
                                         s.robot_heading.shape[0],
                                         s.n_updates.shape[0],
                                         s.n_frame_changes.shape[0],
                                         s.n_inconsistent.shape[0],
                                         s.window_vertices.shape[0],
                                         s.window_counts.shape[0],
                                         s.window_inlier.shape[0],
                                         s.window_rejected.shape[0],
                                         s.window_length.shape[0],
                                         s.window_next.shape[0],
                                         s.base_vertices.shape[0],
                                         s.base_counts.shape[0],
                                         s.n_dropped.shape[0],
                                         s.outliers.shape[0],
                                         s.level_vertices.shape[0],
                                         s.level_counts.shape[0],
                                         s.n_regions.shape[0],
                                         s.robot_fixed_at.shape[0],
                                         s.noise_scale.shape[0],
                                         s.bound_events.shape[0],
                                         s.probe_vertices.shape[0],
                                         s.probe_counts.shape[0],
                                         s.history_frame_bearings.shape[0],
                                         s.history_bearings.shape[0],
                                         s.history_length.shape[0],
                                         s.history_next.shape[0]};
    for (size_t f = 0; f < firsts.size(); ++f) {
        if (firsts[f] != M) {
            value_error(std::string("maps.") + STATE_FIELDS[f] + " has " +
                        std::to_string(firsts[f]) + " maps, maps.vertices " + std::to_string(M));
        }
    }
    const std::array<int64_t, 15> landmark_axes{
        s.counts.shape[1],          s.areas.shape[1],          s.centroids.shape[1],
        s.window_vertices.shape[2], s.window_counts.shape[2],  s.window_inlier.shape[2],
        s.base_vertices.shape[1],   s.base_counts.shape[1],    s.n_dropped.shape[1],
        s.outliers.shape[1],        s.level_vertices.shape[1], s.level_counts.shape[1],
        s.n_regions.shape[1],       s.probe_vertices.shape[1], s.history_bearings.shape[3]};
    for (int64_t length : landmark_axes) {
        if (length != m) {
            value_error("maps' per-landmark arrays must all map the " + std::to_string(m) +
                        " landmarks of maps.vertices");
        }
    }
    const bool axes_match = s.window_counts.shape[1] == w && s.window_inlier.shape[1] == w &&
                            s.window_rejected.shape[1] == w && s.level_counts.shape[2] == levels &&
                            s.history_bearings.shape[1] == h;
    if (!axes_match) value_error("maps' window, level or history axes do not match");
    for (const auto& [length, name] : {std::pair{s.base_vertices.shape[2], "base_vertices"},
                                       std::pair{s.probe_vertices.shape[2], "probe_vertices"}}) {
        if (length != C && length != 0) {
            value_error(std::string("maps.") + name + " must have " + std::to_string(C) +
                        " (or 0) vertex slots on its last axis, not " + std::to_string(length));
        }
    }
    if (w > slam::MAX_WINDOW) value_error("maps' window is longer than MAX_WINDOW");
    if (m + 2 > slam::MAX_LANDMARKS) {
        value_error("maps map " + std::to_string(m) + " landmarks, more than MAX_LANDMARKS - 2");
    }
    return s;
}

// What the fusion of `params` needs of the map state's optional arrays (as the native
// update's bindings check it before an update).
inline void check_state_for(const slam::MapState& s, const slam::Params& p) {
    if (p.fusion == slam::FUSION_RELAXED &&
        (s.window_vertices.shape[1] < 1 || s.base_vertices.shape[2] != slam::CAPACITY)) {
        value_error("params.fusion is FUSION_RELAXED but maps have no relaxed window or bases");
    }
    if (p.fusion == slam::FUSION_ROBUST) {
        if (s.level_vertices.shape[2] < 1) {
            value_error("params.fusion is FUSION_ROBUST but maps have no robust levels");
        }
        if (p.estimate_bound &&
            (s.probe_vertices.shape[2] != slam::CAPACITY || s.history_bearings.shape[1] < 1)) {
            value_error("params.estimate_bound is set but maps have no probe or history");
        }
    }
}

// The envs' state (state.BatchState's KERNEL_ARRAYS) from a BatchState.
inline env::BatchState batch_state_of(nb::handle obj, Kept& kept) {
    env::BatchState s;
    field_of(obj, "n_landmarks", s.n_landmarks, kept);
    const int64_t N = s.n_landmarks.shape[0];
    field_of(obj, "landmarks", s.landmarks, kept, {N, -1, 2});
    const int64_t slots = s.landmarks.shape[1];
    if (slots < 2) value_error("landmarks must have at least 2 slots");
    field_of(obj, "positions", s.positions, kept, {N, 2});
    field_of(obj, "headings", s.headings, kept, {N});
    field_of(obj, "frame_origin", s.frame_origin, kept, {N});
    field_of(obj, "frame_unit", s.frame_unit, kept, {N});
    field_of(obj, "landmarks_fl", s.landmarks_fl, kept, {N, slots - 2});
    field_of(obj, "moves", s.moves, kept, {N});
    field_of(obj, "potentials", s.potentials, kept, {N});
    field_of(obj, "latest_bearings", s.latest_bearings, kept, {N, slots});
    field_of(obj, "start_bearings", s.start_bearings, kept, {N, slots});
    field_of(obj, "start_positions", s.start_positions, kept, {N, 2});
    field_of(obj, "frame_changed", s.frame_changed, kept, {N});
    field_of(obj, "blocked", s.blocked, kept, {N});
    field_of(obj, "done", s.done, kept, {N});
    field_of(obj, "trajectory_length", s.trajectory_length, kept, {N});
    field_of(obj, "noise_offsets", s.noise_offsets, kept, {N, -1});
    const int64_t values = s.noise_offsets.shape[1];
    field_of(obj, "noise_is_outlier", s.noise_is_outlier, kept, {N, values});
    field_of(obj, "noise_replacement", s.noise_replacement, kept, {N, values});
    field_of(obj, "noise_used", s.noise_used, kept, {N});
    field_of(obj, "noise_filled", s.noise_filled, kept, {N});
    const bool zero_axes_match =
        s.landmarks_fl.shape[0] == N && s.landmarks_fl.shape[1] == slots - 2 &&
        s.noise_is_outlier.shape[1] == values && s.noise_replacement.shape[1] == values;
    if (!zero_axes_match) value_error("the state's arrays do not match in shape");
    return s;
}

}  // namespace bearing::bindings
