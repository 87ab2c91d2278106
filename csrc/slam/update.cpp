// bearing_env/slam/kernels/update.py in C++: one movement per map for a batch of maps,
// serial or on kept worker threads over contiguous blocks of rows (same branches, same
// order of operations as the numba kernels, so the same bits).
#include <bearing_core/slam/update.hpp>

#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include <bearing_core/core/errors.hpp>
#include <bearing_core/core/pymath.hpp>
#include <bearing_core/core/worker_pool.hpp>
#include <bearing_core/slam/frames.hpp>
#include <bearing_core/slam/fusion.hpp>
#include <bearing_core/slam/polygons.hpp>
#include <bearing_core/slam/robust.hpp>
#include <bearing_core/slam/scratch.hpp>

namespace bearing::slam {

namespace {

constexpr double INF = std::numeric_limits<double>::infinity();
constexpr double NaN = std::numeric_limits<double>::quiet_NaN();

// One movement's frame code and change of frames from the FR regions of L1 and L2.
int64_t frame_of(Buffers& buf, const Params& params, FrameChange& frame) {
    return change_of_frames(buf.fr[0], buf.fr_count[0], buf.fr[1], buf.fr_count[1], params.transfer,
                            params.edge_samples, buf, frame);
}

// Make room in map row's window for a new movement (ageing out the oldest when it is
// full); returns the new movement's slot.
int64_t open_window_slot(const MapState& state, int64_t row, Scratch& scratch) {
    const int64_t window = state.window_counts.shape[1];
    if (state.window_length(row) == window) age_out_oldest(state, row, scratch);
    const int64_t newest = state.window_next(row);
    state.window_rejected(row, newest) = false;
    for (int64_t j = 0; j < state.window_counts.shape[2]; ++j) {
        state.window_counts(row, newest, j) = 0;
    }
    state.window_next(row) = py_mod(newest + 1, window);
    state.window_length(row) += 1;
    return newest;
}

// Map row's robot region (the FR point R2 = 1 in FL) and heading.
void transfer_robot(const MapState& state, int64_t row, const FrameChange& frame, Buffers& buf) {
    Scratch& scratch = buf.scratch;
    cplx* fresh = scratch.fresh;
    const int64_t n_robot =
        transfer_region(buf.robot_point, 1, frame, scratch.cloud, scratch.hull, fresh);
    copy_polygon(fresh, n_robot, state.robot_vertices.row(row), state.robot_vertices.shape[1],
                 "the robot region");
    state.robot_counts(row) = n_robot;
    if (n_robot > 0) {
        auto [area, centroid] = area_centroid(fresh, n_robot);
        state.robot_area(row) = area;
        state.robot_centroid(row) = centroid;
    } else {
        state.robot_area(row) = INF;
        state.robot_centroid(row) = complex_nan();
    }
    // Heading: the FR x-axis seen through T at the vertex means of A_L1 and A_L2.
    cplx mean1(0.0, 0.0);
    for (int64_t v = 0; v < frame.n1; ++v) mean1 += frame.a1[v];
    cplx mean2(0.0, 0.0);
    for (int64_t v = 0; v < frame.n2; ++v) mean2 += frame.a2[v];
    const cplx chord =
        mean2 / static_cast<double>(frame.n2) - mean1 / static_cast<double>(frame.n1);
    state.robot_heading(row) = -std::atan2(chord.im, chord.re);
}

// Every landmark's FR region from one movement's bearings; returns the frame code the
// regions of L1 and L2 allow (FRAME_OK if both are bounded).
int64_t cone_regions(const double* bearings_start, const double* bearings_end, int64_t n_landmarks,
                     double epsilon, Buffers& buf) {
    for (int64_t j = 0; j < n_landmarks; ++j) {
        if (std::isnan(bearings_start[j]) || std::isnan(bearings_end[j])) {
            buf.fr_count[j] = 0;
            buf.fr_status[j] = FR_MISSING;
            continue;
        }
        auto [n, status] = cone_region(bearings_start[j], bearings_end[j], epsilon, buf.fr[j]);
        buf.fr_count[j] = n;
        buf.fr_status[j] = status;
    }
    if (buf.fr_status[0] == FR_MISSING) return FRAME_L1_MISSING;
    if (buf.fr_status[1] == FR_MISSING) return FRAME_L2_MISSING;
    if (buf.fr_status[0] != FR_BOUNDED) return FRAME_L1_UNBOUNDED;
    if (buf.fr_status[1] != FR_BOUNDED) return FRAME_L2_UNBOUNDED;
    return FRAME_OK;
}

// The end of update_row, once the movement's landmarks are fused into map row: count
// the frame change and the inconsistent landmarks (out row i), then place the robot by
// the frame change, or mark it unknown when that change was rejected. (Its own function
// so that update_row reads as the landmark loop it is; one call per map and movement.)
void finish_row(int64_t i, int64_t row, int64_t n_landmarks, const Params& params,
                const MapState& state, const Outputs& out, const FrameChange& frame, Buffers& buf) {
    state.n_frame_changes(row) += out.frame_status(i) == FRAME_OK ? 1 : 0;
    int64_t bad = 0;
    for (int64_t j = 0; j < n_landmarks - 2; ++j) {
        if (out.landmark_status(i, j) == LANDMARK_INCONSISTENT) bad += 1;
    }
    out.n_bad(i) = bad;
    state.n_inconsistent(row) += bad;
    if (!params.with_robot) return;
    if (out.frame_status(i) == FRAME_REJECTED) {
        // The frame change itself is the outlier: the robot's region is unknown.
        state.robot_counts(row) = 0;
        state.robot_area(row) = INF;
        state.robot_centroid(row) = complex_nan();
        state.robot_heading(row) = NaN;
        return;
    }
    transfer_robot(state, row, frame, buf);
    state.robot_fixed_at(row) = state.n_updates(row);
}

// Fuse one movement (bearings_start, bearings_end: n_landmarks each, read with the bound
// epsilon) into map row, reporting to out row i.
void update_row(int64_t i, int64_t row, const double* bearings_start, const double* bearings_end,
                int64_t n_landmarks, double epsilon, const Params& params, const MapState& state,
                const Outputs& out, Buffers& buf) {
    const bool relaxed = params.fusion == FUSION_RELAXED;
    const bool robust = params.fusion == FUSION_ROBUST;
    const bool keep = params.on_inconsistency == INCONSISTENCY_KEEP;
    Scratch& scratch = buf.scratch;
    int64_t* fresh_counts = buf.fresh_counts;
    state.n_updates(row) += 1;
    out.n_bad(i) = 0;
    for (int64_t j = 0; j < n_landmarks - 2; ++j) out.landmark_status(i, j) = LANDMARK_SKIPPED;
    out.frame_status(i) =
        static_cast<int8_t>(cone_regions(bearings_start, bearings_end, n_landmarks, epsilon, buf));
    if (out.frame_status(i) != FRAME_OK) return;
    FrameChange frame;
    const int64_t status = frame_of(buf, params, frame);
    out.frame_status(i) = static_cast<int8_t>(status);
    if (status != FRAME_OK) return;
    int64_t newest = 0;
    if (relaxed) newest = open_window_slot(state, row, scratch);
    const double rate = robust ? contamination(state, row) : 0.0;
    int64_t last = n_landmarks;
    if (robust && params.with_robot && frame_contradicts_robot(state, row, frame, scratch)) {
        out.frame_status(i) = FRAME_REJECTED;  // a misread L1 or L2: no landmark is fused
        last = 2;
    }
    for (int64_t j = 2; j < last; ++j) {
        const int64_t slot = j - 2;
        fresh_counts[slot] = 0;
        if (buf.fr_status[j] == FR_MISSING) {
            out.landmark_status(i, slot) = LANDMARK_MISSING;
            continue;
        }
        if (buf.fr_status[j] == FR_EMPTY) {
            out.landmark_status(i, slot) = LANDMARK_INCONSISTENT;
            continue;
        }
        if (buf.fr_status[j] != FR_BOUNDED) {
            out.landmark_status(i, slot) = LANDMARK_UNBOUNDED;
            continue;
        }
        const int64_t n_new = transfer_region(buf.fr[j], buf.fr_count[j], frame, scratch.cloud,
                                              scratch.hull, scratch.fresh);
        if (n_new < 3) {
            out.landmark_status(i, slot) = LANDMARK_UNBOUNDED;
            continue;
        }
        out.landmark_status(i, slot) = LANDMARK_UPDATED;
        if (relaxed) {
            copy_polygon(scratch.fresh, n_new, state.window_vertices.row(row, newest, slot),
                         state.window_vertices.shape[3], "a window region");
            state.window_counts(row, newest, slot) = n_new;
            fresh_counts[slot] = n_new;
        } else if (robust) {
            if (!robust_landmark(state, row, slot, n_new, rate, params, scratch)) {
                out.landmark_status(i, slot) = LANDMARK_INCONSISTENT;
            }
        } else if (!intersect_landmark(state, row, slot, n_new, keep, scratch)) {
            out.landmark_status(i, slot) = LANDMARK_INCONSISTENT;
        }
    }
    if (relaxed && relaxed_movement(state, row, fresh_counts, params, out, i, scratch)) {
        out.frame_status(i) = FRAME_REJECTED;
    }
    finish_row(i, row, n_landmarks, params, state, out, frame, buf);
}

// Fuse the movement just fused into map row (with the bound epsilon, as out row i
// reports) into its probe, at PROBE_SHRINK * epsilon; returns how many landmarks give
// evidence that the bound is too small.
int64_t probe_row(int64_t i, int64_t row, const double* bearings_start, const double* bearings_end,
                  int64_t n_landmarks, double epsilon, const Params& params, const MapState& state,
                  const Outputs& out, Buffers& buf) {
    if (out.frame_status(i) != FRAME_OK) return 0;
    Scratch& scratch = buf.scratch;
    int64_t status =
        cone_regions(bearings_start, bearings_end, n_landmarks, PROBE_SHRINK * epsilon, buf);
    if (status != FRAME_OK) return 0;
    FrameChange frame;
    status = frame_of(buf, params, frame);
    if (status != FRAME_OK) return 0;
    int64_t evidence = 0;
    for (int64_t j = 2; j < n_landmarks; ++j) {
        const int64_t slot = j - 2;
        const bool consistent_here = out.landmark_status(i, slot) == LANDMARK_UPDATED;
        if (buf.fr_status[j] == FR_EMPTY) {
            evidence += consistent_here ? 1 : 0;
            continue;
        }
        if (buf.fr_status[j] != FR_BOUNDED) continue;
        const int64_t n_new = transfer_region(buf.fr[j], buf.fr_count[j], frame, scratch.cloud,
                                              scratch.hull, scratch.fresh);
        if (n_new >= 3 && !probe_landmark(state, row, slot, n_new, scratch)) {
            evidence += consistent_here ? 1 : 0;
        }
    }
    return evidence;
}

// Fuse map row's kept movements again, oldest first, into empty regions, levels and
// probe at its (new) bound; out row i ends with what the newest one did.
void rebuild_row(int64_t i, int64_t row, int64_t n_landmarks, const Params& params,
                 const MapState& state, const Outputs& out, Buffers& buf) {
    const int64_t updates = state.n_updates(row) - 1;
    const int64_t changes = state.n_frame_changes(row) - (out.frame_status(i) == FRAME_OK ? 1 : 0);
    const int64_t inconsistent = state.n_inconsistent(row) - out.n_bad(i);
    const double epsilon = params.epsilon * state.noise_scale(row);
    forget_regions(state, row);
    const int64_t length = state.history_length(row);
    for (int64_t k = 0; k < length; ++k) {
        history_movement(state, row, k, buf.start, buf.end);
        update_row(i, row, buf.start, buf.end, n_landmarks, epsilon, params, state, out, buf);
        probe_row(i, row, buf.start, buf.end, n_landmarks, epsilon, params, state, out, buf);
    }
    const bool fixed_by_newest = state.robot_fixed_at(row) == state.n_updates(row);
    state.n_updates(row) = updates + 1;
    state.n_frame_changes(row) = changes + (out.frame_status(i) == FRAME_OK ? 1 : 0);
    state.n_inconsistent(row) = inconsistent + out.n_bad(i);
    // Older kept robot regions cannot be told apart from this movement's: none is older.
    state.robot_fixed_at(row) = fixed_by_newest ? state.n_updates(row) : -1;
}

[[noreturn]] void corrupt(int64_t row, const char* what) {
    throw std::invalid_argument("map " + std::to_string(row) + " has a corrupt state: " + what);
}

// A counter the update adds to: in [0, MAX_COUNTER], so the additions cannot overflow.
void check_counter(int64_t value, int64_t row, const char* what) {
    if (value < 0 || value > MAX_COUNTER) corrupt(row, what);
}

// The counters of map row that the update adds to (check_map).
void check_counters(const MapState& state, int64_t row, const Params& params) {
    check_counter(state.n_updates(row), row, "n_updates out of range");
    check_counter(state.n_frame_changes(row), row, "n_frame_changes out of range");
    check_counter(state.n_inconsistent(row), row, "n_inconsistent out of range");
    for (int64_t j = 0; j < state.counts.shape[1]; ++j) {
        if (params.fusion == FUSION_RELAXED) {
            check_counter(state.n_dropped(row, j), row, "n_dropped out of range");
        }
        if (params.fusion == FUSION_ROBUST) {
            check_counter(state.n_regions(row, j), row, "n_regions out of range");
        }
    }
    if (params.fusion == FUSION_ROBUST && params.estimate_bound) {
        check_counter(state.bound_events(row), row, "bound_events out of range");
    }
}

// The counts and positions of map row that the update indexes buffers with, and the
// counters it adds to (written by the kernels only, but a user can write the arrays):
// any out of range raises std::invalid_argument (a ValueError in Python) before the map
// is written.
void check_map(const MapState& state, int64_t row, const Params& params) {
    check_counters(state, row, params);
    const int64_t m = state.counts.shape[1];
    for (int64_t j = 0; j < m; ++j) {
        const int64_t n = state.counts(row, j);
        if (n < 0 || n > state.vertices.shape[2]) corrupt(row, "counts out of range");
    }
    const int64_t n_robot = state.robot_counts(row);
    if (n_robot < 0 || n_robot > state.robot_vertices.shape[1]) {
        corrupt(row, "robot_counts out of range");
    }
    if (params.fusion == FUSION_RELAXED) {
        const int64_t w = state.window_counts.shape[1];
        if (state.window_length(row) < 0 || state.window_length(row) > w) {
            corrupt(row, "window_length out of range");
        }
        if (state.window_next(row) < 0 || state.window_next(row) >= w) {
            corrupt(row, "window_next out of range");
        }
        for (int64_t slot = 0; slot < w; ++slot) {
            for (int64_t j = 0; j < m; ++j) {
                const int64_t n = state.window_counts(row, slot, j);
                if (n < 0 || n > state.window_vertices.shape[3]) {
                    corrupt(row, "window_counts out of range");
                }
            }
        }
        for (int64_t j = 0; j < m; ++j) {
            const int64_t n = state.base_counts(row, j);
            if (n < 0 || n > state.base_vertices.shape[2]) corrupt(row, "base_counts out of range");
        }
    }
    if (params.fusion == FUSION_ROBUST) {
        for (int64_t j = 0; j < m; ++j) {
            if (state.n_regions(row, j) < 0) corrupt(row, "n_regions negative");
            for (int64_t k = 0; k < state.level_counts.shape[2]; ++k) {
                const int64_t n = state.level_counts(row, j, k);
                if (n < 0 || n > state.level_vertices.shape[3]) {
                    corrupt(row, "level_counts out of range");
                }
            }
        }
        if (!(state.noise_scale(row) > 0.0) || !std::isfinite(state.noise_scale(row))) {
            corrupt(row, "noise_scale not a positive number");
        }
        if (params.estimate_bound) {
            const int64_t h = state.history_bearings.shape[1];
            for (int64_t j = 0; j < m; ++j) {
                const int64_t n = state.probe_counts(row, j);
                if (n < 0 || n > state.probe_vertices.shape[2]) {
                    corrupt(row, "probe_counts out of range");
                }
            }
            if (state.history_length(row) < 0 || state.history_length(row) > h) {
                corrupt(row, "history_length out of range");
            }
            if (state.history_next(row) < 0 || state.history_next(row) >= h) {
                corrupt(row, "history_next out of range");
            }
        }
    }
}

// update_maps for bearings rows first to stop, in one thread's buffers.
void update_rows(int64_t first, int64_t stop, View2<const double> bearings_start,
                 View2<const double> bearings_end, View1<const int64_t> rows, const Params& params,
                 const MapState& state, const Outputs& out, Buffers& buf) {
    const bool estimating = params.fusion == FUSION_ROBUST && params.estimate_bound;
    const int64_t n_landmarks = bearings_start.shape[1];
    // As update.py's _new_buffers: zeroed counts, the FR robot point R2 = 1.
    for (int64_t j = 0; j < n_landmarks; ++j) buf.fresh_counts[j] = 0;
    buf.robot_point[0] = cplx(1.0, 0.0);
    for (int64_t i = first; i < stop; ++i) {
        const int64_t row = rows(i);
        check_map(state, row, params);
        double epsilon = params.epsilon;
        if (estimating) epsilon *= state.noise_scale(row);
        const double* start = bearings_start.row(i);
        const double* end = bearings_end.row(i);
        update_row(i, row, start, end, n_landmarks, epsilon, params, state, out, buf);
        if (!estimating) continue;
        push_history(state, row, start, end);
        const int64_t evidence =
            probe_row(i, row, start, end, n_landmarks, epsilon, params, state, out, buf);
        if (evidence > 0) {
            state.bound_events(row) += evidence;
            if (grow_bound(state, row, params.epsilon)) {
                rebuild_row(i, row, n_landmarks, params, state, out, buf);
            }
        }
    }
}

}  // namespace

Buffers& thread_buffers() {
    thread_local std::unique_ptr<Buffers> buffers;
    if (!buffers) buffers = std::make_unique<Buffers>();
    return *buffers;
}

int64_t change_of_frames(const cplx* a1, int64_t n1, const cplx* a2, int64_t n2, int64_t transfer,
                         int64_t edge_samples, Buffers& buf, FrameChange& frame) {
    const bool conservative = transfer != TRANSFER_PAPER;
    const bool local = transfer == TRANSFER_CONSERVATIVE;
    const FramePlan plan = frame_plan(a1, n1, a2, n2, conservative, edge_samples);
    int64_t n_pairs = 0;
    if (plan.status == FRAME_OK) {
        n_pairs = sample_hypotheses(a1, n1, a2, n2, plan.per_edge, buf.h1, buf.inv_d);
        if (local) plan_sub_squares(a1, n1, a2, n2, plan.per_edge, buf.sub);
    }
    frame.a1 = a1;
    frame.n1 = n1;
    frame.a2 = a2;
    frame.n2 = n2;
    frame.h1 = buf.h1;
    frame.inv_d = buf.inv_d;
    frame.n_pairs = n_pairs;
    frame.conservative = conservative;
    frame.local = local && plan.status == FRAME_OK ? &buf.sub : nullptr;
    frame.distance = plan.distance;
    frame.delta1 = plan.delta1;
    frame.delta2 = plan.delta2;
    return plan.status;
}

void update_maps(View2<const double> bearings_start, View2<const double> bearings_end,
                 View1<const int64_t> rows, const Params& params, const MapState& state,
                 const Outputs& out, int64_t threads) {
    const int64_t n_rows = rows.shape[0];
    check_capacity("landmarks per movement", bearings_start.shape[1], MAX_LANDMARKS);
    if (bearings_start.shape[1] != state.counts.shape[1] + 2 ||
        bearings_end.shape[1] != bearings_start.shape[1] || bearings_start.shape[0] < n_rows ||
        bearings_end.shape[0] < n_rows || out.frame_status.shape[0] < n_rows ||
        out.n_bad.shape[0] < n_rows || out.landmark_status.shape[0] < n_rows ||
        out.landmark_status.shape[1] != state.counts.shape[1]) {
        throw std::invalid_argument("update_maps: bearings or outputs of the wrong shape");
    }
    for (int64_t i = 0; i < n_rows; ++i) {
        if (rows(i) < 0 || rows(i) >= state.counts.shape[0]) {
            throw std::invalid_argument("update_maps: rows out of range");
        }
    }
    if (n_rows == 0) return;
    const int64_t blocks = std::max<int64_t>(1, std::min(threads, n_rows));
    if (blocks == 1) {
        update_rows(0, n_rows, bearings_start, bearings_end, rows, params, state, out,
                    thread_buffers());
        return;
    }
    // Blocks as update_maps_parallel splits them; block 0 on the calling thread, the
    // others on the pool's kept workers (and their kept buffers). Each map is computed by
    // the same code, so the result does not depend on `threads`.
    core::WorkerPool::run(blocks, [&](int64_t block) {
        const int64_t first = block * n_rows / blocks;
        const int64_t stop = (block + 1) * n_rows / blocks;
        update_rows(first, stop, bearings_start, bearings_end, rows, params, state, out,
                    thread_buffers());
    });
}

int64_t check_indices(const int64_t* indices, int64_t n, int64_t size, bool distinct, bool* seen) {
    if (distinct) {
        for (int64_t k = 0; k < size; ++k) seen[k] = false;
    }
    for (int64_t k = 0; k < n; ++k) {
        const int64_t index = indices[k];
        if (index < 0 || index >= size) return INDEX_OUT_OF_RANGE;
        if (distinct) {
            if (seen[index]) return INDEX_REPEATED;
            seen[index] = true;
        }
    }
    return INDEX_OK;
}

void contains_points(View3<const cplx> vertices, View2<const int64_t> counts,
                     View1<const int64_t> rows, View2<const cplx> points, double relative,
                     View2<bool> out) {
    for (int64_t i = 0; i < rows.shape[0]; ++i) {
        for (int64_t j = 0; j < points.shape[1]; ++j) {
            const int64_t n = counts(rows(i), j);
            out(i, j) =
                n > 0 && contains_point(vertices.row(rows(i), j), n, points(i, j), relative);
        }
    }
}

}  // namespace bearing::slam
