// bearing_env/slam/kernels/fusion.py in C++ (same branches, same order of operations).
#include <bearing_core/slam/fusion.hpp>

#include <array>
#include <limits>

#include <bearing_core/core/pymath.hpp>
#include <bearing_core/slam/polygons.hpp>

namespace bearing::slam {

namespace {

constexpr double INF = std::numeric_limits<double>::infinity();

inline void set_area_centroid(const MapState& state, int64_t row, int64_t j, int64_t n) {
    auto [area, centroid] = area_centroid(state.vertices.row(row, j), n);
    state.areas(row, j) = area;
    state.centroids(row, j) = centroid;
}

}  // namespace

// ------------------------------------------------------------------------------------
// The strict intersection (the paper's fusion)
// ------------------------------------------------------------------------------------

bool intersect_landmark(const MapState& state, int64_t row, int64_t j, int64_t n_new, bool keep,
                        Scratch& scratch) {
    cplx* region = state.vertices.row(row, j);
    const int64_t n_old = state.counts(row, j);
    const cplx* source = scratch.fresh;
    int64_t n_result = n_new;
    bool consistent = true;
    if (n_old > 0) {
        n_result = clip_convex(region, n_old, scratch.fresh, n_new, scratch.fused, scratch.work);
        if (n_result > 0) {
            source = scratch.fused;
        } else {
            consistent = false;
            if (keep) return consistent;
            n_result = n_new;
        }
    }
    copy_polygon(source, n_result, region, state.vertices.shape[2], "a landmark region");
    state.counts(row, j) = n_result;
    set_area_centroid(state, row, j, n_result);
    return consistent;
}

// ------------------------------------------------------------------------------------
// Relaxed fusion: the q-relaxed intersection over a window of movements
// ------------------------------------------------------------------------------------

int64_t merge_hull(cplx* acc, int64_t n_acc, int64_t acc_capacity, const cplx* poly, int64_t n_poly,
                   cplx* cloud, cplx* hull) {
    check_capacity("a merged hull's points", n_acc + n_poly, MAX_CLOUD);
    for (int64_t v = 0; v < n_acc; ++v) cloud[v] = acc[v];
    for (int64_t v = 0; v < n_poly; ++v) cloud[n_acc + v] = poly[v];
    int64_t n = convex_hull(cloud, n_acc + n_poly, hull);
    n = drop_edges_outward(hull, n, CAPACITY);
    copy_polygon(hull, n, acc, acc_capacity, "a merged hull");
    return n;
}

int64_t window_slots(const MapState& state, int64_t row, int64_t j, int64_t* out) {
    const int64_t length = state.window_length(row), next_slot = state.window_next(row);
    const int64_t size = state.window_counts.shape[1];
    check_capacity("the relaxed window's slots", length, MAX_WINDOW);
    int64_t k = 0;
    for (int64_t age = 0; age < length; ++age) {
        const int64_t slot = py_mod(next_slot - length + age, size);
        if (state.window_counts(row, slot, j) > 0 && !state.window_rejected(row, slot)) {
            out[k] = slot;
            k += 1;
        }
    }
    return k;
}

std::pair<int64_t, bool> intersect_kept(const MapState& state, int64_t row, int64_t j, int64_t k,
                                        const bool* discarded, bool use_base, Scratch& scratch) {
    const int64_t* slots = scratch.slots;
    cplx* first = scratch.fused;
    cplx* second = scratch.fresh;
    cplx* work = scratch.work;
    int64_t n = 0;
    bool started = false;
    bool in_first = true;
    if (use_base) {
        n = state.base_counts(row, j);
        copy_polygon(state.base_vertices.row(row, j), n, first, SCRATCH, "a relaxed base");
        started = true;
    }
    for (int64_t t = 0; t < k; ++t) {
        if (discarded[t]) continue;
        const int64_t slot = slots[t];
        const cplx* region = state.window_vertices.row(row, slot, j);
        const int64_t n_region = state.window_counts(row, slot, j);
        if (!started) {
            copy_polygon(region, n_region, first, SCRATCH, "a window region");
            n = n_region;
            started = true;
            continue;
        }
        if (in_first) {
            n = clip_convex(first, n, region, n_region, second, work);
        } else {
            n = clip_convex(second, n, region, n_region, first, work);
        }
        in_first = !in_first;
        if (n == 0) return {0, in_first};
    }
    return {n, in_first};
}

int64_t relaxed_union(const MapState& state, int64_t row, int64_t j, int64_t k, bool use_base,
                      int64_t q, Scratch& scratch) {
    check_capacity("the relaxed window's slots", k, MAX_WINDOW);
    check_capacity("the relaxed fusion's left-out slots", q, MAX_WINDOW);
    const int64_t* slots = scratch.slots;
    cplx* acc = scratch.acc;
    std::array<bool, MAX_WINDOW> discarded{};
    std::array<int64_t, MAX_WINDOW> combination{};
    int64_t n_acc = 0;
    for (int64_t t = 0; t < q; ++t) combination[t] = t;
    while (true) {
        for (int64_t t = 0; t < k; ++t) discarded[t] = false;
        for (int64_t t = 0; t < q; ++t) discarded[combination[t]] = true;
        auto [n, in_first] = intersect_kept(state, row, j, k, discarded.data(), use_base, scratch);
        if (n > 0) {
            const cplx* piece = in_first ? scratch.fused : scratch.fresh;
            if (n_acc == 0) {
                copy_polygon(piece, n, acc, SCRATCH, "the relaxed union");
                n_acc = n;
            } else {
                n_acc = merge_hull(acc, n_acc, SCRATCH, piece, n, scratch.cloud, scratch.hull);
            }
            for (int64_t t = 0; t < k; ++t) {
                if (!discarded[t]) state.window_inlier(row, slots[t], j) = true;
            }
        }
        // The next combination of q positions out of k, in lexicographic order.
        int64_t t = q - 1;
        while (t >= 0 && combination[t] == k - q + t) t -= 1;
        if (t < 0) return n_acc;
        combination[t] += 1;
        for (int64_t u = t + 1; u < q; ++u) combination[u] = combination[u - 1] + 1;
    }
}

std::pair<int64_t, int64_t> relaxed_region(const MapState& state, int64_t row, int64_t j, int64_t k,
                                           bool use_base, int64_t max_outliers, Scratch& scratch) {
    // Without a base, at least one region must be kept.
    const int64_t q_max = std::min(max_outliers, use_base ? k : k - 1);
    for (int64_t q = 0; q < q_max + 1; ++q) {
        const int64_t n = relaxed_union(state, row, j, k, use_base, q, scratch);
        if (n > 0) return {n, q};
    }
    return {0, q_max};
}

void solve_landmark(const MapState& state, int64_t row, int64_t j, const Params& params,
                    Scratch& scratch) {
    int64_t* slots = scratch.slots;
    cplx* acc = scratch.acc;
    const int64_t k = window_slots(state, row, j, slots);
    for (int64_t t = 0; t < k; ++t) state.window_inlier(row, slots[t], j) = false;
    const bool use_base = state.base_counts(row, j) > 0;
    int64_t n = 0;
    if (k > 0 || use_base) {
        n = relaxed_region(state, row, j, k, use_base, params.max_outliers, scratch).first;
        if (n == 0 && use_base) {
            // The base contradicts the window beyond the cap: it is dropped.
            state.base_counts(row, j) = 0;
            state.n_dropped(row, j) += 1;
            n = relaxed_region(state, row, j, k, false, params.max_outliers, scratch).first;
        }
    }
    if (n == 0 && k > 0) {
        // More than max_outliers regions disagree: keep the old region, or restart from
        // the newest movement's region alone.
        const int64_t newest = slots[k - 1];
        if (params.on_inconsistency == INCONSISTENCY_KEEP && state.counts(row, j) > 0) return;
        n = state.window_counts(row, newest, j);
        copy_polygon(state.window_vertices.row(row, newest, j), n, acc, SCRATCH, "a window region");
        state.window_inlier(row, newest, j) = true;
    }
    copy_polygon(acc, n, state.vertices.row(row, j), state.vertices.shape[2], "a landmark region");
    state.counts(row, j) = n;
    if (n > 0) {
        set_area_centroid(state, row, j, n);
    } else {
        state.areas(row, j) = INF;
        state.centroids(row, j) = complex_nan();
    }
}

void age_out_oldest(const MapState& state, int64_t row, Scratch& scratch) {
    const int64_t size = state.window_counts.shape[1];
    const int64_t slot = py_mod(state.window_next(row) - state.window_length(row), size);
    const int64_t n_mapped = state.window_counts.shape[2];
    for (int64_t j = 0; j < n_mapped; ++j) {
        const int64_t n_region = state.window_counts(row, slot, j);
        if (n_region == 0) continue;
        if (state.window_rejected(row, slot) || !state.window_inlier(row, slot, j)) {
            state.n_dropped(row, j) += 1;
            continue;
        }
        const cplx* region = state.window_vertices.row(row, slot, j);
        cplx* base = state.base_vertices.row(row, j);
        const int64_t n_base = state.base_counts(row, j);
        if (n_base == 0) {
            copy_polygon(region, n_region, base, state.base_vertices.shape[2], "a relaxed base");
            state.base_counts(row, j) = n_region;
            continue;
        }
        const int64_t n = clip_convex(base, n_base, region, n_region, scratch.fused, scratch.work);
        if (n > 0) {
            copy_polygon(scratch.fused, n, base, state.base_vertices.shape[2], "a relaxed base");
            state.base_counts(row, j) = n;
        } else {
            state.n_dropped(row, j) += 1;  // kept by another of the relaxed set's pieces only
        }
    }
    for (int64_t j = 0; j < n_mapped; ++j) state.window_counts(row, slot, j) = 0;
    state.window_length(row) -= 1;
}

bool keeps_every_region(const MapState& state, int64_t row, int64_t j) {
    const int64_t length = state.window_length(row), next_slot = state.window_next(row);
    const int64_t size = state.window_counts.shape[1];
    for (int64_t age = 0; age < length; ++age) {
        const int64_t slot = py_mod(next_slot - length + age, size);
        if (state.window_counts(row, slot, j) > 0 && !state.window_rejected(row, slot) &&
            !state.window_inlier(row, slot, j)) {
            return false;
        }
    }
    return true;
}

void reject_outlier_movements(const MapState& state, int64_t row, const Params& params,
                              Scratch& scratch) {
    const int64_t size = state.window_counts.shape[1];
    const int64_t n_mapped = state.window_counts.shape[2];
    bool changed = true;
    while (changed) {
        changed = false;
        const int64_t length = state.window_length(row);  // range() is evaluated once
        for (int64_t age = 0; age < length; ++age) {
            const int64_t slot =
                py_mod(state.window_next(row) - state.window_length(row) + age, size);
            if (state.window_rejected(row, slot)) continue;
            int64_t regions = 0;
            int64_t votes_out = 0;
            for (int64_t j = 0; j < n_mapped; ++j) {
                if (state.window_counts(row, slot, j) > 0) {
                    regions += 1;
                    if (!state.window_inlier(row, slot, j)) votes_out += 1;
                }
            }
            if (2 * votes_out <= regions) continue;
            state.window_rejected(row, slot) = true;
            changed = true;
            for (int64_t j = 0; j < n_mapped; ++j) {
                if (state.window_counts(row, slot, j) > 0 && state.window_inlier(row, slot, j)) {
                    solve_landmark(state, row, j, params, scratch);
                }
            }
        }
    }
}

bool relaxed_movement(const MapState& state, int64_t row, const int64_t* fresh_counts,
                      const Params& params, const Outputs& out, int64_t i, Scratch& scratch) {
    const int64_t size = state.window_counts.shape[1];
    const int64_t newest = py_mod(state.window_next(row) - 1, size);
    const int64_t n_mapped = state.window_counts.shape[2];
    for (int64_t j = 0; j < n_mapped; ++j) {
        const int64_t n_new = fresh_counts[j];
        state.window_inlier(row, newest, j) = n_new > 0;
        if (n_new == 0) continue;
        const int64_t n_old = state.counts(row, j);
        if (n_old > 0 && keeps_every_region(state, row, j)) {
            cplx* region = state.vertices.row(row, j);
            const int64_t n = clip_convex(region, n_old, state.window_vertices.row(row, newest, j),
                                          n_new, scratch.fused, scratch.work);
            if (n > 0) {
                copy_polygon(scratch.fused, n, region, state.vertices.shape[2],
                             "a landmark region");
                state.counts(row, j) = n;
                set_area_centroid(state, row, j, n);
                continue;
            }
        }
        solve_landmark(state, row, j, params, scratch);
    }
    reject_outlier_movements(state, row, params, scratch);
    const bool rejected = state.window_rejected(row, newest);
    const int64_t length = state.window_length(row), next_slot = state.window_next(row);
    for (int64_t j = 0; j < n_mapped; ++j) {
        int64_t left_out = state.n_dropped(row, j);
        for (int64_t age = 0; age < length; ++age) {
            const int64_t slot = py_mod(next_slot - length + age, size);
            if (state.window_counts(row, slot, j) > 0 &&
                (state.window_rejected(row, slot) || !state.window_inlier(row, slot, j))) {
                left_out += 1;
            }
        }
        state.outliers(row, j) = left_out;
        if (fresh_counts[j] > 0 && (rejected || !state.window_inlier(row, newest, j))) {
            out.landmark_status(i, j) = LANDMARK_INCONSISTENT;
        }
    }
    return rejected;
}

}  // namespace bearing::slam
