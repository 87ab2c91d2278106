// The checked kernels over views (checked.hpp): each checks its counts and outputs' room,
// then runs the kernel of polygons.cpp, frames.cpp or local_bound.cpp.
#include <bearing_core/slam/checked.hpp>

#include <memory>
#include <string>

#include <bearing_core/core/checks.hpp>
#include <bearing_core/slam/common.hpp>
#include <bearing_core/slam/local_bound.hpp>
#include <bearing_core/slam/polygons.hpp>
#include <bearing_core/slam/scratch.hpp>
#include <bearing_core/slam/update.hpp>

namespace bearing::slam::checked {

namespace {

// The FR regions of L1 and L2 for transfer_polygon and sub_square_growths: 1 to
// FR_VERTICES vertices each.
void check_small_region(In region, const char* name) {
    if (region.shape[0] < 1 || region.shape[0] > FR_VERTICES) {
        invalid_argument(std::string(name) + " must have 1 to " + std::to_string(FR_VERTICES) +
                         " vertices, it has " + std::to_string(region.shape[0]));
    }
}

void check_edge_samples(int64_t edge_samples, const char* name) {
    if (edge_samples < 1 || edge_samples > MAX_EDGE_SAMPLES) {
        invalid_argument(std::string(name) + " must be in [1, " + std::to_string(MAX_EDGE_SAMPLES) +
                         "], got " + std::to_string(edge_samples));
    }
}

}  // namespace

std::pair<double, double> scale_of(In poly, int64_t n) {
    check_count(n, "n", poly.shape[0], "poly", 1);
    return slam::scale_of(poly.data, n);
}

int64_t convex_hull(In points, int64_t n_points, Out out) {
    check_count(n_points, "n_points", points.shape[0], "points");
    check_room(n_points + 1, out.shape[0], "out");
    return slam::convex_hull(points.data, n_points, out.data);
}

int64_t small_convex_hull(In points, int64_t n_points, Out out, double tol) {
    check_count(n_points, "n_points", points.shape[0], "points");
    check_room(n_points + 1, out.shape[0], "out");
    return slam::small_convex_hull(points.data, n_points, out.data, tol);
}

int64_t small_hull_indices(In points, int64_t n_points, View1<int64_t> out, double tol) {
    check_count(n_points, "n_points", points.shape[0], "points");
    check_room(n_points + 1, out.shape[0], "out");
    return slam::small_hull_indices(points.data, n_points, out.data, tol);
}

std::pair<double, cplx> area_centroid(In poly, int64_t n) {
    check_count(n, "n", poly.shape[0], "poly", 1);
    return slam::area_centroid(poly.data, n);
}

bool contains_point(In poly, int64_t n, cplx point, double relative) {
    check_count(n, "n", poly.shape[0], "poly", 1);
    return slam::contains_point(poly.data, n, point, relative);
}

double polygon_distance(In p, int64_t n_p, In q, int64_t n_q) {
    check_count(n_p, "n_p", p.shape[0], "p", 1);
    check_count(n_q, "n_q", q.shape[0], "q", 1);
    return slam::polygon_distance(p.data, n_p, q.data, n_q);
}

double longest_edge(In poly, int64_t n) {
    check_count(n, "n", poly.shape[0], "poly");
    return slam::longest_edge(poly.data, n);
}

int64_t simplify(Out poly, int64_t n, double tol) {
    check_count(n, "n", poly.shape[0], "poly");
    return slam::simplify(poly.data, n, tol);
}

int64_t drop_edges_outward(Out poly, int64_t n, int64_t capacity) {
    check_count(n, "n", poly.shape[0], "poly");
    return slam::drop_edges_outward(poly.data, n, capacity);
}

int64_t clip_convex(In subject, int64_t n_subject, In clipper, int64_t n_clipper, Out out,
                    Out work) {
    check_count(n_subject, "n_subject", subject.shape[0], "subject", 1);
    check_count(n_clipper, "n_clipper", clipper.shape[0], "clipper", 1);
    check_room(SCRATCH, out.shape[0], "out");
    check_room(SCRATCH, work.shape[0], "work");
    return slam::clip_convex(subject.data, n_subject, clipper.data, n_clipper, out.data, work.data);
}

int64_t offset_outward(In poly, int64_t n, double radius, Out out) {
    check_count(n, "n", poly.shape[0], "poly");
    require(n >= 1, "offset_outward needs n >= 1");
    check_room(n + 3, out.shape[0], "out");
    return slam::offset_outward(poly.data, n, radius, out.data);
}

std::pair<int64_t, int64_t> cone_region(double a, double b, double epsilon, Out out) {
    check_room(FR_VERTICES, out.shape[0], "out");
    return slam::cone_region(a, b, epsilon, out.data);
}

int64_t boundary_samples(In poly, int64_t n, int64_t per_edge, Out out) {
    check_count(n, "n", poly.shape[0], "poly");
    check_room(product(n, per_edge), out.shape[0], "out");
    return slam::boundary_samples(poly.data, n, per_edge, out.data);
}

FramePlan frame_plan(In a1, int64_t n1, In a2, int64_t n2, bool conservative,
                     int64_t edge_samples) {
    check_count(n1, "n1", a1.shape[0], "a1", 1);
    check_count(n2, "n2", a2.shape[0], "a2", 1);
    return slam::frame_plan(a1.data, n1, a2.data, n2, conservative, edge_samples);
}

int64_t sample_hypotheses(In a1, int64_t n1, In a2, int64_t n2, int64_t per_edge, Out h1,
                          Out inv_d) {
    check_count(n1, "n1", a1.shape[0], "a1");
    check_count(n2, "n2", a2.shape[0], "a2");
    // The kernel raises CapacityError beyond MAX_SAMPLES samples per region.
    if (product(n1, per_edge) <= MAX_SAMPLES && product(n2, per_edge) <= MAX_SAMPLES) {
        const int64_t pairs = product(product(n1, per_edge), product(n2, per_edge));
        check_room(pairs, h1.shape[0], "h1");
        check_room(pairs, inv_d.shape[0], "inv_d");
    }
    return slam::sample_hypotheses(a1.data, n1, a2.data, n2, per_edge, h1.data, inv_d.data);
}

FrameChange frame_change(In a1, int64_t n1, In a2, int64_t n2, In h1, In inv_d, int64_t n_pairs,
                         bool conservative, double distance, double delta1, double delta2) {
    check_count(n1, "frame.n1", a1.shape[0], "frame.a1");
    check_count(n2, "frame.n2", a2.shape[0], "frame.a2");
    check_count(n_pairs, "frame.n_pairs", h1.shape[0], "frame.h1");
    check_count(n_pairs, "frame.n_pairs", inv_d.shape[0], "frame.inv_d");
    FrameChange frame;
    frame.a1 = a1.data;
    frame.n1 = n1;
    frame.a2 = a2.data;
    frame.n2 = n2;
    frame.h1 = h1.data;
    frame.inv_d = inv_d.data;
    frame.n_pairs = n_pairs;
    frame.conservative = conservative;
    frame.distance = distance;
    frame.delta1 = delta1;
    frame.delta2 = delta2;
    return frame;
}

int64_t transfer_region(In target, int64_t n_target, const FrameChange& frame, Out cloud, Out hull,
                        Out out) {
    check_count(n_target, "n_target", target.shape[0], "target");
    const int64_t k = product(n_target, frame.n_pairs);
    // Beyond MAX_CLOUD the kernel raises CapacityError before touching the arrays.
    if (k <= MAX_CLOUD) {
        check_room(k, cloud.shape[0], "cloud");
        check_room(k + 1, hull.shape[0], "hull");
        check_room(SCRATCH, out.shape[0], "out");
    }
    return slam::transfer_region(target.data, n_target, frame, cloud.data, hull.data, out.data);
}

std::pair<int64_t, int64_t> transfer_polygon(In target, In a1, In a2, int64_t transfer,
                                             int64_t edge_samples, Out out) {
    check_small_region(a1, "a1");
    check_small_region(a2, "a2");
    require(target.shape[0] >= 1, "target must hold at least one point");
    if (!valid_transfer(transfer)) {
        invalid_argument(
            "transfer must be TRANSFER_CONSERVATIVE (0), TRANSFER_PAPER (1) or "
            "TRANSFER_CONSERVATIVE_GLOBAL (2), got " +
            std::to_string(transfer));
    }
    check_edge_samples(edge_samples, "edge_samples");
    check_room(SCRATCH, out.shape[0], "out");
    // The thread's reused buffers (every slot used is written first): a fresh Buffers
    // would zero its 260 KB on every call.
    Buffers& buf = thread_buffers();
    FrameChange frame;
    const int64_t status = change_of_frames(a1.data, a1.shape[0], a2.data, a2.shape[0], transfer,
                                            edge_samples, buf, frame);
    if (status != FRAME_OK) return {status, 0};
    Scratch& scratch = buf.scratch;
    const int64_t n = slam::transfer_region(target.data, target.shape[0], frame, scratch.cloud,
                                            scratch.hull, scratch.fresh);
    check_room(n, out.shape[0], "out");
    for (int64_t v = 0; v < n; ++v) out.data[v] = scratch.fresh[v];
    return {status, n};
}

std::pair<int64_t, int64_t> sub_square_growths(In target, In a1, In a2, int64_t per_edge,
                                               View1<double> out) {
    check_small_region(a1, "a1");
    check_small_region(a2, "a2");
    check_edge_samples(per_edge, "per_edge");
    const std::unique_ptr<SubSquares> sub(new SubSquares);
    plan_sub_squares(a1.data, a1.shape[0], a2.data, a2.shape[0], per_edge, *sub);
    const int64_t squares = sub->m1 * sub->m2;
    check_room(product(target.shape[0], squares), out.shape[0], "out");
    for (int64_t v = 0; v < target.shape[0]; ++v) {
        for (int64_t i = 0; i < sub->m1; ++i) {
            for (int64_t j = 0; j < sub->m2; ++j) {
                out.data[v * squares + i * sub->m2 + j] =
                    sub_square_growth(target.data[v], *sub, i, j);
            }
        }
    }
    return {sub->m1, sub->m2};
}

}  // namespace bearing::slam::checked
