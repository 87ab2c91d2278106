// bearing_env/slam/kernels/robust.py in C++ (same branches, same order of operations).
#include <bearing_core/slam/robust.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

#include <bearing_core/slam/fusion.hpp>
#include <bearing_core/slam/polygons.hpp>

namespace bearing::slam {

namespace {

constexpr double INF = std::numeric_limits<double>::infinity();

// x ** n for a float x and a non-literal int64 n >= 0, as numba lowers it
// (int_power_impl: binary exponentiation, math.pow past 0x10000).
double int_power(double a, int64_t b) {
    double r = 1.0;
    int64_t exp = b;
    if (exp > 0x10000) return std::pow(a, static_cast<double>(b));
    while (exp != 0) {
        if (exp & 1) r *= a;
        exp >>= 1;
        a *= a;
    }
    return r;
}

}  // namespace

int64_t binomial_q(int64_t n, double p, double risk, int64_t q_cap) {
    if (p <= 0.0 || n <= 0) return 0;
    p = std::min(p, 0.999);
    double term = int_power(1.0 - p, n);  // P(X = 0)
    double below = term;                  // P(X <= q)
    int64_t q = 0;
    while (q < q_cap && 1.0 - below >= risk) {
        // A zero term stays zero (past q = n, or underflowed), so `below` and the test
        // above no longer change: the loop would run on to q_cap (endless for a huge
        // q_cap, such as a risk <= 0 never met). Its answer, at once:
        if (term == 0.0) return q_cap;
        term *= static_cast<double>(n - q) / (static_cast<double>(q) + 1.0) * p / (1.0 - p);
        q += 1;
        below += term;
    }
    return q;
}

double contamination(const MapState& state, int64_t row) {
    double contradictions = PRIOR_CONTRADICTIONS + static_cast<double>(bound_growths(state, row));
    double regions = PRIOR_REGIONS;
    for (int64_t j = 0; j < state.n_regions.shape[1]; ++j) {
        contradictions += static_cast<double>(state.outliers(row, j));
        regions += static_cast<double>(state.n_regions(row, j));
    }
    return UNSEEN_FACTOR * contradictions / regions;
}

void update_levels(const MapState& state, int64_t row, int64_t j, int64_t n_new, Scratch& scratch) {
    const int64_t n_levels = state.level_counts.shape[2];
    const int64_t capacity = state.level_vertices.shape[3];
    int64_t* counts = state.level_counts.row(row, j);
    auto level = [&](int64_t k) { return state.level_vertices.row(row, j, k); };
    const int64_t seen = state.n_regions(row, j);
    // Level `seen` (if kept) was the whole plane: its clip is the new region itself.
    for (int64_t k = std::min(seen, n_levels - 1); k > -1; --k) {
        int64_t n;
        if (k == seen) {
            copy_polygon(scratch.fresh, n_new, level(k), capacity, "a robust level");
            n = n_new;
        } else if (counts[k] > 0) {
            n = clip_convex(level(k), counts[k], scratch.fresh, n_new, scratch.fused, scratch.work);
            copy_polygon(scratch.fused, n, level(k), capacity, "a robust level");
        } else {
            n = 0;
        }
        if (k > 0 && counts[k - 1] > 0) {
            if (n == 0) {
                n = counts[k - 1];
                copy_polygon(level(k - 1), n, level(k), capacity, "a robust level");
            } else {
                n = merge_hull(level(k), n, capacity, level(k - 1), counts[k - 1], scratch.cloud,
                               scratch.hull);
            }
        }
        counts[k] = n;
    }
    state.n_regions(row, j) = seen + 1;
}

bool robust_landmark(const MapState& state, int64_t row, int64_t j, int64_t n_new, double rate,
                     const Params& params, Scratch& scratch) {
    const int64_t n_levels = state.level_counts.shape[2];
    const int64_t capacity = state.level_vertices.shape[3];
    int64_t* counts = state.level_counts.row(row, j);
    const int64_t before = state.outliers(row, j);
    update_levels(state, row, j, n_new, scratch);
    const int64_t seen = state.n_regions(row, j);
    int64_t top = std::min(seen, n_levels) - 1;
    int64_t k_min = 0;
    while (k_min <= top && counts[k_min] == 0) k_min += 1;
    const bool consistent = k_min <= before;
    if (k_min > top) {
        // More contradictions than levels: restart from the new region alone.
        check_capacity("the robust levels", 1, n_levels);
        copy_polygon(scratch.fresh, n_new, state.level_vertices.row(row, j, 0), capacity,
                     "a robust level");
        for (int64_t k = 0; k < n_levels; ++k) counts[k] = 0;
        counts[0] = n_new;
        state.n_regions(row, j) = 1;
        k_min = 0;
        top = 0;
    }
    state.outliers(row, j) = k_min;
    int64_t chosen = k_min;
    if (!params.likely) chosen = std::max(chosen, binomial_q(seen, rate, params.risk, top));
    const int64_t n = counts[chosen];
    copy_polygon(state.level_vertices.row(row, j, chosen), n, state.vertices.row(row, j),
                 state.vertices.shape[2], "a landmark region");
    state.counts(row, j) = n;
    auto [area, centroid] = area_centroid(state.vertices.row(row, j), n);
    state.areas(row, j) = area;
    state.centroids(row, j) = centroid;
    return consistent;
}

bool frame_contradicts_robot(const MapState& state, int64_t row, const FrameChange& frame,
                             Scratch& scratch) {
    const int64_t n_robot = state.robot_counts(row);
    if (n_robot == 0 || state.robot_fixed_at(row) != state.n_updates(row) - 1) return false;
    const cplx origin[1] = {cplx(0.0, 0.0)};
    const int64_t n_start =
        transfer_region(origin, 1, frame, scratch.cloud, scratch.hull, scratch.fresh);
    if (n_start < 3) return false;
    const int64_t n = clip_convex(state.robot_vertices.row(row), n_robot, scratch.fresh, n_start,
                                  scratch.fused, scratch.work);
    return n == 0;
}

bool probe_landmark(const MapState& state, int64_t row, int64_t j, int64_t n_new,
                    Scratch& scratch) {
    int64_t& count = state.probe_counts(row, j);
    int64_t n = n_new;
    const cplx* source = scratch.fresh;
    if (count > 0) {
        n = clip_convex(state.probe_vertices.row(row, j), count, scratch.fresh, n_new,
                        scratch.fused, scratch.work);
        if (n == 0) return false;
        source = scratch.fused;
    }
    copy_polygon(source, n, state.probe_vertices.row(row, j), state.probe_vertices.shape[2],
                 "a probe region");
    count = n;
    return true;
}

int64_t bound_growths(const MapState& state, int64_t row) {
    // Python's round() of a float: numba lowers it to llvm.rint (half to even), then
    // converts to int.
    return static_cast<int64_t>(
        std::rint(std::log(state.noise_scale(row)) / std::log(BOUND_GROWTH)));
}

bool grow_bound(const MapState& state, int64_t row, double epsilon) {
    const int64_t per_growth = std::max<int64_t>(1, py_floordiv(state.counts.shape[1] + 1, 2));
    if (state.bound_events(row) < per_growth * (bound_growths(state, row) + 1)) return false;
    const double scale = state.noise_scale(row) * BOUND_GROWTH;
    if (scale > MAX_NOISE_SCALE * (1.0 + 1e-9) || scale * epsilon >= MAX_BOUND) return false;
    state.noise_scale(row) = scale;
    return true;
}

void push_history(const MapState& state, int64_t row, const double* start, const double* end) {
    const int64_t size = state.history_bearings.shape[1];
    const int64_t n_mapped = state.history_bearings.shape[3];
    const int64_t slot = state.history_next(row);
    check_capacity("the bearing history", slot + 1, size);
    for (int64_t j = 0; j < 2; ++j) {
        state.history_frame_bearings(row, slot, 0, j) = start[j];
        state.history_frame_bearings(row, slot, 1, j) = end[j];
    }
    for (int64_t j = 0; j < n_mapped; ++j) {
        state.history_bearings(row, slot, 0, j) = start[j + 2];
        state.history_bearings(row, slot, 1, j) = end[j + 2];
    }
    state.history_next(row) = py_mod(slot + 1, size);
    state.history_length(row) = std::min(size, state.history_length(row) + 1);
}

void history_movement(const MapState& state, int64_t row, int64_t k, double* start, double* end) {
    const int64_t size = state.history_bearings.shape[1];
    const int64_t n_mapped = state.history_bearings.shape[3];
    const int64_t slot = py_mod(state.history_next(row) - state.history_length(row) + k, size);
    for (int64_t j = 0; j < 2; ++j) {
        start[j] = state.history_frame_bearings(row, slot, 0, j);
        end[j] = state.history_frame_bearings(row, slot, 1, j);
    }
    for (int64_t j = 0; j < n_mapped; ++j) {
        start[j + 2] = state.history_bearings(row, slot, 0, j);
        end[j + 2] = state.history_bearings(row, slot, 1, j);
    }
}

void forget_regions(const MapState& state, int64_t row) {
    const int64_t m = state.counts.shape[1];
    for (int64_t j = 0; j < m; ++j) {
        state.counts(row, j) = 0;
        state.areas(row, j) = INF;
        state.centroids(row, j) = complex_nan();
        state.outliers(row, j) = 0;
        state.n_regions(row, j) = 0;
        state.probe_counts(row, j) = 0;
        for (int64_t k = 0; k < state.level_counts.shape[2]; ++k) state.level_counts(row, j, k) = 0;
    }
    state.robot_counts(row) = 0;
    state.robot_area(row) = INF;
    state.robot_centroid(row) = complex_nan();
    state.robot_heading(row) = std::numeric_limits<double>::quiet_NaN();
}

}  // namespace bearing::slam
