// The simulator's motion and noise-free bearings (the numba kernels of
// bearing_env/world.py, ported function for function, same order of operations).
#pragma once

#include <cstdint>

#include <bearing_core/core/views.hpp>
#include <bearing_core/sim/sensing.hpp>

namespace bearing::sim {

// out = wrap(true_bearings + offsets), elementwise over (N, n).
void add_wrapped(View2<const double> true_bearings, View2<const double> offsets, View2<double> out);
// As add_wrapped, with replacement[i, j] (wrapped) where is_outlier[i, j].
void add_wrapped_with_outliers(View2<const double> true_bearings, View2<const double> offsets,
                               View2<const bool> is_outlier, View2<const double> replacement,
                               View2<double> out);

// The noise-free bearing of a landmark from a pose, radians CCW from the heading.
double bearing(double landmark_x, double landmark_y, double x, double y, double heading);

// What one straight move did: the new position, the distance travelled, whether it was
// stopped short (world.straight_move's tuple, in its order).
struct Move {
    double x;
    double y;
    double travelled;
    bool blocked;
};

// The arena's walls and margin, and the shortest move (obstructed_move's `settings`).
struct MoveSettings {
    double width;
    double height;
    double margin;
    double min_baseline;
};

Move straight_move(double x, double y, double heading, double length, double width, double height,
                   double margin, double min_baseline);
Move obstructed_move(double x, double y, double heading, double length,
                     const MoveSettings& settings, const Obstacles& obstacles);
// Noise-free bearings of landmarks (N, n, 2) from poses (N, 2), (N,) into out (N, n).
void true_bearings_into(View3<const double> landmarks, View2<const double> positions,
                        View1<const double> headings, View2<double> out);

}  // namespace bearing::sim
