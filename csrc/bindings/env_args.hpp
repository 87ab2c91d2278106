// Checked arguments of the env kernels (bind_env.cpp): a group's Settings, the map update's
// Params, the envs' BatchState, read from their Python objects once (the map state's
// parser is state_args.hpp's).
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
#include "bindings/state_args.hpp"

namespace bearing::bindings {

// The view of attribute `name` of obj, its array kept.
template <class T, int D>
void field_of(nb::handle obj, const char* name, View<T, D>& out, Kept& kept,
              const std::array<int64_t, D>& expect = any_shape<D>()) {
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
    slam::validate(p);  // the native Params' ranges (the update's buffers are sized by them)
    return p;
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
