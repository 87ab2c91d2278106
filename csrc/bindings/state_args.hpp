// A map batch's state from its Python objects (a State tuple, a MapState's, or an object
// with State's arrays as attributes): the one parser of it, for the MapState binding
// (bind_slam_update.cpp) and the env step's arguments (env_args.hpp).
#pragma once

#include <nanobind/nanobind.h>

#include <string>

#include <bearing_core/slam/scratch.hpp>
#include <bearing_core/slam/state.hpp>
#include "bindings/structs.hpp"

namespace bearing::bindings {

// The lengths a map state's rules start from: its vertex capacity.
inline schema::Sizes map_sizes() { return {{"CAPACITY", slam::CAPACITY}}; }

// The 34 arrays of a map batch's state (`label` in messages), checked as the native update
// needs them: each against its shape rule (state.hpp) with `sizes`, which then holds the
// state's axes (maps, m, w, levels, h); vertex axes of CAPACITY or 0, a window and a
// landmark count the update's buffers hold, and bool bytes the update reads.
inline slam::MapState parse_map_state(nb::handle source, const char* label, schema::Sizes& sizes,
                                      Kept& kept) {
    const slam::MapState s = read_struct<slam::MapState>(source, label, sizes, kept, true);
    for (const char* axis : {"base_capacity", "probe_capacity"}) {
        if (sizes.at(axis) != slam::CAPACITY && sizes.at(axis) != 0) {
            value_error(std::string(label) + "'s " + axis + " (the last axis of " +
                        std::string(sizes.bound_by(axis)) + ") must be " +
                        std::to_string(slam::CAPACITY) + " or 0, not " +
                        std::to_string(sizes.at(axis)));
        }
    }
    if (sizes.at("w") > slam::MAX_WINDOW) {
        value_error(std::string(label) + ".window_vertices has a window of " +
                    std::to_string(sizes.at("w")) + " movements, more than MAX_WINDOW (" +
                    std::to_string(slam::MAX_WINDOW) + ")");
    }
    if (sizes.at("m") + 2 > slam::MAX_LANDMARKS) {
        value_error(std::string(label) + ".vertices has " + std::to_string(sizes.at("m")) +
                    " mapped landmarks, more than " + std::to_string(slam::MAX_LANDMARKS - 2) +
                    " (MAX_LANDMARKS - 2)");
    }
    return s;
}

// A map batch's state for the env step and the codec: a MapState binding's (its State
// tuple, .state), a State tuple, or any object with State's arrays as attributes.
inline slam::MapState map_state_of(nb::handle obj, schema::Sizes& sizes, Kept& kept) {
    nb::object source = nb::borrow(obj);
    if (!nb::isinstance<nb::tuple>(source) && !nb::hasattr(source, "vertices") &&
        nb::hasattr(source, "state")) {
        source = source.attr("state");
    }
    kept.push_back(source);
    return parse_map_state(source, "maps", sizes, kept);
}

// A batch's state as the native update takes it: checked views of the arrays of a State,
// and the State (its arrays stay alive).
struct PyMapState {
    nb::object state;
    slam::MapState views;
    schema::Sizes sizes;  // its axes: maps, m (mapped landmarks), w, levels, h
    int64_t maps = 0, mapped = 0;

    explicit PyMapState(nb::handle source) : state(nb::borrow(source)) {
        Kept kept;  // (the State keeps its arrays alive)
        sizes = map_sizes();
        views = parse_map_state(source, "state", sizes, kept);
        maps = sizes.at("maps");
        mapped = sizes.at("m");
    }
};

// `to` can take copies of `from`'s maps (`what` in messages): another state, of the same
// landmarks and fusion arrays.
inline void require_copyable(const PyMapState& from, const PyMapState& to, const char* what) {
    if (from.views.vertices.data == to.views.vertices.data) {
        value_error(std::string(what) + " needs two different states");
    }
    bool same = from.mapped == to.mapped;
    for (const char* axis : {"w", "base_capacity", "levels", "probe_capacity", "h"}) {
        same = same && from.sizes.at(axis) == to.sizes.at(axis);
    }
    if (!same) {
        value_error(
            std::string(what) + " needs states of the same landmarks and fusion arrays: from has " +
            std::to_string(from.mapped) + " mapped landmarks, to " + std::to_string(to.mapped));
    }
}

// What the fusion of `params` needs of the map state's optional arrays (checked before
// an update: the MapState binding's update_maps and the env step).
inline void check_state_for(const slam::MapState& s, const slam::Params& p) {
    auto require = [](bool ok, const char* why) {
        if (!ok) value_error(why);
    };
    if (p.fusion == slam::FUSION_RELAXED) {
        require(s.window_vertices.shape[1] >= 1,
                "state has no relaxed window (window_vertices axis 1 is 0), but params.fusion "
                "is FUSION_RELAXED");
        require(s.base_vertices.shape[2] == slam::CAPACITY,
                "state.base_vertices has no vertex slots, but params.fusion is FUSION_RELAXED");
    }
    if (p.fusion == slam::FUSION_ROBUST) {
        require(s.level_vertices.shape[2] >= 1,
                "state has no robust levels (level_vertices axis 2 is 0), but params.fusion "
                "is FUSION_ROBUST");
        require(!p.estimate_bound || s.probe_vertices.shape[2] == slam::CAPACITY,
                "state.probe_vertices has no vertex slots, but params.estimate_bound is set");
        require(!p.estimate_bound || s.history_bearings.shape[1] >= 1,
                "state has no bearing history (history_bearings axis 1 is 0), but "
                "params.estimate_bound is set");
    }
}

}  // namespace bearing::bindings
