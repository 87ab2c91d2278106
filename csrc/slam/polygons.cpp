// Convex polygons in fixed-capacity arrays: a function-for-function port of
// bearing_env/slam/kernels/polygons.py (same operations in the same order, so the same
// bits). Temporary arrays the numba kernels allocate are small fixed-capacity arrays on
// the stack here, or, for the hulls' (up to MAX_HULL_POINTS points), per-thread heap
// arrays (core/workspace.hpp); either way sized by the documented maxima and guarded by
// check_capacity.
#include <bearing_core/slam/polygons.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

#include <bearing_core/core/errors.hpp>
#include <bearing_core/core/workspace.hpp>

namespace bearing::slam {

namespace {

// -1j as Python folds the literal: complex(-0.0, -1.0).
constexpr cplx MINUS_I{-0.0, -1.0};

// How x compares with tol * abs(d) (hypot), decided without hypot when that is
// conclusive: -1 if certainly x <= tol * abs(d), +1 if certainly x > tol * abs(d), 0 if
// not certain (the caller then evaluates the original expression). Only for tol > 0
// finite and d finite (span = |d.re| + |d.im| finite):
// - x <= 0: tol * abs(d) is in [+0, inf] (abs(d) is, tol finite > 0: no NaN), so x <= it.
// - x > bound = tol * span * 2.0 with bound in [2^-1000, inf): the exact length r is at
//   most |d.re| + |d.im| <= span (1 + u) (u = 2^-53), hypot within one ulp (2u relative)
//   of r, and tol * abs(d) rounds by (1 + u) at most (it is normal: abs(d) >= span / 1.5,
//   so tol * abs(d) >= bound / 3 >= 2^-1002), so tol * abs(d) <= tol * span (1 + 5u),
//   while bound (its product normal, doubling exact) >= 2 tol span (1 - u). So
//   x > bound > tol * abs(d).
inline int versus_scaled_length(double x, double tol, cplx d) {
    constexpr double INF = std::numeric_limits<double>::infinity();
    const double span = std::fabs(d.re) + std::fabs(d.im);
    if (!(tol > 0.0 && tol < INF && span < INF)) return 0;
    if (x <= 0.0) return -1;
    const double bound = tol * span * 2.0;
    if (bound >= 0x1p-1000 && bound < INF && x > bound) return 1;
    return 0;
}

// Whether b fails to turn left by more than tol on the way from a to c.
inline bool within_chord(cplx a, cplx b, cplx c, double tol) {
    const double turn = cross(b - a, c - a);
    if (tol == 0.0) return turn <= 0.0;
    const int side = versus_scaled_length(turn, tol, c - a);  // turn <= tol * abs(c - a)
    if (side != 0) return side < 0;
    return turn <= tol * abs(c - a);
}

inline bool separated(const cplx* p, int64_t n_p, const cplx* q, int64_t n_q, cplx axis) {
    double lo_p = dot(axis, p[0]), hi_p = lo_p;
    for (int64_t i = 1; i < n_p; ++i) {
        const double v = dot(axis, p[i]);
        lo_p = std::min(lo_p, v);
        hi_p = std::max(hi_p, v);
    }
    double lo_q = dot(axis, q[0]), hi_q = lo_q;
    for (int64_t i = 1; i < n_q; ++i) {
        const double v = dot(axis, q[i]);
        lo_q = std::min(lo_q, v);
        hi_q = std::max(hi_q, v);
    }
    return lo_q > hi_p || lo_p > hi_q;
}

// convex_hull's temporaries: its candidates' indices (the upper side's gathered apart
// first), its task stack and the copy of its hull (about 490 KB at MAX_HULL_POINTS points:
// too much for a thread's stack).
struct HullWorkspace {
    ScratchArray<int64_t> index, upper, task_start, task_end, chain_from, chain_to, task_far;
    ScratchArray<cplx> candidates;
};

// The monotone chain's temporaries (hull_indices' sort order and the merge's second
// buffer, the chain's points, and the chain that small_convex_hull and
// small_hull_indices read back).
struct ChainWorkspace {
    ScratchArray<int64_t> order, merged, run_start, chosen;
    ScratchArray<cplx> chain;
};

HullWorkspace& hull_workspace() {
    thread_local HullWorkspace workspace;
    return workspace;
}

ChainWorkspace& chain_workspace() {
    thread_local ChainWorkspace workspace;
    return workspace;
}

// convex_hull is a quickhull; its steps follow, each with its arithmetic as it was in
// the one function (and as numba's kernel has it), operation for operation.

// The first of the lowest-x (then lowest-y) points and the first of the highest-x (then
// highest-y) points: the ends of the lower and upper chains.
inline void extreme_points(const cplx* points, int64_t n_points, int64_t& first, int64_t& last) {
    cplx lo = points[first], hi = points[last];
    for (int64_t i = 1; i < n_points; ++i) {
        const cplx p = points[i];
        if (p.re < lo.re || (p.re == lo.re && p.im < lo.im)) {
            first = i;
            lo = p;
        }
        if (p.re > hi.re || (p.re == hi.re && p.im > hi.im)) {
            last = i;
            hi = p;
        }
    }
}

// Sort the points' indices into `index` by side of a -> b: the lower side (right of it)
// first, n_lower of them, then the upper side, n_upper (gathered in `upper` first, in the
// same pass); the rest are on the line. Returns
// the slot of the lower side's farthest candidate (-1 if it has none).
// The lower chain's task (a -> b) would find that candidate by its scan, whose expression
// bx * (p.im - ay) - by * (p.re - ax), with ax, ay = a and bx, by = b - a, is
// cross(b - a, p - a) operation for operation, over these candidates, in this order (the
// first minimum wins, as in the scan). Each point's side is computed once (numba
// evaluated the same expression again for the upper side: the same value).
inline int64_t split_sides(const cplx* points, int64_t n_points, cplx a, cplx b, int64_t* upper,
                           int64_t* index, int64_t& n_lower, int64_t& n_upper) {
    int64_t far_lower = -1;
    double min_lower = 0.0;
    for (int64_t i = 0; i < n_points; ++i) {
        const double side = cross(b - a, points[i] - a);
        if (side < 0.0) {
            if (side < min_lower) {
                min_lower = side;
                far_lower = n_lower;
            }
            index[n_lower] = i;
            n_lower += 1;
        } else if (side > 0.0) {
            upper[n_upper] = i;
            n_upper += 1;
        }
    }
    std::copy(upper, upper + n_upper, index + n_lower);
    return far_lower;
}

// convex_hull's stack of tasks: hull the chain from point chain_from to chain_to over the
// candidates index[start:end]; a task with start < 0 emits point chain_from instead.
// task_far: the slot of the task's farthest candidate when its parent found it while
// partitioning (-1: the task scans for it).
struct HullTasks {
    int64_t* task_start;
    int64_t* task_end;
    int64_t* chain_from;
    int64_t* chain_to;
    int64_t* task_far;

