// Bindings of the polygon and frame kernels (csrc/include/bearing_core/slam/polygons.hpp,
// frames.hpp), for tests and one-off geometry: the same Python signatures and return conventions as
// the numba kernels of bearing_env.slam.kernels (complex128 arrays in, `out` arrays written in
// place, the same return tuples), so that the package can re-export either.
//
// Every array is checked (dtype, dimensions, C-contiguity, writeability), and every count
// against the arrays it indexes: a bad argument raises TypeError or ValueError naming it,
// an input beyond a kernel's fixed capacity raises CapacityError, never a crash. A
// kernel that reads element 0 whatever its count (scale_of, area_centroid, ...) needs an
// array of at least one element, as numba does to stay in bounds.
#include <nanobind/nanobind.h>

#include <cstdint>
#include <memory>
#include <string>

#include <bearing_core/slam/common.hpp>
#include <bearing_core/slam/frames.hpp>
#include <bearing_core/slam/local_bound.hpp>
#include <bearing_core/slam/polygons.hpp>
#include <bearing_core/slam/scratch.hpp>
#include <bearing_core/slam/update.hpp>
#include "bindings/arrays.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace {

using bearing::cplx;
using bearing::View1;
using bearing::bindings::extent_of;
using bearing::bindings::require_apart;
using bearing::bindings::value_error;
using bearing::bindings::view_of;

using In = View1<const cplx>;
using Out = View1<cplx>;

In input(nb::handle obj, const char* name) { return view_of<const cplx, 1>(obj, name); }
Out output(nb::handle obj, const char* name) { return view_of<cplx, 1>(obj, name); }

// A count `n` (argument `name`) of elements of an array `array` of `length` elements:
// 0 <= n <= length, and the array holds at least `least` elements.
void check_count(int64_t n, const char* name, int64_t length, const char* array,
                 int64_t least = 0) {
    if (n < 0) value_error(std::string(name) + " must not be negative, got " + std::to_string(n));
    if (n > length) {
        value_error(std::string(name) + " = " + std::to_string(n) + " exceeds the length of " +
                    array + " (" + std::to_string(length) + ")");
    }
    if (length < least) {
        value_error(std::string(array) + " must hold at least " + std::to_string(least) +
                    " points, it has " + std::to_string(length));
    }
}

// An output array `array` of `length` elements must hold `needed`.
void check_room(int64_t needed, int64_t length, const char* array) {
    if (length < needed) {
        value_error(std::string(array) + " must hold at least " + std::to_string(needed) +
                    " elements, it has " + std::to_string(length));
    }
}

// n * m without overflow, for counts already checked against array lengths.
int64_t product(int64_t n, int64_t m) {
    if (n <= 0 || m <= 0) return 0;
    if (n > INT64_MAX / m) return INT64_MAX;
    return n * m;
}

cplx complex_of(nb::handle obj, const char* name) {
    const Py_complex z = PyComplex_AsCComplex(obj.ptr());
    if (z.real == -1.0 && PyErr_Occurred()) {
        PyErr_Clear();
        bearing::bindings::type_error(std::string(name) + " must be a complex number, not " +
                                      nb::type_name(obj.type()).c_str());
    }
    return {z.real, z.imag};
}

// A bool argument: Python's or numpy's (numba takes both).
bool bool_of(nb::handle obj, const char* name) {
    if (PyBool_Check(obj.ptr())) return obj.ptr() == Py_True;
    if (obj.type().is(nb::module_::import_("numpy").attr("bool_"))) {
        return PyObject_IsTrue(obj.ptr()) == 1;
    }
    bearing::bindings::type_error(std::string(name) + " must be a bool, not " +
                                  nb::type_name(obj.type()).c_str());
}

nb::object py_complex(cplx z) { return nb::steal(PyComplex_FromDoubles(z.re, z.im)); }

// --------------------------------------------------------------------------------------
// common.py
// --------------------------------------------------------------------------------------

