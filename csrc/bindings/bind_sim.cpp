// Bindings of the simulator's kernels (csrc/sim/): the numba kernels of bearing_env/world.py
// and bearing_env/sensing.py, with their Python names, signatures and return conventions,
// so that those modules can re-export them unchanged.
#include <nanobind/nanobind.h>
#include <nanobind/stl/tuple.h>

#include <string>
#include <tuple>

#include <bearing_core/sim/sensing.hpp>
#include <bearing_core/sim/world.hpp>
#include "bindings/arrays.hpp"
#include "bindings/sim_args.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace {

using bearing::View1;
using bearing::View2;
using bearing::View3;
using bearing::bindings::obstacles_of;
using bearing::bindings::value_error;
using bearing::bindings::view_of;

using MoveTuple = std::tuple<double, double, double, bool>;

MoveTuple as_tuple(const bearing::sim::Move& move) {
    return {move.x, move.y, move.travelled, move.blocked};
}

// out (and every other array) must have the shape of the first: the kernels loop over it.
void check_same_shape(const std::array<int64_t, 2>& shape, const std::array<int64_t, 2>& other,
                      const char* name) {
    if (shape != other) {
        value_error(std::string(name) + " has shape (" + std::to_string(other[0]) + ", " +
                    std::to_string(other[1]) + "), expected (" + std::to_string(shape[0]) + ", " +
                    std::to_string(shape[1]) + ")");
    }
}

}  // namespace

