// Geometry of a limited sensor among obstacles (bearing_env/sensing.py, ported function
// for function, same order of operations): how far a robot can move along a ray before
// it touches an obstacle, line of sight, the field of view and range, clearance.
//
// Obstacles are packed as in Python: vertices (V, 2) metres and starts (k + 1,), polygon
// p being vertices[starts[p]:starts[p + 1]] (closed implicitly).
#pragma once

#include <cstdint>

#include <bearing_core/core/checks.hpp>
#include <bearing_core/core/views.hpp>

namespace bearing::sim {

// Rounding slack (metres) of the contact tests (sensing.CONTACT_SLACK).
inline constexpr double CONTACT_SLACK = 1e-12;

// Packed obstacles: vertices (V, 2) and starts (k + 1,).
struct Obstacles {
    View2<const double> vertices;
    View1<const int64_t> starts;

    // Obstacles whose polygons' vertex ranges stay in `vertices` (the kernels index it
    // unchecked); std::invalid_argument naming the array otherwise.
    static Obstacles checked(View2<const double> vertices, View1<const int64_t> starts,
                             const char* vertices_name = "vertices",
                             const char* starts_name = "starts");
};

// The arrays of a kernel over landmarks (N, n, 2) seen from poses (N, 2), (N,) into out
// (N, n) agree in shape: std::invalid_argument naming the one that does not.
template <class T>
void check_landmark_rows(View3<const double> landmarks, View2<const double> positions,
                         View1<const double> headings, const View2<T>& out) {
    check_axis(landmarks, 2, 2, "landmarks");
    check_axis(positions, 0, landmarks.shape[0], "positions");
    check_axis(positions, 1, 2, "positions");
    check_axis(headings, 0, landmarks.shape[0], "headings");
    check_axis(out, 0, landmarks.shape[0], "out");
    check_axis(out, 1, landmarks.shape[1], "out");
}

double edge_entry(double x, double y, double dx, double dy, double ax, double ay, double bx,
                  double by, double margin);
double disc_entry(double x, double y, double dx, double dy, double cx, double cy, double r);
double free_length(double x, double y, double heading, const Obstacles& obstacles, double margin);
double cross(double ox, double oy, double ax, double ay, double bx, double by);
bool segments_cross(double px, double py, double qx, double qy, double ax, double ay, double bx,
                    double by);
bool on_segment(double ax, double ay, double bx, double by, double px, double py);
bool line_of_sight(double x, double y, double target_x, double target_y,
                   const Obstacles& obstacles);
bool visible(double x, double y, double heading, double target_x, double target_y, double half_fov,
             double max_range, const Obstacles& obstacles);
// Whether (x, y) lies inside the polygon vertices[first:last] (std::invalid_argument if
// that range leaves the vertices).
bool inside_polygon(double x, double y, View2<const double> vertices, int64_t first, int64_t last);
double segment_distance(double x, double y, double ax, double ay, double bx, double by);
double clearance(double x, double y, const Obstacles& obstacles);
// visible() for landmarks (N, n, 2) from poses (N, 2), (N,), into out (N, n).
void visible_rows(View3<const double> landmarks, View2<const double> positions,
                  View1<const double> headings, double half_fov, double max_range,
                  const Obstacles& obstacles, View2<bool> out);

}  // namespace bearing::sim