nb::tuple scale_of(nb::handle poly_obj, int64_t n) {
    const In poly = input(poly_obj, "poly");
    check_count(n, "n", poly.shape[0], "poly", 1);
    const auto [size, magnitude] = bearing::slam::scale_of(poly.data, n);
    return nb::make_tuple(size, magnitude);
}

// --------------------------------------------------------------------------------------
// polygons.py
// --------------------------------------------------------------------------------------

int64_t convex_hull(nb::handle points_obj, int64_t n_points, nb::handle out_obj) {
    const In points = input(points_obj, "points");
    const Out out = output(out_obj, "out");
    check_count(n_points, "n_points", points.shape[0], "points");
    check_room(n_points + 1, out.shape[0], "out");
    require_apart({extent_of(points, "points"), extent_of(out, "out")});
    return bearing::slam::convex_hull(points.data, n_points, out.data);
}

int64_t small_convex_hull(nb::handle points_obj, int64_t n_points, nb::handle out_obj, double tol) {
    const In points = input(points_obj, "points");
    const Out out = output(out_obj, "out");
    check_count(n_points, "n_points", points.shape[0], "points");
    check_room(n_points + 1, out.shape[0], "out");
    require_apart({extent_of(points, "points"), extent_of(out, "out")});
    return bearing::slam::small_convex_hull(points.data, n_points, out.data, tol);
}

int64_t small_hull_indices(nb::handle points_obj, int64_t n_points, nb::handle out_obj,
                           double tol) {
    const In points = input(points_obj, "points");
    const View1<int64_t> out = view_of<int64_t, 1>(out_obj, "out");
    check_count(n_points, "n_points", points.shape[0], "points");
    check_room(n_points + 1, out.shape[0], "out");
    require_apart({extent_of(points, "points"), extent_of(out, "out")});
    return bearing::slam::small_hull_indices(points.data, n_points, out.data, tol);
}

nb::tuple area_centroid(nb::handle poly_obj, int64_t n) {
    const In poly = input(poly_obj, "poly");
    check_count(n, "n", poly.shape[0], "poly", 1);
    const auto [area, centroid] = bearing::slam::area_centroid(poly.data, n);
    return nb::make_tuple(area, py_complex(centroid));
}

bool contains_point(nb::handle poly_obj, int64_t n, nb::handle point, double relative) {
    const In poly = input(poly_obj, "poly");
    check_count(n, "n", poly.shape[0], "poly", 1);
    return bearing::slam::contains_point(poly.data, n, complex_of(point, "point"), relative);
}

double polygon_distance(nb::handle p_obj, int64_t n_p, nb::handle q_obj, int64_t n_q) {
    const In p = input(p_obj, "p");
    const In q = input(q_obj, "q");
    check_count(n_p, "n_p", p.shape[0], "p", 1);
    check_count(n_q, "n_q", q.shape[0], "q", 1);
    return bearing::slam::polygon_distance(p.data, n_p, q.data, n_q);
}

double longest_edge(nb::handle poly_obj, int64_t n) {
    const In poly = input(poly_obj, "poly");
    check_count(n, "n", poly.shape[0], "poly");
    return bearing::slam::longest_edge(poly.data, n);
}

int64_t simplify(nb::handle poly_obj, int64_t n, double tol) {
    const Out poly = output(poly_obj, "poly");
    check_count(n, "n", poly.shape[0], "poly");
    return bearing::slam::simplify(poly.data, n, tol);
}

int64_t drop_edges_outward(nb::handle poly_obj, int64_t n, int64_t capacity) {
    const Out poly = output(poly_obj, "poly");
    check_count(n, "n", poly.shape[0], "poly");
    return bearing::slam::drop_edges_outward(poly.data, n, capacity);
}

