// bearing_env/envs/robot_map.py's kernels (see robot_map.hpp).
#include <bearing_core/env/robot_map.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bearing::env {

namespace {

// dst[:count] = src[:count] (Python's slices on both sides) and, with `zero_rest`,
// dst[count:] = 0.
template <class T>
void copy_prefix(T* dst, int64_t dst_length, const T* src, int64_t src_length, int64_t count,
                 bool zero_rest) {
    const int64_t stop = slice_stop(count, dst_length);
    const int64_t copied = std::min(stop, slice_stop(count, src_length));
    std::copy(src, src + copied, dst);
    if (zero_rest) std::fill(dst + stop, dst + dst_length, T{});
}

}  // namespace

void pad_encoded(const Encoded& encoded) {
    const double inf = std::numeric_limits<double>::infinity();
    std::fill_n(encoded.areas.data, encoded.areas.size(), inf);
    std::fill_n(encoded.centroids.data, encoded.centroids.size(), cplx(inf, inf));
}

void encode_map_into(const slam::MapState& state, View1<const int64_t> rows,
                     const Encoded& encoded) {
    const int64_t mapped = state.counts.shape[1];
    const int64_t capacity = encoded.vertices.shape[2];
    const int64_t state_capacity = state.vertices.shape[2];
    const int64_t robot_capacity = encoded.robot_vertices.shape[1];
    const int64_t state_robot_capacity = state.robot_vertices.shape[1];
    for (int64_t i = 0; i < rows.shape[0]; ++i) {
        const int64_t row = rows[i];
        for (int64_t j = 0; j < mapped; ++j) {
            const int64_t count = state.counts(row, j);
            encoded.counts(i, j) = count;
            copy_prefix(encoded.vertices.row(i, j), capacity, state.vertices.row(row, j),
                        state_capacity, count, true);
            encoded.areas(i, j) = state.areas(row, j);
            encoded.centroids(i, j) = known(state.centroids(row, j));
        }
        const int64_t count = state.robot_counts[row];
        encoded.robot_counts[i] = count;
        copy_prefix(encoded.robot_vertices.row(i), robot_capacity, state.robot_vertices.row(row),
                    state_robot_capacity, count, true);
        encoded.robot_area[i] = state.robot_area[row];
        encoded.robot_centroid[i] = known(state.robot_centroid[row]);
        const double heading = state.robot_heading[row];
        encoded.robot_heading[i] =
            std::isnan(heading) ? std::numeric_limits<double>::infinity() : heading;
        encoded.n_updates[i] = state.n_updates[row];
        encoded.n_frame_changes[i] = state.n_frame_changes[row];
        encoded.n_inconsistent[i] = state.n_inconsistent[row];
    }
}

void encode_window_into(const slam::MapState& state, View1<const int64_t> rows, const Window& out) {
    const int64_t mapped = state.counts.shape[1];
    const int64_t window = state.window_vertices.shape[1];
    const int64_t capacity = state.window_vertices.shape[3];
    const int64_t base_capacity = state.base_vertices.shape[2];
    for (int64_t i = 0; i < rows.shape[0]; ++i) {
        const int64_t row = rows[i];
        for (int64_t k = 0; k < window; ++k) {
            out.window_rejected(i, k) = state.window_rejected(row, k);
            for (int64_t j = 0; j < mapped; ++j) {
                const int64_t count = state.window_counts(row, k, j);
                out.window_counts(i, k, j) = count;
                copy_prefix(out.window_vertices.row(i, k, j), out.window_vertices.shape[3],
                            state.window_vertices.row(row, k, j), capacity, count, false);
                out.window_inlier(i, k, j) = state.window_inlier(row, k, j);
            }
        }
        out.window_length[i] = state.window_length[row];
        out.window_next[i] = state.window_next[row];
        for (int64_t j = 0; j < mapped; ++j) {
            const int64_t count = state.base_counts(row, j);
            out.base_counts(i, j) = count;
            copy_prefix(out.base_vertices.row(i, j), out.base_vertices.shape[2],
                        state.base_vertices.row(row, j), base_capacity, count, false);
            out.n_dropped(i, j) = state.n_dropped(row, j);
            out.outliers(i, j) = state.outliers(row, j);
        }
    }
}

void encode_levels_into(const slam::MapState& state, View1<const int64_t> rows, const Levels& out) {
    const int64_t mapped = state.counts.shape[1];
    const int64_t levels = state.level_vertices.shape[2];
    const int64_t capacity = state.level_vertices.shape[3];
    const int64_t history = state.history_bearings.shape[1];
    const int64_t probe_capacity = state.probe_vertices.shape[2];
    for (int64_t i = 0; i < rows.shape[0]; ++i) {
        const int64_t row = rows[i];
        out.robot_fixed_at[i] = state.robot_fixed_at[row];
        out.noise_scale[i] = state.noise_scale[row];
        out.bound_events[i] = state.bound_events[row];
        const int64_t frame_values = state.history_frame_bearings.stride(0);
        std::copy(state.history_frame_bearings.row(row),
                  state.history_frame_bearings.row(row) + frame_values,
                  out.history_frame_bearings.row(i));
        out.history_length[i] = state.history_length[row];
        out.history_next[i] = state.history_next[row];
        for (int64_t j = 0; j < mapped; ++j) {
            out.outliers(i, j) = state.outliers(row, j);
            out.n_regions(i, j) = state.n_regions(row, j);
            for (int64_t k = 0; k < levels; ++k) {
                const int64_t count = state.level_counts(row, j, k);
                out.level_counts(i, j, k) = count;
                copy_prefix(out.level_vertices.row(i, j, k), out.level_vertices.shape[3],
                            state.level_vertices.row(row, j, k), capacity, count, false);
            }
            const int64_t count = state.probe_counts(row, j);
            out.probe_counts(i, j) = count;
            copy_prefix(out.probe_vertices.row(i, j), out.probe_vertices.shape[2],
                        state.probe_vertices.row(row, j), probe_capacity, count, false);
            for (int64_t h = 0; h < history; ++h) {
                for (int64_t e = 0; e < 2; ++e) {
                    out.history_bearings(i, h, e, j) = state.history_bearings(row, h, e, j);
                }
            }
        }
    }
}

}  // namespace bearing::env
