// Bindings of the polygon and frame kernels (csrc/include/bearing_core/slam/checked.hpp,
// the kernels of polygons.hpp and frames.hpp over checked views), for tests and one-off
// geometry: the same Python signatures and return conventions as the numba kernels of
// bearing_env.slam.kernels (complex128 arrays in, `out` arrays written in place, the same
// return tuples), so that the package can re-export either.
#include <nanobind/nanobind.h>
#include <nanobind/stl/tuple.h>

#include <cstdint>
#include <tuple>

#include <bearing_core/slam/checked.hpp>
#include <bearing_core/slam/common.hpp>
#include "bindings/def.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace {

using namespace bearing::slam::checked;
using bearing::bindings::Bool;
using bearing::bindings::extent_of;
using bearing::bindings::view_of;

// transfer_region with frames.py's FrameChange tuple (a1, n1, a2, n2, h1, inv_d, n_pairs,
// conservative, distance, delta1, delta2).
int64_t transfer_region_of(In target, int64_t n_target, nb::handle frame, Out cloud, Out hull,
                           Out out) {
    std::tuple<nb::handle, int64_t, nb::handle, int64_t, nb::handle, nb::handle, int64_t, Bool,
               double, double, double>
        f;
    if (!PyTuple_Check(frame.ptr()) || !nb::try_cast(frame, f)) {
        bearing::bindings::type_error(
            "frame must be a FrameChange (a tuple of 11: a1, n1, a2, n2, h1, inv_d, n_pairs, "
            "conservative, distance, delta1, delta2)");
    }
    const auto [a1_obj, n1, a2_obj, n2, h1_obj, inv_d_obj, n_pairs, conservative, distance, delta1,
                delta2] = f;
    const In a1 = view_of<const bearing::cplx, 1>(a1_obj, "frame.a1");
    const In a2 = view_of<const bearing::cplx, 1>(a2_obj, "frame.a2");
    const In h1 = view_of<const bearing::cplx, 1>(h1_obj, "frame.h1");
    const In inv_d = view_of<const bearing::cplx, 1>(inv_d_obj, "frame.inv_d");
    bearing::bindings::require_apart({extent_of(a1, "frame.a1"), extent_of(a2, "frame.a2"),
                                      extent_of(h1, "frame.h1"), extent_of(inv_d, "frame.inv_d"),
                                      extent_of(cloud, "cloud"), extent_of(hull, "hull"),
                                      extent_of(out, "out")});
    return transfer_region(target, n_target,
                           frame_change(a1, n1, a2, n2, h1, inv_d, n_pairs, conservative.value,
                                        distance, delta1, delta2),
                           cloud, hull, out);
}

std::tuple<int64_t, int64_t, double, double, double> frame_plan_of(In a1, int64_t n1, In a2,
                                                                   int64_t n2, bool conservative,
                                                                   int64_t edge_samples) {
    const auto p = frame_plan(a1, n1, a2, n2, conservative, edge_samples);
    return {p.status, p.per_edge, p.distance, p.delta1, p.delta2};
}

}  // namespace

void bind_slam_geometry(nb::module_& m) {
    using bearing::cplx;
    using bearing::bindings::def;
    // common.py and numerics.py's scalar helpers.
    def(m, "cross", &bearing::cross, "a"_a, "b"_a, "2-D cross product a.x * b.y - a.y * b.x.");
    def(m, "dot", &bearing::dot, "a"_a, "b"_a, "2-D dot product.");
    def(m, "wrap", &bearing::wrap, "angle"_a, "An angle wrapped to [-pi, pi).");
    def(m, "scale_of", &scale_of, "poly"_a, "n"_a,
        "(bounding-box size, largest coordinate magnitude) of poly[:n].");
    def(m, "tolerance_of", &bearing::slam::tolerance_of, "size"_a, "magnitude"_a,
        "Distance below which two features count as touching, for polygons of that scale.");
    // polygons.py
    def(m, "convex_hull", &convex_hull, "points"_a, "n_points"_a, "out"_a,
        "Convex hull of points[:n_points] into out (n_points + 1); returns its vertex count.");
    def(m, "small_convex_hull", &small_convex_hull, "points"_a, "n_points"_a, "out"_a, "tol"_a,
        "Andrew's monotone chain of points[:n_points] into out (n_points + 1).");
    def(m, "small_hull_indices", &small_hull_indices, "points"_a, "n_points"_a, "out"_a, "tol"_a,
        "small_convex_hull as indices (int64 out, n_points + 1).");
    def(m, "area_centroid", &area_centroid, "poly"_a, "n"_a,
        "(area, centroid) of a convex polygon (the vertex mean if degenerate).");
    def(m, "contains_point", &contains_point, "poly"_a, "n"_a, "point"_a, "relative"_a,
        "Whether point lies in the convex polygon poly[:n], to within relative * its size.");
    def(m, "polygon_distance", &polygon_distance, "p"_a, "n_p"_a, "q"_a, "n_q"_a,
        "Distance between two small convex polygons; 0 if they touch or overlap.");
    def(m, "longest_edge", &longest_edge, "poly"_a, "n"_a, "Length of the longest edge.");
    def(m, "simplify", &simplify, "poly"_a, "n"_a, "tol"_a,
        "Drop repeated and collinear vertices in place; returns the new count.");
    def(m, "drop_edges_outward", &drop_edges_outward, "poly"_a, "n"_a, "capacity"_a,
        "Reduce a convex polygon in place to at most capacity vertices by removing edges.");
    def(m, "clip_convex", &clip_convex, "subject"_a, "n_subject"_a, "clipper"_a, "n_clipper"_a,
        "out"_a, "work"_a,
        "Intersection of two convex polygons into out (out and work hold SCRATCH).");
    def(m, "offset_outward", &offset_outward, "poly"_a, "n"_a, "radius"_a, "out"_a,
        "Every edge of a convex polygon moved outward by radius, into out (n + 3).");
    // frames.py
    def(m, "cone_region", &cone_region, "a"_a, "b"_a, "epsilon"_a, "out"_a,
        "(n, status): the FR region of a landmark seen at bearings a and b, into out (4).");
    def(m, "boundary_samples", &boundary_samples, "poly"_a, "n"_a, "per_edge"_a, "out"_a,
        "per_edge evenly spaced points on each edge, vertices included.");
    def(m, "frame_plan", &frame_plan_of, "a1"_a, "n1"_a, "a2"_a, "n2"_a, "conservative"_a,
        "edge_samples"_a, "(status, per_edge, distance, delta1, delta2) of a frame change.");
    def(m, "sample_hypotheses", &sample_hypotheses, "a1"_a, "n1"_a, "a2"_a, "n2"_a, "per_edge"_a,
        "h1"_a, "inv_d"_a, "Hypothesis pairs (h1, 1 / (h2 - h1)); returns their count.");
    def(m, "transfer_region", &transfer_region_of, "target"_a, "n_target"_a, "frame"_a, "cloud"_a,
        "hull"_a, "out"_a,
        "The FL region of an FR region into out (SCRATCH); returns its vertex count.");
    def(m, "transfer_polygon", &transfer_polygon, "target"_a, "a1"_a, "a2"_a, "transfer"_a,
        "edge_samples"_a, "out"_a,
        "(status, n): one FR region's change of frames as the update runs it, into out "
        "(SCRATCH).");
    def(m, "sub_square_growths", &sub_square_growths, "target"_a, "a1"_a, "a2"_a, "per_edge"_a,
        "out"_a,
        "(m1, m2): the local bound of every target point and sub-square into out "
        "(float64, n_target * m1 * m2).");
}
