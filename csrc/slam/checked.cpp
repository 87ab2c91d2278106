// The checked kernels over views (checked.hpp): each checks its counts and outputs' room,
// then runs the kernel of polygons.cpp, frames.cpp or local_bound.cpp.
#include <bearing_core/slam/checked.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <bearing_core/core/checks.hpp>
#include <bearing_core/slam/common.hpp>
#include <bearing_core/slam/fusion.hpp>
#include <bearing_core/slam/local_bound.hpp>
#include <bearing_core/slam/polygons.hpp>
#include <bearing_core/slam/robust.hpp>
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

// A vertex count the kernels read a region of the state with (from an array a user can
// write, as the update's own check of a map does): within the region's `slots`.
void check_region_count(int64_t n, int64_t slots, const char* name) {
    if (n < 0 || n > slots) {
        invalid_argument(std::string("state.") + name + " holds " + std::to_string(n) +
                         ", outside [0, " + std::to_string(slots) + "]: a corrupt state");
    }
}

// Map `row` and landmark slot `j` of the state `s`.
void check_map_and_slot(const MapState& s, int64_t row, int64_t j) {
    const int64_t maps = s.vertices.shape[0], mapped = s.vertices.shape[1];
    require(0 <= row && row < maps, "row must be a map index in [0, " + std::to_string(maps) + ")");
    require(0 <= j && j < mapped,
            "j must be a landmark slot in [0, " + std::to_string(mapped) + ")");
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

void check_state(const MapState& s, const char* label) {
    const std::string state(label);
    for (const auto& [axis, array, length] :
         {std::tuple{"base_capacity", "base_vertices", s.base_vertices.shape[2]},
          std::tuple{"probe_capacity", "probe_vertices", s.probe_vertices.shape[2]}}) {
        if (length != CAPACITY && length != 0) {
            invalid_argument(state + "'s " + axis + " (the last axis of " + state + "." + array +
                             ") must be " + std::to_string(CAPACITY) + " or 0, not " +
                             std::to_string(length));
        }
    }
    if (s.window_vertices.shape[1] > MAX_WINDOW) {
        invalid_argument(state + ".window_vertices has a window of " +
                         std::to_string(s.window_vertices.shape[1]) +
                         " movements, more than MAX_WINDOW (" + std::to_string(MAX_WINDOW) + ")");
    }
    if (s.vertices.shape[1] + 2 > MAX_LANDMARKS) {
        invalid_argument(state + ".vertices has " + std::to_string(s.vertices.shape[1]) +
                         " mapped landmarks, more than " + std::to_string(MAX_LANDMARKS - 2) +
                         " (MAX_LANDMARKS - 2)");
    }
}

void check_state_for(const MapState& s, const Params& p) {
    if (p.fusion == FUSION_RELAXED) {
        require(s.window_vertices.shape[1] >= 1,
                "state has no relaxed window (window_vertices axis 1 is 0), but params.fusion "
                "is FUSION_RELAXED");
        require(s.base_vertices.shape[2] == CAPACITY,
                "state.base_vertices has no vertex slots, but params.fusion is FUSION_RELAXED");
    }
    if (p.fusion == FUSION_ROBUST) {
        require(s.level_vertices.shape[2] >= 1,
                "state has no robust levels (level_vertices axis 2 is 0), but params.fusion "
                "is FUSION_ROBUST");
        require(!p.estimate_bound || s.probe_vertices.shape[2] == CAPACITY,
                "state.probe_vertices has no vertex slots, but params.estimate_bound is set");
        require(!p.estimate_bound || s.history_bearings.shape[1] >= 1,
                "state has no bearing history (history_bearings axis 1 is 0), but "
                "params.estimate_bound is set");
    }
}

void check_copyable(const MapState& from, const MapState& to, const char* what) {
    require(from.vertices.data != to.vertices.data,
            std::string(what) + " needs two different states");
    const auto axes = [](const MapState& s) {
        return std::vector<int64_t>{s.vertices.shape[1],       s.window_vertices.shape[1],
                                    s.base_vertices.shape[2],  s.level_vertices.shape[2],
                                    s.probe_vertices.shape[2], s.history_bearings.shape[1]};
    };
    if (axes(from) != axes(to)) {
        invalid_argument(std::string(what) +
                         " needs states of the same landmarks and fusion arrays: from has " +
                         std::to_string(from.vertices.shape[1]) + " mapped landmarks, to " +
                         std::to_string(to.vertices.shape[1]));
    }
}

void check_rows(View1<const int64_t> rows, int64_t size, bool distinct, const char* name) {
    thread_local std::unique_ptr<bool[]> seen;  // check_indices' table, reused
    thread_local int64_t seen_size = 0;
    if (distinct && seen_size < size) {
        seen.reset(new bool[static_cast<size_t>(size)]);
        seen_size = size;
    }
    const int64_t status =
        slam::check_indices(rows.data, rows.shape[0], size, distinct, seen.get());
    for (int64_t k = 0; k < rows.shape[0] && status == INDEX_OUT_OF_RANGE; ++k) {
        if (rows[k] < 0 || rows[k] >= size) {
            invalid_argument(std::string(name) + " holds " + std::to_string(rows[k]) +
                             " at position " + std::to_string(k) + ", outside [0, " +
                             std::to_string(size) + ")");
        }
    }
    require(status != INDEX_REPEATED, std::string(name) + " must not repeat a row");
}

void update_maps(View2<const double> bearings_start, View2<const double> bearings_end,
                 View1<const int64_t> rows, const Params& params, const MapState& state,
                 const Outputs& out, int64_t threads) {
    require(threads >= 1, "threads must be at least 1, not " + std::to_string(threads));
    // Threads write their maps concurrently: a map in two blocks would race.
    check_rows(rows, state.vertices.shape[0], threads > 1);
    const int64_t size = rows.shape[0], mapped = state.vertices.shape[1];
    for (const auto& [bearings, name] :
         {std::pair{bearings_start, "bearings_start"}, std::pair{bearings_end, "bearings_end"}}) {
        check_axis(bearings, 0, size, name);
        check_axis(bearings, 1, mapped + 2, name);
    }
    check_axis(out.frame_status, 0, size, "out.frame_status");
    check_axis(out.landmark_status, 0, size, "out.landmark_status");
    check_axis(out.landmark_status, 1, mapped, "out.landmark_status");
    check_axis(out.n_bad, 0, size, "out.n_bad");
    check_state_for(state, params);
    slam::update_maps(bearings_start, bearings_end, rows, params, state, out, threads);
}

void copy_maps(const MapState& from, View1<const int64_t> rows, const MapState& to) {
    check_copyable(from, to, "copy_maps");
    check_rows(rows, from.vertices.shape[0], false);
    require(rows.shape[0] <= to.vertices.shape[0],
            "rows has " + std::to_string(rows.shape[0]) + " entries, more than to's " +
                std::to_string(to.vertices.shape[0]) + " maps");
    slam::copy_maps(from, rows, to);
}

bool none_infinite(View1<const double> values) {
    return std::none_of(values.data, values.data + values.size(),
                        [](double value) { return std::isinf(value); });
}

int64_t check_indices(View1<const int64_t> indices, int64_t size, bool distinct) {
    require(!distinct || size >= 0, "size must not be negative, got " + std::to_string(size));
    const int64_t n = indices.shape[0];
    if (!distinct) return slam::check_indices(indices.data, n, size, false, nullptr);
    // The kernel's table of seen indices needs a slot per index in range only up to the
    // largest one given, not `size` slots (a huge size would allocate and clear that
    // much): with `limit` for `size`, an index is in range exactly when it was before.
    int64_t limit = 0;
    for (int64_t k = 0; k < n; ++k) {
        if (indices(k) >= 0 && indices(k) < size) limit = std::max(limit, indices(k) + 1);
    }
    constexpr int64_t MAX_TABLE = int64_t{1} << 20;
    if (limit <= MAX_TABLE) {
        std::unique_ptr<bool[]> seen(new bool[static_cast<size_t>(limit)]);
        return slam::check_indices(indices.data, n, limit, true, seen.get());
    }
    // Sparse large indices: the kernel's answer (the first problem in order) from a sorted
    // copy of the indices before the first one out of range.
    int64_t stop = 0;
    while (stop < n && indices(stop) >= 0 && indices(stop) < size) ++stop;
    std::vector<int64_t> sorted(indices.data, indices.data + stop);
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) return INDEX_REPEATED;
    return stop < n ? INDEX_OUT_OF_RANGE : INDEX_OK;
}

