// bearing_env/sensing.py's kernels (see sensing.hpp).
#include <bearing_core/sim/sensing.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <bearing_core/core/checks.hpp>
#include <bearing_core/core/pymath.hpp>

namespace bearing::sim {

namespace {
constexpr double INF = std::numeric_limits<double>::infinity();
}  // namespace

double edge_entry(double x, double y, double dx, double dy, double ax, double ay, double bx,
                  double by, double margin) {
    const double ex = bx - ax, ey = by - ay;
    const double length = std::hypot(ex, ey);
    if (length == 0.0) return INF;
    double best = INF;
    for (const double side : {1.0, -1.0}) {
        const double nx = -side * ey / length, ny = side * ex / length;
        const double approach = dx * nx + dy * ny;
        if (approach >= 0.0) continue;
        const double offset = (x - ax) * nx + (y - ay) * ny;
        if (offset < -CONTACT_SLACK) continue;
        const double t = std::max(0.0, (margin - offset) / approach);
        const double px = x + t * dx - ax, py = y + t * dy - ay;
        const double along = (px * ex + py * ey) / length;
        if (0.0 <= along && along <= length && t < best) best = t;
    }
    return best;
}

double disc_entry(double x, double y, double dx, double dy, double cx, double cy, double r) {
    const double px = x - cx, py = y - cy;
    const double b = px * dx + py * dy;
    if (b >= 0.0) return INF;
    const double c = px * px + py * py - r * r;
    if (c <= CONTACT_SLACK) return 0.0;
    const double disc = b * b - c;
    if (disc < 0.0) return INF;
    return -b - std::sqrt(disc);
}

double free_length(double x, double y, double heading, const Obstacles& obstacles, double margin) {
    const double dx = std::cos(heading), dy = std::sin(heading);
    const auto& vertices = obstacles.vertices;
    const auto& starts = obstacles.starts;
    double best = INF;
    for (int64_t p = 0; p < starts.shape[0] - 1; ++p) {
        const int64_t first = starts[p], last = starts[p + 1];
        for (int64_t k = first; k < last; ++k) {
            const int64_t following = k + 1 < last ? k + 1 : first;
            const double ax = vertices(k, 0), ay = vertices(k, 1);
            const double bx = vertices(following, 0), by = vertices(following, 1);
            best = std::min(best, edge_entry(x, y, dx, dy, ax, ay, bx, by, margin));
            best = std::min(best, disc_entry(x, y, dx, dy, ax, ay, margin));
        }
    }
    return best;
}

double cross(double ox, double oy, double ax, double ay, double bx, double by) {
    return (ax - ox) * (by - oy) - (ay - oy) * (bx - ox);
}

bool segments_cross(double px, double py, double qx, double qy, double ax, double ay, double bx,
                    double by) {
    const double d1 = cross(ax, ay, bx, by, px, py), d2 = cross(ax, ay, bx, by, qx, qy);
    const double d3 = cross(px, py, qx, qy, ax, ay), d4 = cross(px, py, qx, qy, bx, by);
    if (((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) &&
        ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))) {
        return true;
    }
    return (d1 == 0.0 && on_segment(ax, ay, bx, by, px, py)) ||
           (d2 == 0.0 && on_segment(ax, ay, bx, by, qx, qy)) ||
           (d3 == 0.0 && on_segment(px, py, qx, qy, ax, ay)) ||
           (d4 == 0.0 && on_segment(px, py, qx, qy, bx, by));
}

bool on_segment(double ax, double ay, double bx, double by, double px, double py) {
    return std::min(ax, bx) <= px && px <= std::max(ax, bx) && std::min(ay, by) <= py &&
           py <= std::max(ay, by);
}

bool line_of_sight(double x, double y, double target_x, double target_y,
                   const Obstacles& obstacles) {
    const auto& vertices = obstacles.vertices;
    const auto& starts = obstacles.starts;
    for (int64_t p = 0; p < starts.shape[0] - 1; ++p) {
        const int64_t first = starts[p], last = starts[p + 1];
        for (int64_t k = first; k < last; ++k) {
            const int64_t following = k + 1 < last ? k + 1 : first;
            if (segments_cross(x, y, target_x, target_y, vertices(k, 0), vertices(k, 1),
                               vertices(following, 0), vertices(following, 1))) {
                return false;
            }
        }
    }
    return true;
}