int64_t clip_convex(nb::handle subject_obj, int64_t n_subject, nb::handle clipper_obj,
                    int64_t n_clipper, nb::handle out_obj, nb::handle work_obj) {
    const In subject = input(subject_obj, "subject");
    const In clipper = input(clipper_obj, "clipper");
    const Out out = output(out_obj, "out");
    const Out work = output(work_obj, "work");
    check_count(n_subject, "n_subject", subject.shape[0], "subject", 1);
    check_count(n_clipper, "n_clipper", clipper.shape[0], "clipper", 1);
    check_room(bearing::slam::SCRATCH, out.shape[0], "out");
    check_room(bearing::slam::SCRATCH, work.shape[0], "work");
    require_apart({extent_of(subject, "subject"), extent_of(clipper, "clipper"),
                   extent_of(out, "out"), extent_of(work, "work")});
    return bearing::slam::clip_convex(subject.data, n_subject, clipper.data, n_clipper, out.data,
                                      work.data);
}

int64_t offset_outward(nb::handle poly_obj, int64_t n, double radius, nb::handle out_obj) {
    const In poly = input(poly_obj, "poly");
    const Out out = output(out_obj, "out");
    check_count(n, "n", poly.shape[0], "poly");
    if (n < 1) value_error("offset_outward needs n >= 1");
    check_room(n + 3, out.shape[0], "out");
    require_apart({extent_of(poly, "poly"), extent_of(out, "out")});
    return bearing::slam::offset_outward(poly.data, n, radius, out.data);
}

// --------------------------------------------------------------------------------------
// frames.py
// --------------------------------------------------------------------------------------

nb::tuple cone_region(double a, double b, double epsilon, nb::handle out_obj) {
    const Out out = output(out_obj, "out");
    check_room(bearing::slam::FR_VERTICES, out.shape[0], "out");
    const auto [n, status] = bearing::slam::cone_region(a, b, epsilon, out.data);
    return nb::make_tuple(n, status);
}

int64_t boundary_samples(nb::handle poly_obj, int64_t n, int64_t per_edge, nb::handle out_obj) {
    const In poly = input(poly_obj, "poly");
    const Out out = output(out_obj, "out");
    check_count(n, "n", poly.shape[0], "poly");
    check_room(product(n, per_edge), out.shape[0], "out");
    require_apart({extent_of(poly, "poly"), extent_of(out, "out")});
    return bearing::slam::boundary_samples(poly.data, n, per_edge, out.data);
}

nb::tuple frame_plan(nb::handle a1_obj, int64_t n1, nb::handle a2_obj, int64_t n2,
                     nb::handle conservative, int64_t edge_samples) {
    const In a1 = input(a1_obj, "a1");
    const In a2 = input(a2_obj, "a2");
    check_count(n1, "n1", a1.shape[0], "a1", 1);
    check_count(n2, "n2", a2.shape[0], "a2", 1);
    const bearing::slam::FramePlan plan = bearing::slam::frame_plan(
        a1.data, n1, a2.data, n2, bool_of(conservative, "conservative"), edge_samples);
    return nb::make_tuple(plan.status, plan.per_edge, plan.distance, plan.delta1, plan.delta2);
}

int64_t sample_hypotheses(nb::handle a1_obj, int64_t n1, nb::handle a2_obj, int64_t n2,
                          int64_t per_edge, nb::handle h1_obj, nb::handle inv_d_obj) {
    const In a1 = input(a1_obj, "a1");
    const In a2 = input(a2_obj, "a2");
    const Out h1 = output(h1_obj, "h1");
    const Out inv_d = output(inv_d_obj, "inv_d");
    check_count(n1, "n1", a1.shape[0], "a1");
    check_count(n2, "n2", a2.shape[0], "a2");
    // The kernel raises CapacityError beyond MAX_SAMPLES samples per region.
    const int64_t samples = bearing::slam::MAX_SAMPLES;
    if (product(n1, per_edge) <= samples && product(n2, per_edge) <= samples) {
        const int64_t pairs = product(product(n1, per_edge), product(n2, per_edge));
        check_room(pairs, h1.shape[0], "h1");
        check_room(pairs, inv_d.shape[0], "inv_d");
    }
    require_apart(
        {extent_of(a1, "a1"), extent_of(a2, "a2"), extent_of(h1, "h1"), extent_of(inv_d, "inv_d")});
    return bearing::slam::sample_hypotheses(a1.data, n1, a2.data, n2, per_edge, h1.data,
                                            inv_d.data);
}

