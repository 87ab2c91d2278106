// A map batch's state from its Python objects (a bearing_env.slam.kernels.State tuple, a
// MapState's, or an object with State's arrays as attributes): the one parser of it, for
// the MapState binding (bind_slam_update.cpp) and the env step's arguments (env_args.hpp).
#pragma once

#include <nanobind/nanobind.h>

#include <array>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <bearing_core/slam/scratch.hpp>
#include <bearing_core/slam/state.hpp>
#include "bindings/arrays.hpp"

namespace bearing::bindings {

// The Python objects a native object's views point into, kept alive with it.
using Kept = std::vector<nb::object>;

// kernels.State's fields, in order (slam/state.hpp's list).
inline constexpr const char* STATE_FIELDS[] = {
#define BEARING_CORE_FIELD_NAME(T, D, name) #name,
    BEARING_CORE_MAP_STATE(BEARING_CORE_FIELD_NAME)
#undef BEARING_CORE_FIELD_NAME
};
inline constexpr size_t N_STATE_FIELDS = sizeof(STATE_FIELDS) / sizeof(STATE_FIELDS[0]);

// out = the view of `value` (argument `name`), its shape checked against `expect`.
template <class T, int D>
void assign_view(View<T, D>& out, nb::handle value, const char* name,
                 const std::common_type_t<std::array<int64_t, D>>& expect) {
    out = view_of<T, D>(value, name, expect);
}

// A map batch's state, checked, and the sizes of its axes.
struct ParsedState {
    slam::MapState views;
    int64_t maps = 0;
    int64_t mapped = 0;  // m: landmarks mapped per map (L1 and L2 excluded)
    int64_t window = 0;  // w
    int64_t levels = 0;
    int64_t history = 0;  // h
};

// The 34 arrays of a map batch's state, checked as the native update needs them: from
// `source`, a State tuple (by_position) or an object with State's arrays as attributes;
// `label` names it in messages ("state", "maps"). Each array: dtype, layout, and the
// axes it shares with state.vertices (maps M, mapped landmarks m), its own window, level
// and history axes, vertex axes of CAPACITY (or 0 where a fusion leaves them empty), a
// window and a landmark count the update's buffers hold. The one parser of a map state:
// the MapState binding and the env step's arguments both use it.
inline ParsedState parse_map_state(nb::handle source, bool by_position, const char* label,
                                   Kept& kept) {
    ParsedState parsed;
    slam::MapState& s = parsed.views;
    size_t k = 0;
    auto get = [&](auto& view, const auto& expect) {
        const char* name = STATE_FIELDS[k++];
        const std::string qualified = std::string(label) + "." + name;
        if (!by_position && !nb::hasattr(source, name)) {
            type_error(std::string(label) +
                       " must be a MapState, a bearing_env.slam.kernels."
                       "State or an object with its arrays; it has no '" +
                       name + "'");
        }
        nb::object value = by_position ? nb::borrow(source[k - 1]) : source.attr(name);
        assign_view(view, value, qualified.c_str(), expect);
        kept.push_back(std::move(value));
    };
    using A1 = std::array<int64_t, 1>;
    using A2 = std::array<int64_t, 2>;
    using A3 = std::array<int64_t, 3>;
    using A4 = std::array<int64_t, 4>;
    const int64_t C = slam::CAPACITY, any = ANY_LENGTH;
    get(s.vertices, A3{any, any, C});
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
    get(s.window_vertices, A4{M, any, m, C});
    const int64_t w = s.window_vertices.shape[1];
    get(s.window_counts, A3{M, w, m});
    get(s.window_inlier, A3{M, w, m});
    get(s.window_rejected, A2{M, w});
    get(s.window_length, A1{M});
    get(s.window_next, A1{M});
    get(s.base_vertices, A3{M, m, any});
    get(s.base_counts, A2{M, m});
    get(s.n_dropped, A2{M, m});
    get(s.outliers, A2{M, m});
    get(s.level_vertices, A4{M, m, any, C});
    const int64_t levels = s.level_vertices.shape[2];
    get(s.level_counts, A3{M, m, levels});
    get(s.n_regions, A2{M, m});
    get(s.robot_fixed_at, A1{M});
    get(s.noise_scale, A1{M});
    get(s.bound_events, A1{M});
    get(s.probe_vertices, A3{M, m, any});
    get(s.probe_counts, A2{M, m});
    get(s.history_frame_bearings, A4{M, any, 2, 2});
    const int64_t h = s.history_frame_bearings.shape[1];
    get(s.history_bearings, A4{M, h, 2, m});
    get(s.history_length, A1{M});
    get(s.history_next, A1{M});
    for (const auto& [length, name] : {std::pair{s.base_vertices.shape[2], "base_vertices"},
                                       std::pair{s.probe_vertices.shape[2], "probe_vertices"}}) {
        if (length != C && length != 0) {
            value_error(std::string(label) + "." + name + " must have " + std::to_string(C) +
                        " (or 0) vertex slots on its last axis, not " + std::to_string(length));
        }
    }
    if (w > slam::MAX_WINDOW) {
        value_error(std::string(label) + ".window_vertices has a window of " + std::to_string(w) +
                    " movements, more than MAX_WINDOW (" + std::to_string(slam::MAX_WINDOW) + ")");
    }
    if (m + 2 > slam::MAX_LANDMARKS) {
        value_error(std::string(label) + ".vertices has " + std::to_string(m) +
                    " mapped landmarks, more than " + std::to_string(slam::MAX_LANDMARKS - 2) +
                    " (MAX_LANDMARKS - 2)");
    }
    // The bool arrays the update reads as well as writes.
    check_bool_bytes(s.window_inlier.data, s.window_inlier.size(),
                     (std::string(label) + ".window_inlier").c_str());
    check_bool_bytes(s.window_rejected.data, s.window_rejected.size(),
                     (std::string(label) + ".window_rejected").c_str());
    parsed.maps = M;
    parsed.mapped = m;
    parsed.window = w;
    parsed.levels = levels;
    parsed.history = h;
    return parsed;
}

// A map batch's state for the env step: the native MapState (bind_slam_update.cpp: its
// State tuple, .state), a kernels.State tuple, or any object with State's 34 arrays as
// attributes (a BatchedPolygonSLAM).
inline slam::MapState map_state_of(nb::handle obj, Kept& kept) {
    nb::object source = nb::borrow(obj);
    if (!nb::isinstance<nb::tuple>(source) && !nb::hasattr(source, "vertices") &&
        nb::hasattr(source, "state")) {
        source = source.attr("state");
    }
    const bool by_position = nb::isinstance<nb::tuple>(source);
    if (by_position && nb::len(source) != N_STATE_FIELDS) {
        value_error("maps must hold the 34 arrays of bearing_env.slam.kernels.State, not " +
                    std::to_string(nb::len(source)));
    }
    kept.push_back(source);
    return parse_map_state(source, by_position, "maps", kept).views;
}

// What the fusion of `params` needs of the map state's optional arrays (checked before
// an update: the MapState binding's update_maps and the env step).
inline void check_state_for(const slam::MapState& s, const slam::Params& p) {
    if (p.fusion == slam::FUSION_RELAXED) {
        if (s.window_vertices.shape[1] < 1) {
            value_error(
                "state has no relaxed window (state.window_vertices axis 1 is 0), but "
                "params.fusion is FUSION_RELAXED");
        }
        if (s.base_vertices.shape[2] != slam::CAPACITY) {
            value_error(
                "state.base_vertices has no vertex slots, but params.fusion is "
                "FUSION_RELAXED");
        }
    }
    if (p.fusion == slam::FUSION_ROBUST) {
        if (s.level_vertices.shape[2] < 1) {
            value_error(
                "state has no robust levels (state.level_vertices axis 2 is 0), but "
                "params.fusion is FUSION_ROBUST");
        }
        if (p.estimate_bound && s.probe_vertices.shape[2] != slam::CAPACITY) {
            value_error(
                "state.probe_vertices has no vertex slots, but params.estimate_bound "
                "is set");
        }
        if (p.estimate_bound && s.history_bearings.shape[1] < 1) {
            value_error(
                "state has no bearing history (state.history_bearings axis 1 is 0), "
                "but params.estimate_bound is set");
        }
    }
}

}  // namespace bearing::bindings