    void chain(int64_t slot, int64_t start, int64_t end, int64_t from, int64_t to,
               int64_t far) const {
        task_start[slot] = start;
        task_end[slot] = end;
        chain_from[slot] = from;
        chain_to[slot] = to;
        task_far[slot] = far;
    }
    void emit(int64_t slot, int64_t from) const {
        task_start[slot] = -1;
        chain_from[slot] = from;
    }
};

// The slot in index[start:end] of the candidate farthest right of the line from (ax, ay)
// along (bx, by): the first minimum of its side, or `start` if none is right of it.
inline int64_t farthest_right(const cplx* points, const int64_t* index, int64_t start, int64_t end,
                              double ax, double ay, double bx, double by) {
    int64_t far = start;
    double far_side = 0.0;
    for (int64_t j = start; j < end; ++j) {
        const cplx p = points[index[j]];
        const double side = bx * (p.im - ay) - by * (p.re - ax);
        if (side < far_side) {
            far_side = side;
            far = j;
        }
    }
    return far;
}

// Move the candidates of index[start:end] right of the line from (ax, ay) along (bx, by)
// to the front of the range, in the order they are met (each goes to the next slot; no
// later swap reaches it); returns how many, with `far` the slot of the farthest of them
// (the first minimum of its side, -1 if none). The side's expression is farthest_right's,
// operation for operation, so `far` is the slot that the child task's scan would find.
inline int64_t partition_right(const cplx* points, int64_t* index, int64_t start, int64_t end,
                               double ax, double ay, double bx, double by, int64_t& far) {
    int64_t n = 0;
    double min_side = 0.0;
    far = -1;
    for (int64_t j = start; j < end; ++j) {
        const cplx p = points[index[j]];
        const double side = bx * (p.im - ay) - by * (p.re - ax);
        if (side < 0.0) {
            if (side < min_side) {
                min_side = side;
                far = start + n;
            }
            std::swap(index[start + n], index[j]);
            n += 1;
        }
    }
    return n;
}

// Run convex_hull's three first tasks (in slots 0 to 2) and every task they push, writing
// the hull's vertices after out[0]; returns how many out holds.
int64_t run_hull_tasks(const cplx* points, int64_t n_points, int64_t* index, const HullTasks& tasks,
                       int64_t size, cplx* out) {
    int64_t top = 3;
    int64_t k = 1;
    while (top > 0) {
        top -= 1;
        const int64_t start = tasks.task_start[top], end = tasks.task_end[top],
                      i_from = tasks.chain_from[top], i_to = tasks.chain_to[top];
        if (start < 0) {
            check_capacity("convex_hull output", k + 1, n_points + 1);
            out[k] = points[i_from];
            k += 1;
            continue;
        }
        if (end <= start) continue;
        const double ax = points[i_from].re, ay = points[i_from].im;
        int64_t far = tasks.task_far[top];
        if (far < 0) {
            const double bx = points[i_to].re - ax, by = points[i_to].im - ay;
            far = farthest_right(points, index, start, end, ax, ay, bx, by);
        }
        const int64_t i_far = index[far];
        const double cx = points[i_far].re, cy = points[i_far].im;
        // Right of a -> c to the front, then right of c -> b; the rest is inside. Each
        // partition finds its child task's farthest candidate (the child a -> c has
        // ax, ay = a and bx, by = c - a = ux, uy; the child c -> b has ax, ay = c and
        // bx, by = b - c = vx, vy).
        const double ux = cx - ax, uy = cy - ay;
        int64_t far_left = -1, far_right = -1;
        const int64_t n_left = partition_right(points, index, start, end, ax, ay, ux, uy, far_left);
        const int64_t mid = start + n_left;
        const double vx = points[i_to].re - cx, vy = points[i_to].im - cy;
        const int64_t n_right = partition_right(points, index, mid, end, cx, cy, vx, vy, far_right);
        check_capacity("convex_hull task stack", top + 3, size);
        tasks.chain(top, mid, mid + n_right, i_far, i_to, far_right);
        tasks.emit(top + 1, i_far);
        tasks.chain(top + 2, start, mid, i_from, i_far, far_left);
        top += 3;
    }
    return k;
}

}  // namespace

// --------------------------------------------------------------------------------------
// Convex hulls
// --------------------------------------------------------------------------------------

int64_t convex_hull(const cplx* points, int64_t n_points, cplx* out) {
    if (n_points == 0) return 0;
    check_capacity("convex_hull points", n_points, MAX_HULL_POINTS);
    int64_t first = 0, last = 0;
    extreme_points(points, n_points, first, last);
    const cplx a = points[first], b = points[last];
    out[0] = a;
    if (a == b) return 1;
    HullWorkspace& work = hull_workspace();
    // Candidate indices, the lower side (right of a -> b) first, then the upper side.
    int64_t* const index = work.index.at_least(n_points);
    int64_t n_lower = 0, n_upper = 0;
    const int64_t far_lower =
        split_sides(points, n_points, a, b, work.upper.at_least(n_points), index, n_lower, n_upper);
    const int64_t size = 2 * n_points + 4;
    const HullTasks tasks{work.task_start.at_least(size), work.task_end.at_least(size),
                          work.chain_from.at_least(size), work.chain_to.at_least(size),
                          work.task_far.at_least(size)};
    tasks.chain(0, n_lower, n_lower + n_upper, last, first, -1);  // the upper chain, b -> a
    tasks.emit(1, last);
    tasks.chain(2, 0, n_lower, first, last, far_lower);  // the lower chain, a -> b
    const int64_t k = run_hull_tasks(points, n_points, index, tasks, size, out);
    // out[:k] is copied (the small hull writes out; the slots it does not rewrite keep
    // the quickhull's vertices, as in numba) into storage not zero-filled first.
    cplx* const candidates = work.candidates.at_least(k);
    std::copy(out, out + k, candidates);
    const auto [extent, magnitude] = scale_of(candidates, k);
    return small_convex_hull(candidates, k, out, tolerance_of(extent, magnitude));
}

namespace {

// Whether point a comes before point b in the monotone chain's order: by x, then y, then
// index. For points without NaN this is a strict total order, and numba's stable
// insertion sort by (x, y) puts equal points in index order: so any sort by it gives
// numba's order exactly.
inline bool comes_before(const cplx* points, int64_t a, int64_t b) {
    const cplx p = points[a], q = points[b];
    if (p.re != q.re) return p.re < q.re;
    if (p.im != q.im) return p.im < q.im;
    return a < b;
}

// numba's insertion sort by (x, y), kept for points with a NaN (whose comparisons are no
// order, so only this loop gives numba's result).
void insertion_sort(const cplx* points, int64_t n_points, int64_t* order) {
    for (int64_t i = 0; i < n_points; ++i) {
        const cplx p = points[i];
        int64_t j = i;
        while (j > 0) {
            const cplx q = points[order[j - 1]];
            if (q.re < p.re || (q.re == p.re && q.im <= p.im)) break;
            order[j] = order[j - 1];
            j -= 1;
        }
        order[j] = i;
    }
}

// Split 0..n_points into maximal runs, each ascending or descending in comes_before
// order, written ascending into order (a descending run reversed); run_start gets each
// run's first slot and, last, n_points. Returns the number of runs. The points a hull
// sees come in few runs: a quickhull's output is its lower chain (ascending) then its
// upper chain (descending), and samples along a boundary trace a closed curve.
int64_t find_runs(const cplx* points, int64_t n_points, int64_t* order, int64_t* run_start) {
    int64_t runs = 0;
    for (int64_t i = 0; i < n_points;) {
        int64_t j = i + 1;
        if (j < n_points && comes_before(points, j, i)) {
            while (j + 1 < n_points && comes_before(points, j + 1, j)) j += 1;
            j += 1;
            for (int64_t v = i; v < j; ++v) order[v] = i + j - 1 - v;
        } else {
            while (j < n_points && comes_before(points, j - 1, j)) j += 1;
            for (int64_t v = i; v < j; ++v) order[v] = v;
        }
        run_start[runs] = i;
        runs += 1;
        i = j;
    }
    run_start[runs] = n_points;
    return runs;
}

// Merge from[lo:mid] and from[mid:hi] (each ascending in comes_before order) into to[lo:hi].
inline void merge_runs(const cplx* points, const int64_t* from, int64_t lo, int64_t mid, int64_t hi,
                       int64_t* to) {
    int64_t a = lo, b = mid, k = lo;
    while (a < mid && b < hi)
        to[k++] = comes_before(points, from[b], from[a]) ? from[b++] : from[a++];
    while (a < mid) to[k++] = from[a++];
    while (b < hi) to[k++] = from[b++];
}

// Whether any coordinate of points[:n_points] is NaN.
bool any_nan(const cplx* points, int64_t n_points) {
    for (int64_t i = 0; i < n_points; ++i) {
        if (std::isunordered(points[i].re, points[i].im)) return true;  // either is NaN
    }
    return false;
}

// Insertion sort of order[:n_points] (a permutation of 0..n_points - 1) by comes_before:
// cheap when order is nearly sorted already, as the previous row's order is for the
// next row of sample_hypotheses' images.
void sort_from(const cplx* points, int64_t n_points, int64_t* order) {
    for (int64_t i = 1; i < n_points; ++i) {
        const int64_t index = order[i];
        int64_t j = i;
        while (j > 0 && comes_before(points, index, order[j - 1])) {
            order[j] = order[j - 1];
            j -= 1;
        }
        order[j] = index;
    }
}

// The indices of points[:n_points] in numba's order (see comes_before), by merging the
// input's runs pairwise; returns the array that holds them (work.order or work.merged).
int64_t* merge_sort_runs(const cplx* points, int64_t n_points, ChainWorkspace& work) {
    int64_t* order = work.order.at_least(n_points);
    int64_t* run_start = work.run_start.at_least(n_points + 1);
    int64_t runs = find_runs(points, n_points, order, run_start);
    int64_t* merged = work.merged.at_least(n_points);
    while (runs > 1) {
        int64_t kept = 0;
        for (int64_t r = 0; r < runs; r += 2) {
            const int64_t lo = run_start[r];
            if (r + 1 < runs) {
                merge_runs(points, order, lo, run_start[r + 1], run_start[r + 2], merged);
            } else {
                std::copy(order + lo, order + n_points, merged + lo);
            }
            run_start[kept] = lo;
            kept += 1;
        }
        run_start[kept] = n_points;
        runs = kept;
        std::swap(order, merged);
    }
    return order;
}

// Andrew's monotone chain as numba's small_hull_indices runs it, over points[:n_points]
// taken in `order` (sorted as numba sorts them), into `out`. The chain's points are kept
// beside their indices (`stack`, 2 * n_points slots), read without indirection. With
// EXACT, tol is 0 and within_chord is its sign test.
template <bool EXACT>
int64_t monotone_chain(const cplx* points, int64_t n_points, const int64_t* order, double tol,
                       int64_t* out, cplx* stack) {
    const auto pops = [tol](cplx a, cplx b, cplx c) {
        if constexpr (EXACT) return cross(b - a, c - a) <= 0.0;
        return within_chord(a, b, c, tol);
    };
    int64_t k = 0;
    for (int64_t j = 0; j < n_points; ++j) {  // lower chain
        const cplx p = points[order[j]];
        while (k >= 2 && pops(stack[k - 2], stack[k - 1], p)) k -= 1;
        out[k] = order[j];
        stack[k] = p;
        k += 1;
    }
    const int64_t lower = k + 1;
    for (int64_t j = n_points - 2; j > -1; --j) {  // upper chain
        const cplx p = points[order[j]];
        while (k >= lower && pops(stack[k - 2], stack[k - 1], p)) k -= 1;
        out[k] = order[j];
        stack[k] = p;
        k += 1;
    }
    k -= 1;  // the last point repeats the first
    if (k == 2 && points[out[0]] == points[out[1]]) return 1;
    return std::max(k, int64_t{1});
}

// Up to this many points, numba's insertion sort costs less than finding and merging runs,
// or than checking for NaN before sorting from a seed (the paper transfer's 4 samples).
constexpr int64_t SMALL_SORT = 8;

// small_hull_indices' hull into `out` of `capacity` (2 * n_points suffices: when rounding
// makes the lower and upper chains disagree on nearly collinear points, both keep a
// point; each point is pushed once per chain at most, so the chain holds at most
// 2 * n_points - 1 indices before its last is dropped). `seed`, if not null, holds a
// permutation of 0..n_points - 1 to start the sort from, and is left sorted; else the
// input's runs are merged (a quickhull's output is two: its lower chain, ascending, then
// its upper chain, descending). The same order either way (comes_before), unless a
// point has a NaN: then numba's own insertion sort, as for a few points.
int64_t hull_indices(const cplx* points, int64_t n_points, int64_t* out, double tol,
                     int64_t capacity, int64_t* seed = nullptr) {
    if (n_points <= 0) return 0;
    check_capacity("small_hull_indices points", n_points, MAX_HULL_POINTS);
    check_capacity("small_hull_indices chain", 2 * n_points - 1, capacity);
    ChainWorkspace& work = chain_workspace();
    const int64_t* order = nullptr;
    if (n_points <= SMALL_SORT || any_nan(points, n_points)) {
        int64_t* const sorted = seed != nullptr ? seed : work.order.at_least(n_points);
        insertion_sort(points, n_points, sorted);
        order = sorted;
    } else if (seed != nullptr) {
        sort_from(points, n_points, seed);
        order = seed;
    } else {
        order = merge_sort_runs(points, n_points, work);
    }
    cplx* const stack = work.chain.at_least(2 * n_points);
    if (tol == 0.0) return monotone_chain<true>(points, n_points, order, tol, out, stack);
    return monotone_chain<false>(points, n_points, order, tol, out, stack);
}

}  // namespace

// Slots of the chain buffer: a chain of any accepted input fits (see hull_indices).
constexpr int64_t CHAIN_SLOTS = 2 * MAX_HULL_POINTS;

// The chains of small_convex_hull and small_hull_indices run in a buffer of their own
// (numba's kernels wrote past their n_points + 1 slots in the disagreeing case above,
// corrupting the heap); only a hull of more than n_points + 1 vertices, which would
// overflow the caller's `out`, raises CapacityError.
int64_t small_convex_hull(const cplx* points, int64_t n_points, cplx* out, double tol) {
    int64_t* const chosen = chain_workspace().chosen.at_least(CHAIN_SLOTS);
    const int64_t k = hull_indices(points, n_points, chosen, tol, CHAIN_SLOTS);
    check_capacity("small_convex_hull output", k, n_points + 1);
    for (int64_t v = 0; v < k; ++v) out[v] = points[chosen[v]];
    return k;
}

int64_t small_hull_indices(const cplx* points, int64_t n_points, int64_t* out, double tol,
                           int64_t* order) {
    int64_t* const chosen = chain_workspace().chosen.at_least(CHAIN_SLOTS);
    const int64_t k = hull_indices(points, n_points, chosen, tol, CHAIN_SLOTS, order);
    check_capacity("small_hull_indices output", k, n_points + 1);
    std::copy(chosen, chosen + k, out);
    return k;
}

// --------------------------------------------------------------------------------------
// Area, centroid, containment, distance
// --------------------------------------------------------------------------------------

std::pair<double, cplx> area_centroid(const cplx* poly, int64_t n) {
    const cplx origin = poly[0];
    double twice_area = 0.0;
    cplx weighted(0.0, 0.0);
    for (int64_t i = 1; i < n - 1; ++i) {
        const cplx a = poly[i] - origin;
        const cplx b = poly[i + 1] - origin;
        const double c = cross(a, b);
        twice_area += c;
        weighted += (a + b) * c;
    }
    if (twice_area > 0.0) return {0.5 * twice_area, origin + weighted / (3.0 * twice_area)};
    cplx mean(0.0, 0.0);
    for (int64_t i = 0; i < n; ++i) mean += poly[i];
    return {0.0, mean / static_cast<double>(n)};
}

bool contains_point(const cplx* poly, int64_t n, cplx point, double relative) {
    const auto [size, magnitude] = scale_of(poly, n);
    const double tol = relative * size + 4e-16 * std::max(magnitude, abs(point));
    if (n == 1) return length_at_most(point - poly[0], tol);
    for (int64_t i = 0; i < n; ++i) {
        const cplx a = poly[i];
        const cplx edge = poly[py_mod(i + 1, n)] - a;
        const double length = abs(edge);
        if (length == 0.0) continue;
        if (cross(edge, point - a) / length < -tol) return false;
    }
    if (n == 2) {  // a segment: also within its ends
        const cplx edge = poly[1] - poly[0];
        const double t = dot(point - poly[0], edge) / dot(edge, edge);
        const double length = abs(edge);
        return -tol / length <= t && t <= 1.0 + tol / length;
    }
    return true;
}

double polygon_distance(const cplx* p, int64_t n_p, const cplx* q, int64_t n_q) {
    bool sep = false;
    for (int64_t i = 0; i < n_p; ++i) {
        if (separated(p, n_p, q, n_q, MINUS_I * (p[py_mod(i + 1, n_p)] - p[i]))) {
            sep = true;
            break;
        }
    }
    if (!sep) {
        for (int64_t i = 0; i < n_q; ++i) {
            if (separated(p, n_p, q, n_q, MINUS_I * (q[py_mod(i + 1, n_q)] - q[i]))) {
                sep = true;
                break;
            }
        }
    }
    if (!sep) {
        for (int64_t i = 0; i < n_p; ++i) {
            for (int64_t j = 0; j < n_q; ++j) {
                if (separated(p, n_p, q, n_q, q[j] - p[i])) {
                    sep = true;
                    break;
                }
            }
            if (sep) break;
        }
    }
    if (!sep) return 0.0;
    double gap = std::numeric_limits<double>::infinity();
    for (int64_t i = 0; i < n_p; ++i) {
        for (int64_t j = 0; j < n_q; ++j) {
            gap = std::min(gap, point_segment_distance(p[i], q[j], q[py_mod(j + 1, n_q)]));
            gap = std::min(gap, point_segment_distance(q[j], p[i], p[py_mod(i + 1, n_p)]));
        }
    }
    return gap;
}

double longest_edge(const cplx* poly, int64_t n) {
    double longest = 0.0;
    for (int64_t i = 0; i < n; ++i)
        longest = std::max(longest, abs(poly[py_mod(i + 1, n)] - poly[i]));
    return longest;
}

// --------------------------------------------------------------------------------------
// Cleaning, capacity and clipping
// --------------------------------------------------------------------------------------

int64_t simplify(cplx* poly, int64_t n, double tol) {
    bool changed = true;
    while (changed && n >= 3) {
        changed = false;
        int64_t k = 0;
        for (int64_t i = 0; i < n; ++i) {
            const cplx prev = k > 0 ? poly[k - 1] : poly[n - 1];
            const cplx nxt = poly[py_mod(i + 1, n)];
            const cplx v = poly[i];
            const cplx chord = nxt - prev;
            // (the chord's length, a pure function of chord, is needed only when the
            // first test fails)
            if (length_at_most(v - prev, tol)) {
                changed = true;
                continue;
            }
            // When fabs(cross) <= tol * length is certainly false (versus_scaled_length),
            // so is the whole test, and the length is not needed.
            const double off = std::fabs(cross(chord, v - prev));
            if (versus_scaled_length(off, tol, chord) <= 0) {
                const double length = abs(chord);
                if (length > 0.0 && off <= tol * length && dot(v - prev, chord) >= 0.0 &&
                    dot(nxt - v, chord) >= 0.0) {
                    changed = true;
                    continue;
                }
            }
            poly[k] = v;
            k += 1;
        }
        n = k;
    }
    if (n == 2 && length_at_most(poly[1] - poly[0], tol)) n = 1;
    return n;
}

int64_t drop_edges_outward(cplx* poly, int64_t n, int64_t capacity) {
    while (n > capacity) {
        int64_t best = -1;
        double best_area = std::numeric_limits<double>::infinity();
        cplx best_point(0.0, 0.0);
        for (int64_t i = 0; i < n; ++i) {
            const cplx a = poly[py_mod(i - 1, n)];
            const cplx b = poly[i];
            const cplx c = poly[py_mod(i + 1, n)];
            const cplx d = poly[py_mod(i + 2, n)];
            const cplx u = b - a;
            const cplx w = d - c;
            const double denom = cross(u, w);
            if (!(denom > 0.0)) continue;  // the neighbouring edges turn by half a circle or more
            const double t = cross(c - b, w) / denom;
            const cplx meet = b + t * u;
            const double added = 0.5 * std::fabs(cross(c - b, meet - b));
            if (added < best_area) {
                best = i;
                best_area = added;
                best_point = meet;
            }
        }
        if (best < 0) break;
        poly[best] = best_point;
        for (int64_t j = best + 1; j < n - 1; ++j) poly[j] = poly[j + 1];
        if (best == n - 1) {  // the removed edge wrapped around: its second vertex was poly[0]
            for (int64_t j = 0; j < n - 1; ++j) poly[j] = poly[j + 1];
        }
        n -= 1;
    }
    return n;
}

int64_t clip_convex(const cplx* subject, int64_t n_subject, const cplx* clipper, int64_t n_clipper,
                    cplx* out, cplx* work) {
    const auto [size_s, mag_s] = scale_of(subject, n_subject);
    const auto [size_c, mag_c] = scale_of(clipper, n_clipper);
    const double size = std::min(size_s, size_c);
    const double tol = tolerance_of(size, std::max(mag_s, mag_c));
    check_capacity("clip_convex subject", n_subject, SCRATCH);
    for (int64_t i = 0; i < n_subject; ++i) out[i] = subject[i];
    int64_t n = n_subject;
    bool in_out = true;  // whether the current polygon is in out (else in work)
    double distances[SCRATCH];
    for (int64_t e = 0; e < n_clipper; ++e) {
        const cplx a = clipper[e];
        const cplx edge = clipper[py_mod(e + 1, n_clipper)] - a;
        const double length = abs(edge);
        if (length == 0.0) continue;
        cplx* current = in_out ? out : work;
        cplx* other = in_out ? work : out;
        bool all_in = true;
        bool any_in = false;
        for (int64_t i = 0; i < n; ++i) {
            const double d = cross(edge, current[i] - a) / length;
            distances[i] = d;
            if (d < -tol) {
                all_in = false;
            } else {
                any_in = true;
            }
        }
        if (all_in) continue;
        if (!any_in) return 0;
        int64_t k = 0;
        for (int64_t i = 0; i < n; ++i) {
            const int64_t j = py_mod(i + 1, n);
            const double di = distances[i], dj = distances[j];
            if (di >= -tol) {
                check_capacity("clip_convex output", k + 1, SCRATCH);
                other[k] = current[i];
                k += 1;
                if (dj < -tol && di > tol) {
                    check_capacity("clip_convex output", k + 1, SCRATCH);
                    other[k] = current[i] + (di / (di - dj)) * (current[j] - current[i]);
                    k += 1;
                }
            } else if (dj > tol) {
                check_capacity("clip_convex output", k + 1, SCRATCH);
                other[k] = current[i] + (di / (di - dj)) * (current[j] - current[i]);
                k += 1;
            }
        }
        in_out = !in_out;
        n = k;
        if (n == 0) return 0;
    }
    if (!in_out) {
        for (int64_t i = 0; i < n; ++i) out[i] = work[i];
    }
    n = simplify(out, n, tol);
    if (n < 3) return 0;
    const double area = area_centroid(out, n).first;
    if (!(area > tol * size)) return 0;
    return drop_edges_outward(out, n, CAPACITY);
}

// --------------------------------------------------------------------------------------
// Growing a polygon outward
// --------------------------------------------------------------------------------------

int64_t offset_outward(const cplx* poly, int64_t n, double radius, cplx* out) {
    if (n < 1) {
        // numba would read poly[-1] (the array's last slot): no meaningful result.
        throw std::invalid_argument("offset_outward needs at least one vertex");
    }
    if (n <= 2) {
        const cplx along = poly[n - 1] - poly[0];
        const cplx tangent = abs(along) > 0.0 ? along / abs(along) : cplx(1.0, 0.0);
        const cplx normal = MINUS_I * tangent;
        const cplx start = poly[0] - radius * tangent;
        const cplx end = poly[n - 1] + radius * tangent;
        out[0] = start + radius * normal;
        out[1] = end + radius * normal;
        out[2] = end - radius * normal;
        out[3] = start - radius * normal;
        return 4;
    }
    int64_t k = 0;
    // Vertex i's incoming edge poly[i] - poly[i - 1] is vertex i - 1's outgoing edge (the
    // same operands: i - 1 + 1 = i, and (n - 1) + 1 wraps to 0), so its unit tangent and
    // normal are carried over instead of computed again (the same bits).
    const cplx first_edge = poly[0] - poly[py_mod(-1, n)];
    cplx t_in = first_edge / abs(first_edge);
    cplx n_in = MINUS_I * t_in;  // outward normals (CCW polygon)
    for (int64_t i = 0; i < n; ++i) {
        const cplx next_edge = poly[py_mod(i + 1, n)] - poly[i];
        const cplx t_out = next_edge / abs(next_edge);
        const cplx n_out = MINUS_I * t_out;
        const double cos_turn = dot(n_in, n_out);
        if (cos_turn >= 0.0) {
            check_capacity("offset_outward output", k + 1, n + 3);
            out[k] = poly[i] + radius * (n_in + n_out) / (1.0 + cos_turn);
            k += 1;
        } else {
            // tan(turn / 4) from the half-angle formulas, turn in (90, 180) degrees.
            const double half_cos = std::sqrt(std::max(0.0, 0.5 * (1.0 + cos_turn)));
            const double half_sin = std::sqrt(std::max(0.0, 0.5 * (1.0 - cos_turn)));
            const double quarter_tan = half_sin / (1.0 + half_cos);
            check_capacity("offset_outward output", k + 2, n + 3);
            out[k] = poly[i] + radius * (n_in + quarter_tan * t_in);
            out[k + 1] = poly[i] + radius * (n_out - quarter_tan * t_out);
            k += 2;
        }
        t_in = t_out;
        n_in = n_out;
    }
    return k;
}

}  // namespace bearing::slam