int64_t transfer_region(nb::handle target_obj, int64_t n_target, nb::handle frame_obj,
                        nb::handle cloud_obj, nb::handle hull_obj, nb::handle out_obj) {
    const In target = input(target_obj, "target");
    check_count(n_target, "n_target", target.shape[0], "target");
    if (!PyTuple_Check(frame_obj.ptr()) || PyTuple_GET_SIZE(frame_obj.ptr()) != 11) {
        bearing::bindings::type_error(
            "frame must be a FrameChange (a tuple of 11: a1, n1, a2, n2, h1, inv_d, n_pairs, "
            "conservative, distance, delta1, delta2)");
    }
    const nb::tuple frame = nb::borrow<nb::tuple>(frame_obj);
    const In a1 = input(frame[0], "frame.a1");
    const In a2 = input(frame[2], "frame.a2");
    const In h1 = input(frame[4], "frame.h1");
    const In inv_d = input(frame[5], "frame.inv_d");
    bearing::slam::FrameChange change;
    try {
        change.n1 = nb::cast<int64_t>(frame[1]);
        change.n2 = nb::cast<int64_t>(frame[3]);
        change.n_pairs = nb::cast<int64_t>(frame[6]);
        change.distance = nb::cast<double>(frame[8]);
        change.delta1 = nb::cast<double>(frame[9]);
        change.delta2 = nb::cast<double>(frame[10]);
    } catch (const nb::cast_error&) {
        bearing::bindings::type_error(
            "frame's n1, n2 and n_pairs must be ints, its distance, delta1 and delta2 floats");
    }
    change.conservative = bool_of(frame[7], "frame.conservative");
    check_count(change.n1, "frame.n1", a1.shape[0], "frame.a1");
    check_count(change.n2, "frame.n2", a2.shape[0], "frame.a2");
    check_count(change.n_pairs, "frame.n_pairs", h1.shape[0], "frame.h1");
    check_count(change.n_pairs, "frame.n_pairs", inv_d.shape[0], "frame.inv_d");
    change.a1 = a1.data;
    change.a2 = a2.data;
    change.h1 = h1.data;
    change.inv_d = inv_d.data;
    const Out cloud = output(cloud_obj, "cloud");
    const Out hull = output(hull_obj, "hull");
    const Out out = output(out_obj, "out");
    const int64_t k = product(n_target, change.n_pairs);
    // Beyond MAX_CLOUD the kernel raises CapacityError before touching the arrays.
    if (k <= bearing::slam::MAX_CLOUD) {
        check_room(k, cloud.shape[0], "cloud");
        check_room(k + 1, hull.shape[0], "hull");
        check_room(bearing::slam::SCRATCH, out.shape[0], "out");
    }
    require_apart({extent_of(target, "target"), extent_of(a1, "frame.a1"),
                   extent_of(a2, "frame.a2"), extent_of(h1, "frame.h1"),
                   extent_of(inv_d, "frame.inv_d"), extent_of(cloud, "cloud"),
                   extent_of(hull, "hull"), extent_of(out, "out")});
    return bearing::slam::transfer_region(target.data, n_target, change, cloud.data, hull.data,
                                          out.data);
}

// The FR regions of L1 and L2 for transfer_polygon and sub_square_growths: 1 to
// FR_VERTICES vertices each.
In small_region(nb::handle obj, const char* name) {
    const In region = input(obj, name);
    if (region.shape[0] < 1 || region.shape[0] > bearing::slam::FR_VERTICES) {
        value_error(std::string(name) + " must have 1 to " +
                    std::to_string(bearing::slam::FR_VERTICES) + " vertices, it has " +
                    std::to_string(region.shape[0]));
    }
    return region;
}

void check_edge_samples(int64_t edge_samples, const char* name) {
    if (edge_samples < 1 || edge_samples > bearing::slam::MAX_EDGE_SAMPLES) {
        value_error(std::string(name) + " must be in [1, " +
                    std::to_string(bearing::slam::MAX_EDGE_SAMPLES) + "], got " +
                    std::to_string(edge_samples));
    }
}

