// The robot-map codec's kernels (bearing_env/envs/robot_map.py): a map batch's state of
// some rows in the info's canonical form (landmark slots padded, unknown points inf).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include <bearing_core/env/types.hpp>

namespace bearing::env {

// A complex point, inf + inf j if unknown (NaN in either part).
inline cplx known(cplx value) {
    if (std::isnan(value.re) || std::isnan(value.im)) {
        return {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
    }
    return value;
}

// The stop of Python's slice [:count] of a sequence of `length` items.
inline int64_t slice_stop(int64_t count, int64_t length) {
    if (count < 0) return count + length > 0 ? count + length : 0;
    return count < length ? count : length;
}

// encode_map_into: the arrays every fusion uses, for rows, into `encoded` (its padding
// kept: only the mapped slots are written).
void encode_map_into(const slam::MapState& state, View1<const int64_t> rows,
                     const Encoded& encoded);

// encode_window's arrays (RELAXED_STATE_ARRAYS), zero-initialised by the caller except
// window_rejected, window_length and window_next (written).
struct Window {
    View4<cplx> window_vertices;
    View3<int64_t> window_counts;
    View3<bool> window_inlier;
    View2<bool> window_rejected;
    View1<int64_t> window_length;
    View1<int64_t> window_next;
    View3<cplx> base_vertices;
    View2<int64_t> base_counts;
    View2<int64_t> n_dropped;
    View2<int64_t> outliers;
};
void encode_window_into(const slam::MapState& state, View1<const int64_t> rows, const Window& out);

// encode_levels's arrays (ROBUST_STATE_ARRAYS), zero-initialised by the caller where
// encode_levels makes zeros.
struct Levels {
    View2<int64_t> outliers;
    View4<cplx> level_vertices;
    View3<int64_t> level_counts;
    View2<int64_t> n_regions;
    View1<int64_t> robot_fixed_at;
    View1<double> noise_scale;
    View1<int64_t> bound_events;
    View3<cplx> probe_vertices;
    View2<int64_t> probe_counts;
    View4<double> history_frame_bearings;
    View4<double> history_bearings;
    View1<int64_t> history_length;
    View1<int64_t> history_next;
};
void encode_levels_into(const slam::MapState& state, View1<const int64_t> rows, const Levels& out);

}  // namespace bearing::env
