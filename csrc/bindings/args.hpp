// The library's structs from their Python objects, checked once: a map batch's state (a
// State tuple, a MapState's, or an object with State's arrays as attributes; the one parser
// of it, for the MapState binding, bind_slam.cpp, and the env kernels, bind_env.cpp), a
// group's Settings and the map update's Params.
#pragma once

#include <nanobind/nanobind.h>

#include <bearing_core/env/checked.hpp>
#include <bearing_core/slam/checked.hpp>
#include <bearing_core/slam/state.hpp>
#include "bindings/structs.hpp"

namespace bearing::bindings {

// The lengths a map state's rules start from: its vertex capacity.
inline schema::Sizes map_sizes() { return {{"CAPACITY", slam::CAPACITY}}; }

// A map batch's state (`label` in messages): a MapState binding's (its State tuple,
// .state), a State tuple, or any object with State's arrays as attributes. Its 34 arrays
// are checked as the native update needs them: each against its shape rule (state.hpp)
// with `sizes`, which then holds the state's axes (maps, m, w, levels, h), the state
// against the update's buffers (checked::check_state), and the bool bytes it reads.
inline slam::MapState map_state_of(nb::handle obj, schema::Sizes& sizes, Kept& kept,
                                   const char* label = "maps") {
    nb::object source = nb::borrow(obj);
    if (!nb::isinstance<nb::tuple>(source) && !nb::hasattr(source, "vertices") &&
        nb::hasattr(source, "state")) {
        source = source.attr("state");
    }
    kept.push_back(source);
    const slam::MapState s = read_struct<slam::MapState>(source, label, sizes, kept, true);
    slam::checked::check_state(s, label);
    return s;
}

// A batch's state as the native update takes it: checked views of the arrays of a State,
// and the State (its arrays stay alive).
struct PyMapState {
    nb::object state;
    slam::MapState views;
    schema::Sizes sizes = map_sizes();  // then its axes: maps, m (mapped landmarks), w, levels, h

    explicit PyMapState(nb::handle source) : state(nb::borrow(source)) {
        Kept kept;  // (the State keeps its arrays alive)
        views = map_state_of(source, sizes, kept, "state");
    }
};

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
    env::checked::validate(s);
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