// One FR region's whole change of frames for one movement, as the update runs it:
// frame_plan, the hypotheses, the sub-squares (TRANSFER_CONSERVATIVE) and transfer_region.
nb::tuple transfer_polygon(nb::handle target_obj, nb::handle a1_obj, nb::handle a2_obj,
                           int64_t transfer, int64_t edge_samples, nb::handle out_obj) {
    namespace slam = bearing::slam;
    const In target = input(target_obj, "target");
    const In a1 = small_region(a1_obj, "a1");
    const In a2 = small_region(a2_obj, "a2");
    const Out out = output(out_obj, "out");
    if (target.shape[0] < 1) value_error("target must hold at least one point");
    if (!slam::valid_transfer(transfer)) {
        value_error(
            "transfer must be TRANSFER_CONSERVATIVE (0), TRANSFER_PAPER (1) or "
            "TRANSFER_CONSERVATIVE_GLOBAL (2), got " +
            std::to_string(transfer));
    }
    check_edge_samples(edge_samples, "edge_samples");
    check_room(slam::SCRATCH, out.shape[0], "out");
    // The thread's reused buffers (every slot used is written first): a fresh Buffers
    // would zero its 260 KB on every call.
    slam::Buffers& buf = slam::thread_buffers();
    slam::FrameChange frame;
    const int64_t status = slam::change_of_frames(a1.data, a1.shape[0], a2.data, a2.shape[0],
                                                  transfer, edge_samples, buf, frame);
    if (status != slam::FRAME_OK) return nb::make_tuple(status, 0);
    slam::Scratch& scratch = buf.scratch;
    const int64_t n = slam::transfer_region(target.data, target.shape[0], frame, scratch.cloud,
                                            scratch.hull, scratch.fresh);
    check_room(n, out.shape[0], "out");
    for (int64_t v = 0; v < n; ++v) out.data[v] = scratch.fresh[v];
    return nb::make_tuple(status, n);
}

// sigma(z) of every target point and sub-square into out (n_target * m1 * m2, as
// [point][piece of L1][piece of L2]); returns (m1, m2).
nb::tuple sub_square_growths(nb::handle target_obj, nb::handle a1_obj, nb::handle a2_obj,
                             int64_t per_edge, nb::handle out_obj) {
    namespace slam = bearing::slam;
    const In target = input(target_obj, "target");
    const In a1 = small_region(a1_obj, "a1");
    const In a2 = small_region(a2_obj, "a2");
    const View1<double> out = view_of<double, 1>(out_obj, "out");
    check_edge_samples(per_edge, "per_edge");
    const std::unique_ptr<slam::SubSquares> sub(new slam::SubSquares);
    slam::plan_sub_squares(a1.data, a1.shape[0], a2.data, a2.shape[0], per_edge, *sub);
    const int64_t squares = sub->m1 * sub->m2;
    check_room(product(target.shape[0], squares), out.shape[0], "out");
    for (int64_t v = 0; v < target.shape[0]; ++v) {
        for (int64_t i = 0; i < sub->m1; ++i) {
            for (int64_t j = 0; j < sub->m2; ++j) {
                out.data[v * squares + i * sub->m2 + j] =
                    slam::sub_square_growth(target.data[v], *sub, i, j);
            }
        }
    }
    return nb::make_tuple(sub->m1, sub->m2);
}

}  // namespace

