// Copies of whole maps between batches (bearing_env/slam/batch.py's fill_from and take).
#include <bearing_core/slam/state.hpp>

#include <algorithm>

namespace bearing::slam {

namespace {

// to's row i = from's row rows[i], for one array (rows checked by the caller).
template <class T, int D>
void copy_rows(const View<T, D>& from, View1<const int64_t> rows, const View<T, D>& to) {
    const int64_t length = from.stride(0);
    for (int64_t i = 0; i < rows.shape[0]; ++i) {
        const T* source = from.row(rows[i]);
        std::copy(source, source + length, to.row(i));
    }
}

}  // namespace

void copy_maps(const MapState& from, View1<const int64_t> rows, const MapState& to) {
    copy_rows(from.vertices, rows, to.vertices);
    copy_rows(from.counts, rows, to.counts);
    copy_rows(from.areas, rows, to.areas);
    copy_rows(from.centroids, rows, to.centroids);
    copy_rows(from.robot_vertices, rows, to.robot_vertices);
    copy_rows(from.robot_counts, rows, to.robot_counts);
    copy_rows(from.robot_area, rows, to.robot_area);
    copy_rows(from.robot_centroid, rows, to.robot_centroid);
    copy_rows(from.robot_heading, rows, to.robot_heading);
    copy_rows(from.n_updates, rows, to.n_updates);
    copy_rows(from.n_frame_changes, rows, to.n_frame_changes);
    copy_rows(from.n_inconsistent, rows, to.n_inconsistent);
    copy_rows(from.window_vertices, rows, to.window_vertices);
    copy_rows(from.window_counts, rows, to.window_counts);
    copy_rows(from.window_inlier, rows, to.window_inlier);
    copy_rows(from.window_rejected, rows, to.window_rejected);
    copy_rows(from.window_length, rows, to.window_length);
    copy_rows(from.window_next, rows, to.window_next);
    copy_rows(from.base_vertices, rows, to.base_vertices);
    copy_rows(from.base_counts, rows, to.base_counts);
    copy_rows(from.n_dropped, rows, to.n_dropped);
    copy_rows(from.outliers, rows, to.outliers);
    copy_rows(from.level_vertices, rows, to.level_vertices);
    copy_rows(from.level_counts, rows, to.level_counts);
    copy_rows(from.n_regions, rows, to.n_regions);
    copy_rows(from.robot_fixed_at, rows, to.robot_fixed_at);
    copy_rows(from.noise_scale, rows, to.noise_scale);
    copy_rows(from.bound_events, rows, to.bound_events);
    copy_rows(from.probe_vertices, rows, to.probe_vertices);
    copy_rows(from.probe_counts, rows, to.probe_counts);
    copy_rows(from.history_frame_bearings, rows, to.history_frame_bearings);
    copy_rows(from.history_bearings, rows, to.history_bearings);
    copy_rows(from.history_length, rows, to.history_length);
    copy_rows(from.history_next, rows, to.history_next);
}

}  // namespace bearing::slam
