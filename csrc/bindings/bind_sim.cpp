// Bindings of the simulator's kernels (csrc/sim/): the numba kernels of bearing_env/world.py
// and bearing_env/sensing.py, with their Python names, signatures and return conventions,
// so that those modules can re-export them unchanged.
#include <nanobind/nanobind.h>
#include <nanobind/stl/tuple.h>

#include <string>
#include <tuple>

#include <bearing_core/sim/sensing.hpp>
#include <bearing_core/sim/world.hpp>
#include "bindings/def.hpp"

namespace nb = nanobind;
using namespace nb::literals;
namespace sim = bearing::sim;

// A move as Python sees it: world.straight_move's tuple (x, y, travelled, blocked).
template <>
struct nb::detail::type_caster<sim::Move> {
    NB_TYPE_CASTER(sim::Move, const_name("tuple[float, float, float, bool]"))
    static handle from_cpp(const sim::Move& move, rv_policy policy, cleanup_list* list) noexcept {
        return make_caster<std::tuple<double, double, double, bool>>::from_cpp(
            std::make_tuple(move.x, move.y, move.travelled, move.blocked), policy, list);
    }
};

namespace bearing::bindings {
// Packed obstacles from two Python arguments, vertices and starts (checked, named).
template <>
struct Param<sim::Obstacles> {
    using Args = std::tuple<nb::handle, nb::handle>;
    static sim::Obstacles from(Taken& taken, size_t at, nb::handle vertices, nb::handle starts) {
        const auto vertex_view = Param<View2<const double>>::from(taken, at, vertices);
        return sim::Obstacles::checked(vertex_view,
                                       Param<View1<const int64_t>>::from(taken, at + 1, starts),
                                       taken.names[at], taken.names[at + 1]);
    }
};
// obstructed_move's settings: a tuple (width, height, margin, min_baseline).
template <>
struct Param<sim::MoveSettings> {
    using Args = std::tuple<std::tuple<double, double, double, double>>;
    static sim::MoveSettings from(Taken&, size_t, std::tuple<double, double, double, double> s) {
        const auto [width, height, margin, min_baseline] = s;
        return {width, height, margin, min_baseline};
    }
};
}  // namespace bearing::bindings

void bind_sim(nb::module_& m) {
    using bearing::bindings::def;
    using bearing::bindings::def_released;
    m.attr("CONTACT_SLACK") = sim::CONTACT_SLACK;  // bearing_env.sensing reads it

    // bearing_env/world.py
    def_released(m, "_add_wrapped", &sim::add_wrapped, "true_bearings"_a, "offsets"_a, "out"_a,
                 "out = wrap(true_bearings + offsets), elementwise (N, n).");
    def_released(m, "_add_wrapped_with_outliers", &sim::add_wrapped_with_outliers,
                 "true_bearings"_a, "offsets"_a, "is_outlier"_a, "replacement"_a, "out"_a,
                 "_add_wrapped with replacement[i, j] where is_outlier[i, j].");
    def(m, "bearing", &sim::bearing, "landmark_x"_a, "landmark_y"_a, "x"_a, "y"_a, "heading"_a,
        "The noise-free bearing of a landmark from a pose, radians CCW from the heading.");
    def(m, "straight_move", &sim::straight_move, "x"_a, "y"_a, "heading"_a, "length"_a, "width"_a,
        "height"_a, "margin"_a, "min_baseline"_a,
        "One straight move stopped at the wall margin: (x, y, travelled, blocked).");
    def(m, "obstructed_move", &sim::obstructed_move, "x"_a, "y"_a, "heading"_a, "length"_a,
        "settings"_a, "vertices"_a, "starts"_a,
        "straight_move that also stops margin short of the obstacles; settings is "
        "(width, height, margin, min_baseline).");
    def_released(
        m, "_true_bearings_into", &sim::true_bearings_into, "landmarks"_a, "positions"_a,
        "headings"_a, "out"_a,
        "Noise-free bearings of landmarks (N, n, 2) from poses (N, 2), (N,) into out (N, n).");

    // bearing_env/sensing.py
    def(m, "_edge_entry", &sim::edge_entry, "x"_a, "y"_a, "dx"_a, "dy"_a, "ax"_a, "ay"_a, "bx"_a,
        "by"_a, "margin"_a);
    def(m, "_disc_entry", &sim::disc_entry, "x"_a, "y"_a, "dx"_a, "dy"_a, "cx"_a, "cy"_a, "r"_a);
    def(m, "free_length", &sim::free_length, "x"_a, "y"_a, "heading"_a, "vertices"_a, "starts"_a,
        "margin"_a,
        "How far a robot can go along heading before its centre comes within margin of an "
        "obstacle; inf without contact.");
    def(m, "_cross", &sim::cross, "ox"_a, "oy"_a, "ax"_a, "ay"_a, "bx"_a, "by"_a);
    def(m, "segments_cross", &sim::segments_cross, "px"_a, "py"_a, "qx"_a, "qy"_a, "ax"_a, "ay"_a,
        "bx"_a, "by"_a, "Whether segments pq and ab share a point (touching counts).");
    def(m, "_on_segment", &sim::on_segment, "ax"_a, "ay"_a, "bx"_a, "by"_a, "px"_a, "py"_a);
    def(m, "line_of_sight", &sim::line_of_sight, "x"_a, "y"_a, "target_x"_a, "target_y"_a,
        "vertices"_a, "starts"_a,
        "Whether the segment from (x, y) to the target crosses no obstacle edge.");
    def(m, "visible", &sim::visible, "x"_a, "y"_a, "heading"_a, "target_x"_a, "target_y"_a,
        "half_fov"_a, "max_range"_a, "vertices"_a, "starts"_a,
        "Whether a sensor at (x, y) facing heading sees the target (field of view, range, "
        "line of sight).");
    def(m, "inside_polygon", &sim::inside_polygon, "x"_a, "y"_a, "vertices"_a, "first"_a, "last"_a,
        "Whether (x, y) lies inside the polygon vertices[first:last] (even-odd rule).");
    def(m, "_segment_distance", &sim::segment_distance, "x"_a, "y"_a, "ax"_a, "ay"_a, "bx"_a,
        "by"_a);
    def(m, "clearance", &sim::clearance, "x"_a, "y"_a, "vertices"_a, "starts"_a,
        "Distance from (x, y) to the nearest obstacle; 0 inside one, inf without.");
    def_released(m, "visible_rows", &sim::visible_rows, "landmarks"_a, "positions"_a, "headings"_a,
                 "half_fov"_a, "max_range"_a, "vertices"_a, "starts"_a, "out"_a,
                 "visible() for landmarks (N, n, 2) from poses (N, 2), (N,), into out (N, n).");
}