void bind_sim(nb::module_& m) {
    namespace sim = bearing::sim;
    m.attr("CONTACT_SLACK") = sim::CONTACT_SLACK;  // bearing_env.sensing reads it

    // bearing_env/world.py
    m.def(
        "_add_wrapped",
        [](nb::handle true_bearings, nb::handle offsets, nb::handle out) {
            auto t = view_of<const double, 2>(true_bearings, "true_bearings");
            auto o = view_of<const double, 2>(offsets, "offsets");
            auto w = view_of<double, 2>(out, "out");
            check_same_shape(t.shape, o.shape, "offsets");
            check_same_shape(t.shape, w.shape, "out");
            nb::gil_scoped_release release;
            sim::add_wrapped(t, o, w);
        },
        "true_bearings"_a, "offsets"_a, "out"_a,
        "out = wrap(true_bearings + offsets), elementwise (N, n).");
    m.def(
        "_add_wrapped_with_outliers",
        [](nb::handle true_bearings, nb::handle offsets, nb::handle is_outlier,
           nb::handle replacement, nb::handle out) {
            auto t = view_of<const double, 2>(true_bearings, "true_bearings");
            auto o = view_of<const double, 2>(offsets, "offsets");
            auto b = view_of<const bool, 2>(is_outlier, "is_outlier");
            auto r = view_of<const double, 2>(replacement, "replacement");
            auto w = view_of<double, 2>(out, "out");
            check_same_shape(t.shape, o.shape, "offsets");
            check_same_shape(t.shape, b.shape, "is_outlier");
            check_same_shape(t.shape, r.shape, "replacement");
            check_same_shape(t.shape, w.shape, "out");
            nb::gil_scoped_release release;
            sim::add_wrapped_with_outliers(t, o, b, r, w);
        },
        "true_bearings"_a, "offsets"_a, "is_outlier"_a, "replacement"_a, "out"_a,
        "_add_wrapped with replacement[i, j] where is_outlier[i, j].");
    m.def("bearing", &sim::bearing, "landmark_x"_a, "landmark_y"_a, "x"_a, "y"_a, "heading"_a,
          "The noise-free bearing of a landmark from a pose, radians CCW from the heading.");
    m.def(
        "straight_move",
        [](double x, double y, double heading, double length, double width, double height,
           double margin, double min_baseline) {
            return as_tuple(
                sim::straight_move(x, y, heading, length, width, height, margin, min_baseline));
        },
        "x"_a, "y"_a, "heading"_a, "length"_a, "width"_a, "height"_a, "margin"_a, "min_baseline"_a,
        "One straight move stopped at the wall margin: (x, y, travelled, blocked).");
    m.def(
        "obstructed_move",
        [](double x, double y, double heading, double length,
           std::tuple<double, double, double, double> settings, nb::handle vertices,
           nb::handle starts) {
            const auto obstacles = obstacles_of(vertices, starts);
            const sim::MoveSettings move_settings{std::get<0>(settings), std::get<1>(settings),
                                                  std::get<2>(settings), std::get<3>(settings)};
            return as_tuple(sim::obstructed_move(x, y, heading, length, move_settings, obstacles));
        },
        "x"_a, "y"_a, "heading"_a, "length"_a, "settings"_a, "vertices"_a, "starts"_a,
        "straight_move that also stops margin short of the obstacles; settings is "
        "(width, height, margin, min_baseline).");
    m.def(
        "_true_bearings_into",
        [](nb::handle landmarks, nb::handle positions, nb::handle headings, nb::handle out) {
            auto l = view_of<const double, 3>(landmarks, "landmarks", {-1, -1, 2});
            const int64_t rows = l.shape[0];
            auto p = view_of<const double, 2>(positions, "positions", {rows, 2});
            auto h = view_of<const double, 1>(headings, "headings", {rows});
            auto w = view_of<double, 2>(out, "out");
            check_same_shape({l.shape[0], l.shape[1]}, w.shape, "out");
            nb::gil_scoped_release release;
            sim::true_bearings_into(l, p, h, w);
        },
        "landmarks"_a, "positions"_a, "headings"_a, "out"_a,
        "Noise-free bearings of landmarks (N, n, 2) from poses (N, 2), (N,) into out (N, n).");

    // bearing_env/sensing.py
    m.def("_edge_entry", &sim::edge_entry, "x"_a, "y"_a, "dx"_a, "dy"_a, "ax"_a, "ay"_a, "bx"_a,
          "by"_a, "margin"_a);
    m.def("_disc_entry", &sim::disc_entry, "x"_a, "y"_a, "dx"_a, "dy"_a, "cx"_a, "cy"_a, "r"_a);
    m.def(
        "free_length",
        [](double x, double y, double heading, nb::handle vertices, nb::handle starts,
           double margin) {
            return sim::free_length(x, y, heading, obstacles_of(vertices, starts), margin);
        },
        "x"_a, "y"_a, "heading"_a, "vertices"_a, "starts"_a, "margin"_a,
        "How far a robot can go along heading before its centre comes within margin of an "
        "obstacle; inf without contact.");
    m.def("_cross", &sim::cross, "ox"_a, "oy"_a, "ax"_a, "ay"_a, "bx"_a, "by"_a);
    m.def("segments_cross", &sim::segments_cross, "px"_a, "py"_a, "qx"_a, "qy"_a, "ax"_a, "ay"_a,
          "bx"_a, "by"_a, "Whether segments pq and ab share a point (touching counts).");
    m.def("_on_segment", &sim::on_segment, "ax"_a, "ay"_a, "bx"_a, "by"_a, "px"_a, "py"_a);
    m.def(
        "line_of_sight",
        [](double x, double y, double target_x, double target_y, nb::handle vertices,
           nb::handle starts) {
            return sim::line_of_sight(x, y, target_x, target_y, obstacles_of(vertices, starts));
        },
        "x"_a, "y"_a, "target_x"_a, "target_y"_a, "vertices"_a, "starts"_a,
        "Whether the segment from (x, y) to the target crosses no obstacle edge.");
    m.def(
        "visible",
        [](double x, double y, double heading, double target_x, double target_y, double half_fov,
           double max_range, nb::handle vertices, nb::handle starts) {
            return sim::visible(x, y, heading, target_x, target_y, half_fov, max_range,
                                obstacles_of(vertices, starts));
        },
        "x"_a, "y"_a, "heading"_a, "target_x"_a, "target_y"_a, "half_fov"_a, "max_range"_a,
        "vertices"_a, "starts"_a,
        "Whether a sensor at (x, y) facing heading sees the target (field of view, range, "
        "line of sight).");
    m.def(
        "inside_polygon",
        [](double x, double y, nb::handle vertices, int64_t first, int64_t last) {
            auto v = view_of<const double, 2>(vertices, "vertices", {-1, 2});
            if (first < last && (first < 0 || last > v.shape[0])) {
                value_error("first and last must lie in [0, " + std::to_string(v.shape[0]) +
                            "], got " + std::to_string(first) + " and " + std::to_string(last));
            }
            return sim::inside_polygon(x, y, v, first, last);
        },
        "x"_a, "y"_a, "vertices"_a, "first"_a, "last"_a,
        "Whether (x, y) lies inside the polygon vertices[first:last] (even-odd rule).");
    m.def("_segment_distance", &sim::segment_distance, "x"_a, "y"_a, "ax"_a, "ay"_a, "bx"_a,
          "by"_a);
    m.def(
        "clearance",
        [](double x, double y, nb::handle vertices, nb::handle starts) {
            return sim::clearance(x, y, obstacles_of(vertices, starts));
        },
        "x"_a, "y"_a, "vertices"_a, "starts"_a,
        "Distance from (x, y) to the nearest obstacle; 0 inside one, inf without.");
    m.def(
        "visible_rows",
        [](nb::handle landmarks, nb::handle positions, nb::handle headings, double half_fov,
           double max_range, nb::handle vertices, nb::handle starts, nb::handle out) {
            auto l = view_of<const double, 3>(landmarks, "landmarks", {-1, -1, 2});
            const int64_t rows = l.shape[0];
            auto p = view_of<const double, 2>(positions, "positions", {rows, 2});
            auto h = view_of<const double, 1>(headings, "headings", {rows});
            const auto obstacles = obstacles_of(vertices, starts);
            auto w = view_of<bool, 2>(out, "out");
            check_same_shape({l.shape[0], l.shape[1]}, w.shape, "out");
            nb::gil_scoped_release release;
            sim::visible_rows(l, p, h, half_fov, max_range, obstacles, w);
        },
        "landmarks"_a, "positions"_a, "headings"_a, "half_fov"_a, "max_range"_a, "vertices"_a,
        "starts"_a, "out"_a,
        "visible() for landmarks (N, n, 2) from poses (N, 2), (N,), into out (N, n).");
}
