// Checked arguments of the env kernels (bind_env.cpp): a group's Settings, the map update's
// Params and the envs' BatchState, read from their Python objects once (the map state's
// parser is state_args.hpp's).
#pragma once

#include <nanobind/nanobind.h>

#include <string>

#include <bearing_core/env/types.hpp>
#include <bearing_core/slam/state.hpp>
#include "bindings/sim_args.hpp"
#include "bindings/state_args.hpp"
#include "bindings/structs.hpp"

namespace bearing::bindings {

// A group's settings from a Settings (any object with its fields).
inline env::Settings settings_of(nb::handle obj, Kept& kept) {
    env::Settings s;
#define BEARING_BINDINGS_READ_SETTING(T, name, value, doc) \
    s.name = scalar_of<T>(obj, #name, "settings");
    BEARING_CORE_SETTINGS(BEARING_BINDINGS_READ_SETTING)
#undef BEARING_BINDINGS_READ_SETTING
    schema::Sizes sizes;
    const env::Settings arrays = read_struct<env::Settings>(obj, "", sizes, kept, false);
    s.obstacle_vertices = arrays.obstacle_vertices;
    s.obstacle_starts = arrays.obstacle_starts;
    // (the obstacles' vertex ranges, checked)
    obstacles_of(obj.attr("obstacle_vertices"), obj.attr("obstacle_starts"),
                 "settings.obstacle_vertices", "settings.obstacle_starts");
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
    constexpr int64_t MAX_APPENDED = int64_t{1} << 31;
    if (s.appended < 0 || s.appended > MAX_APPENDED) {
        value_error("settings.appended must be in [0, " + std::to_string(MAX_APPENDED) + "], got " +
                    std::to_string(s.appended));
    }
    return s;
}

// The map update's settings: the native Params, or any object with its fields.
inline slam::Params params_of(nb::handle obj) {
    slam::Params p;
    if (nb::try_cast(obj, p)) return p;
#define BEARING_BINDINGS_READ_SETTING(T, name, value, doc) \
    p.name = scalar_of<T>(obj, #name, "params");
    BEARING_CORE_PARAMS(BEARING_BINDINGS_READ_SETTING)
#undef BEARING_BINDINGS_READ_SETTING
    slam::validate(p);  // the native Params' ranges (the update's buffers are sized by them)
    return p;
}

}  // namespace bearing::bindings