bool visible(double x, double y, double heading, double target_x, double target_y, double half_fov,
             double max_range, const Obstacles& obstacles) {
    if (half_fov < PI) {
        const double angle = wrap(std::atan2(target_y - y, target_x - x) - heading);
        if (std::fabs(angle) > half_fov) return false;
    }
    if (max_range < INF && std::hypot(target_x - x, target_y - y) > max_range) return false;
    return line_of_sight(x, y, target_x, target_y, obstacles);
}

bool inside_polygon(double x, double y, View2<const double> vertices, int64_t first, int64_t last) {
    check_axis(vertices, 1, 2, "vertices");
    if (first < last && (first < 0 || last > vertices.shape[0])) {
        invalid_argument("first and last must lie in [0, " + std::to_string(vertices.shape[0]) +
                         "], got " + std::to_string(first) + " and " + std::to_string(last));
    }
    bool inside = false;
    for (int64_t k = first; k < last; ++k) {
        const int64_t following = k + 1 < last ? k + 1 : first;
        const double ax = vertices(k, 0), ay = vertices(k, 1);
        const double bx = vertices(following, 0), by = vertices(following, 1);
        if ((ay > y) != (by > y) && x < ax + (y - ay) * (bx - ax) / (by - ay)) inside = !inside;
    }
    return inside;
}

double segment_distance(double x, double y, double ax, double ay, double bx, double by) {
    const double ex = bx - ax, ey = by - ay;
    const double squared = ex * ex + ey * ey;
    const double t = squared == 0.0
                         ? 0.0
                         : std::min(std::max(((x - ax) * ex + (y - ay) * ey) / squared, 0.0), 1.0);
    return std::hypot(x - ax - t * ex, y - ay - t * ey);
}

Obstacles Obstacles::checked(View2<const double> vertices, View1<const int64_t> starts,
                             const char* vertices_name, const char* starts_name) {
    check_axis(vertices, 1, 2, vertices_name);
    const int64_t count = vertices.shape[0];
    for (int64_t p = 0; p + 1 < starts.shape[0]; ++p) {
        const int64_t first = starts[p], last = starts[p + 1];
        if (first < last && (first < 0 || last > count)) {
            invalid_argument(std::string(starts_name) + " indexes past the " +
                             std::to_string(count) + " obstacle vertices (polygon " +
                             std::to_string(p) + ": " + std::to_string(first) + " to " +
                             std::to_string(last) + ")");
        }
    }
    return {vertices, starts};
}

double clearance(double x, double y, const Obstacles& obstacles) {
    const auto& vertices = obstacles.vertices;
    const auto& starts = obstacles.starts;
    double best = INF;
    for (int64_t p = 0; p < starts.shape[0] - 1; ++p) {
        const int64_t first = starts[p], last = starts[p + 1];
        if (inside_polygon(x, y, vertices, first, last)) return 0.0;
        for (int64_t k = first; k < last; ++k) {
            const int64_t following = k + 1 < last ? k + 1 : first;
            best = std::min(best, segment_distance(x, y, vertices(k, 0), vertices(k, 1),
                                                   vertices(following, 0), vertices(following, 1)));
        }
    }
    return best;
}

void visible_rows(View3<const double> landmarks, View2<const double> positions,
                  View1<const double> headings, double half_fov, double max_range,
                  const Obstacles& obstacles, View2<bool> out) {
    check_landmark_rows(landmarks, positions, headings, out);
    for (int64_t i = 0; i < landmarks.shape[0]; ++i) {
        for (int64_t j = 0; j < landmarks.shape[1]; ++j) {
            out(i, j) = visible(positions(i, 0), positions(i, 1), headings[i], landmarks(i, j, 0),
                                landmarks(i, j, 1), half_fov, max_range, obstacles);
        }
    }
}

}  // namespace bearing::sim