void contains_points(View3<const cplx> vertices, View2<const int64_t> counts,
                     View1<const int64_t> rows, View2<const cplx> points, double relative,
                     View2<bool> out) {
    check_axis(counts, 0, vertices.shape[0], "counts");
    check_axis(counts, 1, vertices.shape[1], "counts");
    check_axis(points, 0, rows.shape[0], "points");
    check_axis(points, 1, counts.shape[1], "points");
    check_shape(out, points, "out");
    for (int64_t i = 0; i < rows.shape[0]; ++i) {
        if (rows(i) < 0 || rows(i) >= vertices.shape[0]) {
            invalid_argument("rows must be map indices in [0, " +
                             std::to_string(vertices.shape[0]) + "), got " +
                             std::to_string(rows(i)));
        }
        for (int64_t j = 0; j < counts.shape[1]; ++j) {
            if (counts(rows(i), j) > vertices.shape[2]) {
                invalid_argument("counts must not exceed vertices' last axis (" +
                                 std::to_string(vertices.shape[2]) + "), got " +
                                 std::to_string(counts(rows(i), j)));
            }
        }
    }
    slam::contains_points(vertices, counts, rows, points, relative, out);
}

std::pair<int64_t, int64_t> relaxed_region(const MapState& s, int64_t row, int64_t j,
                                           View1<const int64_t> slots, bool use_base,
                                           int64_t max_outliers, Out out) {
    check_map_and_slot(s, row, j);
    const int64_t w = s.window_vertices.shape[1], k = slots.shape[0];
    require(1 <= k && k <= w, "slots must hold 1.." + std::to_string(w) + " window slots");
    for (int64_t i = 0; i < k; ++i) {
        require(0 <= slots(i) && slots(i) < w, "slots must index the window");
    }
    require(0 <= max_outliers && max_outliers < MAX_WINDOW, "max_outliers out of range");
    require(out.shape[0] >= SCRATCH, "out must hold SCRATCH points");
    for (int64_t i = 0; i < k; ++i) {
        check_region_count(s.window_counts(row, slots(i), j), s.window_vertices.shape[3],
                           "window_counts");
    }
    if (use_base) {
        check_region_count(s.base_counts(row, j), s.base_vertices.shape[2], "base_counts");
    }
    Scratch& scratch = thread_buffers().scratch;  // reused, not zeroed per call
    for (int64_t i = 0; i < k; ++i) scratch.slots[i] = slots(i);
    const auto [n, q] = slam::relaxed_region(s, row, j, k, use_base, max_outliers, scratch);
    for (int64_t v = 0; v < n; ++v) out(v) = scratch.acc[v];
    return {n, q};
}

void update_levels(const MapState& s, int64_t row, int64_t j, In fresh) {
    check_map_and_slot(s, row, j);
    const int64_t levels = s.level_vertices.shape[2];
    require(levels > 0, "the state has no robust levels (fusion must be 'robust')");
    require(3 <= fresh.shape[0] && fresh.shape[0] <= CAPACITY,
            "fresh must have 3.." + std::to_string(CAPACITY) + " vertices");
    require(s.n_regions(row, j) >= 0, "state.n_regions is negative: a corrupt state");
    for (int64_t k = 0; k < levels; ++k) {
        check_region_count(s.level_counts(row, j, k), s.level_vertices.shape[3], "level_counts");
    }
    Scratch& scratch = thread_buffers().scratch;  // reused, not zeroed per call
    for (int64_t v = 0; v < fresh.shape[0]; ++v) scratch.fresh[v] = fresh(v);
    slam::update_levels(s, row, j, fresh.shape[0], scratch);
}

}  // namespace bearing::slam::checked
