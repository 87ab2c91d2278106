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

// Encoded's padding over the whole of `encoded` (new arrays, before encode_map_into):
// inf areas and inf + inf j centroids, the other arrays' padding left as it is (zeros).
void pad_encoded(const Encoded& encoded);

// encode_map_into: the arrays every fusion uses, for rows, into `encoded` (its padding
// kept: only the mapped slots are written).
void encode_map_into(const slam::MapState& state, View1<const int64_t> rows,
                     const Encoded& encoded);

// encode_window's arrays, zero-initialised by the caller except window_rejected,
// window_length and window_next (written).
void encode_window_into(const slam::MapState& state, View1<const int64_t> rows, const Window& out);

// encode_levels's arrays, zero-initialised by the caller where encode_levels makes zeros.
void encode_levels_into(const slam::MapState& state, View1<const int64_t> rows, const Levels& out);

}  // namespace bearing::env
