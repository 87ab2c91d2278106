// bearing_env/world.py's kernels (see world.hpp).
#include <bearing_core/sim/world.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

#include <bearing_core/core/checks.hpp>
#include <bearing_core/core/pymath.hpp>

namespace bearing::sim {

void add_wrapped(View2<const double> true_bearings, View2<const double> offsets,
                 View2<double> out) {
    check_shape(offsets, true_bearings, "offsets");
    check_shape(out, true_bearings, "out");
    for (int64_t i = 0; i < true_bearings.shape[0]; ++i) {
        for (int64_t j = 0; j < true_bearings.shape[1]; ++j) {
            out(i, j) = wrap(true_bearings(i, j) + offsets(i, j));
        }
    }
}

void add_wrapped_with_outliers(View2<const double> true_bearings, View2<const double> offsets,
                               View2<const bool> is_outlier, View2<const double> replacement,
                               View2<double> out) {
    check_shape(offsets, true_bearings, "offsets");
    check_shape(is_outlier, true_bearings, "is_outlier");
    check_shape(replacement, true_bearings, "replacement");
    check_shape(out, true_bearings, "out");
    for (int64_t i = 0; i < true_bearings.shape[0]; ++i) {
        for (int64_t j = 0; j < true_bearings.shape[1]; ++j) {
            const double value =
                is_outlier(i, j) ? replacement(i, j) : true_bearings(i, j) + offsets(i, j);
            out(i, j) = wrap(value);
        }
    }
}

double bearing(double landmark_x, double landmark_y, double x, double y, double heading) {
    return wrap(std::atan2(landmark_y - y, landmark_x - x) - heading);
}

Move straight_move(double x, double y, double heading, double length, double width, double height,
                   double margin, double min_baseline) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    const double dx = std::cos(heading), dy = std::sin(heading);
    const double room_x = dx > 0.0 ? (width - margin - x) / dx : dx < 0.0 ? (margin - x) / dx : inf;
    const double room_y = dy > 0.0   ? (height - margin - y) / dy
                          : dy < 0.0 ? (margin - y) / dy
                                     : inf;
    double free = std::max(0.0, std::min(room_x, room_y));
    if (free < min_baseline) free = 0.0;
    const double travelled = std::min(length, free);
    const double new_x = std::min(std::max(x + travelled * dx, margin), width - margin);
    const double new_y = std::min(std::max(y + travelled * dy, margin), height - margin);
    return {new_x, new_y, travelled, free < length};
}

Move obstructed_move(double x, double y, double heading, double length,
                     const MoveSettings& settings, const Obstacles& obstacles) {
    const double width = settings.width, height = settings.height, margin = settings.margin,
                 min_baseline = settings.min_baseline;
    double room = free_length(x, y, heading, obstacles, margin);
    if (room >= length) {
        return straight_move(x, y, heading, length, width, height, margin, min_baseline);
    }
    if (room < min_baseline) room = 0.0;
    Move move = straight_move(x, y, heading, room, width, height, margin, min_baseline);
    move.blocked = true;
    return move;
}

void true_bearings_into(View3<const double> landmarks, View2<const double> positions,
                        View1<const double> headings, View2<double> out) {
    check_landmark_rows(landmarks, positions, headings, out);
    for (int64_t i = 0; i < landmarks.shape[0]; ++i) {
        for (int64_t j = 0; j < landmarks.shape[1]; ++j) {
            out(i, j) = bearing(landmarks(i, j, 0), landmarks(i, j, 1), positions(i, 0),
                                positions(i, 1), headings[i]);
        }
    }
}

}  // namespace bearing::sim
