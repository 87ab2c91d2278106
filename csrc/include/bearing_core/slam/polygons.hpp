// Convex polygons in fixed-capacity arrays (bearing_env/slam/kernels/polygons.py, ported
// function for function, same order of operations): hulls, area and centroid,
// containment, distances, simplification, capacity reduction, clipping, outward offsets.
// A polygon is a vertex array in counter-clockwise order plus its count n.
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>

#include <bearing_core/slam/common.hpp>

namespace bearing::slam {

// Largest point set convex_hull takes (a transfer's cloud); more raises CapacityError.
inline constexpr int64_t MAX_HULL_POINTS = MAX_CLOUD + SCRATCH;

// Buffers (as in polygons.py): convex_hull, small_convex_hull and small_hull_indices write
// at most n_points + 1 entries of out (a hull that would need more, possible only with
// NaNs, raises CapacityError; the small hulls' chains run in a buffer of their own, see
// polygons.cpp); clip_convex's out and work hold SCRATCH; offset_outward's out n + 3, and
// it throws std::invalid_argument for n < 1 (numba read poly[-1]); its out must not
// overlap poly (each edge's tangent is computed once and reused for the next vertex). Points: at
// most MAX_HULL_POINTS, else CapacityError.
int64_t convex_hull(const cplx* points, int64_t n_points, cplx* out);
int64_t small_convex_hull(const cplx* points, int64_t n_points, cplx* out, double tol);
// order, if given, holds a permutation of 0..n_points - 1 that the hull's sort by
// position starts from (the same result, sooner when it is nearly sorted: the previous
// call's on similar points), and is left holding the sorted one.
int64_t small_hull_indices(const cplx* points, int64_t n_points, int64_t* out, double tol,
                           int64_t* order = nullptr);
std::pair<double, cplx> area_centroid(const cplx* poly, int64_t n);
bool contains_point(const cplx* poly, int64_t n, cplx point, double relative);
double polygon_distance(const cplx* p, int64_t n_p, const cplx* q, int64_t n_q);
double longest_edge(const cplx* poly, int64_t n);
int64_t simplify(cplx* poly, int64_t n, double tol);
int64_t drop_edges_outward(cplx* poly, int64_t n, int64_t capacity);
int64_t clip_convex(const cplx* subject, int64_t n_subject, const cplx* clipper, int64_t n_clipper,
                    cplx* out, cplx* work);
int64_t offset_outward(const cplx* poly, int64_t n, double radius, cplx* out);

// Distance from z to the segment [a, b].
inline double point_segment_distance(cplx z, cplx a, cplx b) {
    const cplx d = b - a;
    const double len2 = dot(d, d);
    if (len2 == 0.0) return abs(z - a);
    const double t = std::min(std::max(dot(z - a, d) / len2, 0.0), 1.0);
    return abs(z - (a + t * d));
}

}  // namespace bearing::slam
