// The polygon and frame kernels (polygons.hpp, frames.hpp, common.hpp) over views, each
// count checked against the arrays it indexes and each output's room against what the
// kernel writes: a bad argument throws std::invalid_argument naming it, an input beyond a
// kernel's fixed capacity CapacityError, never an out-of-bounds access. (The Python
// bindings are these, one line each.) A kernel that reads element 0 whatever its count
// (scale_of, area_centroid, ...) needs an array of at least one element, as numba does.
#pragma once

#include <cstdint>
#include <utility>

#include <bearing_core/core/complex.hpp>
#include <bearing_core/core/views.hpp>
#include <bearing_core/slam/frames.hpp>
#include <bearing_core/slam/state.hpp>

namespace bearing::slam::checked {

using In = View1<const cplx>;
using Out = View1<cplx>;

std::pair<double, double> scale_of(In poly, int64_t n);
int64_t convex_hull(In points, int64_t n_points, Out out);
int64_t small_convex_hull(In points, int64_t n_points, Out out, double tol);
int64_t small_hull_indices(In points, int64_t n_points, View1<int64_t> out, double tol);
std::pair<double, cplx> area_centroid(In poly, int64_t n);
bool contains_point(In poly, int64_t n, cplx point, double relative);
double polygon_distance(In p, int64_t n_p, In q, int64_t n_q);
double longest_edge(In poly, int64_t n);
int64_t simplify(Out poly, int64_t n, double tol);
int64_t drop_edges_outward(Out poly, int64_t n, int64_t capacity);
int64_t clip_convex(In subject, int64_t n_subject, In clipper, int64_t n_clipper, Out out,
                    Out work);
int64_t offset_outward(In poly, int64_t n, double radius, Out out);
std::pair<int64_t, int64_t> cone_region(double a, double b, double epsilon, Out out);
int64_t boundary_samples(In poly, int64_t n, int64_t per_edge, Out out);
FramePlan frame_plan(In a1, int64_t n1, In a2, int64_t n2, bool conservative, int64_t edge_samples);
int64_t sample_hypotheses(In a1, int64_t n1, In a2, int64_t n2, int64_t per_edge, Out h1,
                          Out inv_d);

// A change of frames over views (frames.py's FrameChange tuple), its counts checked
// against its arrays (named frame.a1, frame.n1, ...).
FrameChange frame_change(In a1, int64_t n1, In a2, int64_t n2, In h1, In inv_d, int64_t n_pairs,
                         bool conservative, double distance, double delta1, double delta2);
// `frame` from frame_change; cloud and hull hold n_target * n_pairs (+ 1), out SCRATCH.
int64_t transfer_region(In target, int64_t n_target, const FrameChange& frame, Out cloud, Out hull,
                        Out out);

// One FR region's whole change of frames for one movement, as the update runs it (a1 and
// a2 of 1 to FR_VERTICES vertices): frame_plan, the hypotheses, the sub-squares
// (TRANSFER_CONSERVATIVE) and transfer_region, into out (SCRATCH); (status, n).
std::pair<int64_t, int64_t> transfer_polygon(In target, In a1, In a2, int64_t transfer,
                                             int64_t edge_samples, Out out);
// sigma(z) of every target point and sub-square into out (n_target * m1 * m2, as
// [point][piece of L1][piece of L2]); returns (m1, m2).
std::pair<int64_t, int64_t> sub_square_growths(In target, In a1, In a2, int64_t per_edge,
                                               View1<double> out);

// ---- The map state and the batch helpers (state.hpp, update.hpp, fusion.hpp, robust.hpp).

// The state `s` (`label` in messages) fits the update's buffers: vertex axes of CAPACITY
// or 0 (base_vertices, probe_vertices), a window of at most MAX_WINDOW movements and at
// most MAX_LANDMARKS - 2 mapped landmarks. (Its arrays' shapes agree by its schema.)
void check_state(const MapState& s, const char* label);
// What the fusion of `p` needs of the state's optional arrays.
void check_state_for(const MapState& s, const Params& p);
// `to` can take copies of `from`'s maps (`what` in messages): another state, of the same
// landmarks and fusion arrays.
void check_copyable(const MapState& from, const MapState& to, const char* what);
// The indices `rows` (argument `name`) are in [0, size), none repeated if `distinct`.
void check_rows(View1<const int64_t> rows, int64_t size, bool distinct, const char* name = "rows");

// update_maps (update.hpp) with its arguments checked: the rows, the bearings (rows, n),
// the outputs' rows and the state's arrays for params.
void update_maps(View2<const double> bearings_start, View2<const double> bearings_end,
                 View1<const int64_t> rows, const Params& params, const MapState& state,
                 const Outputs& out, int64_t threads);
void copy_maps(const MapState& from, View1<const int64_t> rows, const MapState& to);
// check_indices (update.hpp) of any size: its table of seen indices is as long as the
// largest index given needs, not `size`.
int64_t check_indices(View1<const int64_t> indices, int64_t size, bool distinct);
// Whether no value is +-inf (NaN allowed: a missed reading).
bool none_infinite(View1<const double> values);
void contains_points(View3<const cplx> vertices, View2<const int64_t> counts,
                     View1<const int64_t> rows, View2<const cplx> points, double relative,
                     View2<bool> out);
// The relaxed fusion's region of landmark j of map `row` over the window slots `slots`,
// with the bases if use_base: (n, q), the region in out[:n] (SCRATCH).
std::pair<int64_t, int64_t> relaxed_region(const MapState& s, int64_t row, int64_t j,
                                           View1<const int64_t> slots, bool use_base,
                                           int64_t max_outliers, Out out);
// Fuse the region `fresh` (3..CAPACITY vertices) into landmark j's robust levels of map
// `row`.
void update_levels(const MapState& s, int64_t row, int64_t j, In fresh);

}  // namespace bearing::slam::checked