void bind_slam_geometry(nb::module_& m) {
    // common.py and numerics.py's scalar helpers.
    m.def(
        "cross",
        [](nb::handle a, nb::handle b) {
            return bearing::cross(complex_of(a, "a"), complex_of(b, "b"));
        },
        "a"_a, "b"_a, "2-D cross product a.x * b.y - a.y * b.x.");
    m.def(
        "dot",
        [](nb::handle a, nb::handle b) {
            return bearing::dot(complex_of(a, "a"), complex_of(b, "b"));
        },
        "a"_a, "b"_a, "2-D dot product.");
    m.def("wrap", &bearing::wrap, "angle"_a, "An angle wrapped to [-pi, pi).");
    m.def("scale_of", &scale_of, "poly"_a, "n"_a,
          "(bounding-box size, largest coordinate magnitude) of poly[:n].");
    m.def("tolerance_of", &bearing::slam::tolerance_of, "size"_a, "magnitude"_a,
          "Distance below which two features count as touching, for polygons of that scale.");
    // polygons.py
    m.def("convex_hull", &convex_hull, "points"_a, "n_points"_a, "out"_a,
          "Convex hull of points[:n_points] into out (n_points + 1); returns its vertex count.");
    m.def("small_convex_hull", &small_convex_hull, "points"_a, "n_points"_a, "out"_a, "tol"_a,
          "Andrew's monotone chain of points[:n_points] into out (n_points + 1).");
    m.def("small_hull_indices", &small_hull_indices, "points"_a, "n_points"_a, "out"_a, "tol"_a,
          "small_convex_hull as indices (int64 out, n_points + 1).");
    m.def("area_centroid", &area_centroid, "poly"_a, "n"_a,
          "(area, centroid) of a convex polygon (the vertex mean if degenerate).");
    m.def("contains_point", &contains_point, "poly"_a, "n"_a, "point"_a, "relative"_a,
          "Whether point lies in the convex polygon poly[:n], to within relative * its size.");
    m.def("polygon_distance", &polygon_distance, "p"_a, "n_p"_a, "q"_a, "n_q"_a,
          "Distance between two small convex polygons; 0 if they touch or overlap.");
    m.def("longest_edge", &longest_edge, "poly"_a, "n"_a, "Length of the longest edge.");
    m.def("simplify", &simplify, "poly"_a, "n"_a, "tol"_a,
          "Drop repeated and collinear vertices in place; returns the new count.");
    m.def("drop_edges_outward", &drop_edges_outward, "poly"_a, "n"_a, "capacity"_a,
          "Reduce a convex polygon in place to at most capacity vertices by removing edges.");
    m.def("clip_convex", &clip_convex, "subject"_a, "n_subject"_a, "clipper"_a, "n_clipper"_a,
          "out"_a, "work"_a,
          "Intersection of two convex polygons into out (out and work hold SCRATCH).");
    m.def("offset_outward", &offset_outward, "poly"_a, "n"_a, "radius"_a, "out"_a,
          "Every edge of a convex polygon moved outward by radius, into out (n + 3).");
    // frames.py
    m.def("cone_region", &cone_region, "a"_a, "b"_a, "epsilon"_a, "out"_a,
          "(n, status): the FR region of a landmark seen at bearings a and b, into out (4).");
    m.def("boundary_samples", &boundary_samples, "poly"_a, "n"_a, "per_edge"_a, "out"_a,
          "per_edge evenly spaced points on each edge, vertices included.");
    m.def("frame_plan", &frame_plan, "a1"_a, "n1"_a, "a2"_a, "n2"_a, "conservative"_a,
          "edge_samples"_a, "(status, per_edge, distance, delta1, delta2) of a frame change.");
    m.def("sample_hypotheses", &sample_hypotheses, "a1"_a, "n1"_a, "a2"_a, "n2"_a, "per_edge"_a,
          "h1"_a, "inv_d"_a, "Hypothesis pairs (h1, 1 / (h2 - h1)); returns their count.");
    m.def("transfer_region", &transfer_region, "target"_a, "n_target"_a, "frame"_a, "cloud"_a,
          "hull"_a, "out"_a,
          "The FL region of an FR region into out (SCRATCH); returns its vertex count.");
    m.def("transfer_polygon", &transfer_polygon, "target"_a, "a1"_a, "a2"_a, "transfer"_a,
          "edge_samples"_a, "out"_a,
          "(status, n): one FR region's change of frames as the update runs it, into out "
          "(SCRATCH).");
    m.def("sub_square_growths", &sub_square_growths, "target"_a, "a1"_a, "a2"_a, "per_edge"_a,
          "out"_a,
          "(m1, m2): the local bound of every target point and sub-square into out "
          "(float64, n_target * m1 * m2).");
}
