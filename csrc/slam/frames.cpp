// Cones in the robot frame FR and the change of frames FR -> FL: a function-for-function
// port of bearing_env/slam/kernels/frames.py (same operations in the same order).
#include <bearing_core/slam/frames.hpp>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>

#include <bearing_core/core/errors.hpp>
#include <bearing_core/slam/local_bound.hpp>
#include <bearing_core/slam/polygons.hpp>

namespace bearing::slam {

namespace {

// numba's float -> int64 conversion (LLVM fptosi, x86's cvttsd2si): truncation, and the
// "integer indefinite" INT64_MIN for NaN and out-of-range values (C++ leaves those
// undefined, so they are spelled out).
inline int64_t fptosi(double x) {
    if (!(x >= -9223372036854775808.0 && x < 9223372036854775808.0)) {
        return std::numeric_limits<int64_t>::min();
    }
    return static_cast<int64_t>(x);
}

// n * per_edge, saturated at INT64_MAX: a huge per_edge must fail the capacity check, not
// wrap to a small or negative count that passes it (and overruns the sample buffers).
inline int64_t samples_of(int64_t n, int64_t per_edge) {
    int64_t samples;
    if (__builtin_mul_overflow(n, per_edge, &samples)) return std::numeric_limits<int64_t>::max();
    return samples;
}

}  // namespace

// --------------------------------------------------------------------------------------
// Cones in the robot frame FR (R1 = 0, R2 = 1)
// --------------------------------------------------------------------------------------

std::pair<int64_t, int64_t> cone_region(double a, double b, double epsilon, cplx* out) {
    if (std::fabs(wrap(b - a)) <= 2.0 * epsilon) return {0, FR_UNBOUNDED};
    cplx candidates[6];
    int64_t n = 0;
    // The two beta = b + sign_b * epsilon and their sines are computed once, not once per
    // alpha, and each alpha's sine and cosine once, not per beta (the same expressions on
    // the same values: the same bits; sin and cos are pure).
    const double signs[2] = {-1.0, 1.0};
    double betas[2], sin_betas[2];
    for (int64_t kb = 0; kb < 2; ++kb) {
        betas[kb] = b + signs[kb] * epsilon;
        sin_betas[kb] = std::sin(betas[kb]);
    }
    for (const double sign_a : signs) {
        const double alpha = a + sign_a * epsilon;
        const double sin_alpha = std::sin(alpha);
        const double cos_alpha = std::cos(alpha);
        for (int64_t kb = 0; kb < 2; ++kb) {
            const double beta = betas[kb];
            const double sin_gap = std::sin(beta - alpha);
            if (std::fabs(sin_gap) <= 1e-12) continue;
            const double t = sin_betas[kb] / sin_gap;
            const double s = sin_alpha / sin_gap;
            if (t >= 0.0 && s >= 0.0) {
                candidates[n] = t * cplx(cos_alpha, sin_alpha);
                n += 1;
            }
        }
    }
    if (std::fabs(wrap(a)) <= epsilon) {  // R2 lies in the cone at R1
        candidates[n] = cplx(1.0, 0.0);
        n += 1;
    }
    if (std::fabs(wrap(PI - b)) <= epsilon) {  // R1 lies in the cone at R2
        candidates[n] = cplx(0.0, 0.0);
        n += 1;
    }
    if (n == 0) return {0, FR_EMPTY};
    cplx hull[7];
    int64_t count = small_convex_hull(candidates, n, hull, 0.0);
    for (int64_t i = 0; i < count; ++i) {
        const int side = length_versus(hull[i], MAX_FR_EXTENT);  // abs(hull[i]) > MAX_FR_EXTENT
        if (side > 0 || (side == 0 && abs(hull[i]) > MAX_FR_EXTENT)) return {0, FR_UNBOUNDED};
    }
    const auto [size, magnitude] = scale_of(hull, count);
    count = simplify(hull, count, tolerance_of(size, magnitude));
    const int64_t kept = std::min(count, FR_VERTICES);
    for (int64_t i = 0; i < kept; ++i) out[i] = hull[i];
    return {kept, FR_BOUNDED};
}

// --------------------------------------------------------------------------------------
// The change of frames FR -> FL
// --------------------------------------------------------------------------------------

int64_t boundary_samples(const cplx* poly, int64_t n, int64_t per_edge, cplx* out) {
    int64_t k = 0;
    for (int64_t i = 0; i < n; ++i) {
        const cplx a = poly[i];
        const cplx edge = poly[py_mod(i + 1, n)] - a;
        for (int64_t s = 0; s < per_edge; ++s) {
            out[k] = a + (static_cast<double>(s) / static_cast<double>(per_edge)) * edge;
            k += 1;
        }
    }
    return k;
}

FramePlan frame_plan(const cplx* a1, int64_t n1, const cplx* a2, int64_t n2, bool conservative,
                     int64_t edge_samples) {
    const double distance = polygon_distance(a1, n1, a2, n2);
    if (!(distance > 0.0)) return {FRAME_L1_L2_OVERLAP, 1, distance, 0.0, 0.0};
    if (!conservative) return {FRAME_OK, 1, distance, 0.0, 0.0};
    const double longest1 = longest_edge(a1, n1), longest2 = longest_edge(a2, n2);
    const int64_t needed = fptosi(std::ceil(std::max(longest1, longest2) / (2.0 * distance)));
    if (needed > MAX_EDGE_SAMPLES) return {FRAME_L1_L2_TOO_CLOSE, 1, distance, 0.0, 0.0};
    const int64_t per_edge = std::max(edge_samples, needed);
    return {FRAME_OK, per_edge, distance, longest1 / static_cast<double>(per_edge),
            longest2 / static_cast<double>(per_edge)};
}

int64_t sample_hypotheses(const cplx* a1, int64_t n1, const cplx* a2, int64_t n2, int64_t per_edge,
                          cplx* h1, cplx* inv_d) {
    // Buffers not zero-filled (PointBuffer): every slot read was written first.
    PointBuffer<MAX_SAMPLES> s1_buffer, s2_buffer, column_buffer;
    cplx* s1 = s1_buffer.data;
    cplx* s2 = s2_buffer.data;
    cplx* column = column_buffer.data;
    if (per_edge > 0) {
        check_capacity("sample_hypotheses samples of a1", samples_of(n1, per_edge), MAX_SAMPLES);
        check_capacity("sample_hypotheses samples of a2", samples_of(n2, per_edge), MAX_SAMPLES);
    }
    const int64_t m1 = boundary_samples(a1, n1, per_edge, s1);
    const int64_t m2 = boundary_samples(a2, n2, per_edge, s2);
    union Inverses {
        cplx rows[MAX_SAMPLES][MAX_SAMPLES];
        Inverses() {}  // NOLINT: deliberately uninitialised (16 KB)
    } inverse_buffer;
    auto& inverses = inverse_buffer.rows;
    double zero = 0.0;  // stays 0 if every image is finite, else NaN (inf - inf is NaN)
    for (int64_t i = 0; i < m1; ++i) {
        for (int64_t j = 0; j < m2; ++j) {
            const cplx image = 1.0 / (s2[j] - s1[i]);
            inverses[i][j] = image;
            zero += (image.re - image.re) + (image.im - image.im);
        }
    }
    int64_t extreme[MAX_SAMPLES + 1];
    // Each hull's sort starts from the previous column's (row's) order: neighbouring
    // samples have nearby images, so it is nearly sorted already (the same order).
    int64_t order[MAX_SAMPLES];
    for (int64_t i = 0; i < m1; ++i) order[i] = i;
    // column_extreme[i][j]: h1 = s1[i] gives a hull vertex among the pairs with h2 = s2[j].
    bool column_extreme[MAX_SAMPLES][MAX_SAMPLES] = {};
    // in_some_column[i]: some column_extreme[i][j]. A row without gives no pair, and its
    // hull is skipped, unless an image is not finite (then the hull may raise
    // CapacityError, where numba's kernel overran its buffer, and must still be run).
    bool in_some_column[MAX_SAMPLES] = {};
    for (int64_t j = 0; j < m2; ++j) {
        for (int64_t i = 0; i < m1; ++i) column[i] = inverses[i][j];
        const int64_t count = small_hull_indices(column, m1, extreme, 0.0, order);
        for (int64_t v = 0; v < count; ++v) {
            column_extreme[extreme[v]][j] = true;
            in_some_column[extreme[v]] = true;
        }
    }
    for (int64_t j = 0; j < m2; ++j) order[j] = j;
    const bool all_finite = zero == 0.0;
    int64_t k = 0;
    for (int64_t i = 0; i < m1; ++i) {
        if (!in_some_column[i] && all_finite) continue;
        const int64_t count = small_hull_indices(inverses[i], m2, extreme, 0.0, order);
        for (int64_t v = 0; v < count; ++v) {
            const int64_t j = extreme[v];
            if (column_extreme[i][j]) {
                h1[k] = s1[i];
                inv_d[k] = inverses[i][j];
                k += 1;
            }
        }
    }
    return k;
}

int64_t transfer_region(const cplx* target, int64_t n_target, const FrameChange& frame, cplx* cloud,
                        cplx* hull, cplx* out) {
    const cplx* a1 = frame.a1;
    const cplx* a2 = frame.a2;
    const int64_t n1 = frame.n1, n2 = frame.n2;
    const cplx* h1 = frame.h1;
    const cplx* inv_d = frame.inv_d;
    const int64_t n_pairs = frame.n_pairs;
    const double distance = frame.distance, delta1 = frame.delta1, delta2 = frame.delta2;
    if (n_target > 0 && n_pairs > 0) {
        check_capacity("transfer_region cloud", n_target * n_pairs, MAX_CLOUD);
    }
    int64_t k = 0;
    for (int64_t v = 0; v < n_target; ++v) {
        const cplx z = target[v];
        for (int64_t p = 0; p < n_pairs; ++p) {
            cloud[k] = (z - h1[p]) * inv_d[p];
            k += 1;
        }
    }
    int64_t n = convex_hull(cloud, k, hull);
    // Rounding can leave hull vertices a hair apart or off their neighbours' line; their
    // edge directions would be noise, and the offset needs true ones.
    const auto [size, magnitude] = scale_of(hull, n);
    n = simplify(hull, n, tolerance_of(size, magnitude));
    if (frame.conservative) {
        double v1 = 0.0;
        double v2 = 0.0;
        for (int64_t v = 0; v < n_target; ++v) {
            // std::max(v, abs(d)) keeps v when abs(d) < v, which the squares can tell
            // without hypot (length_versus); otherwise the original expression.
            for (int64_t j = 0; j < n1; ++j) {
                const cplx d = target[v] - a1[j];
                if (length_versus(d, v1) >= 0) v1 = std::max(v1, abs(d));
            }
            for (int64_t j = 0; j < n2; ++j) {
                const cplx d = target[v] - a2[j];
                if (length_versus(d, v2) >= 0) v2 = std::max(v2, abs(d));
            }
        }
        // distance**3 as numba unrolls it: (1.0 * d) * (d * d).
        const double cube = (1.0 * distance) * (distance * distance);
        double radius = (v2 * delta1 * delta1 + v1 * delta2 * delta2) / (4.0 * cube);
        // A relative margin far above rounding error keeps the bound a bound in floats.
        double margin = 1e-9 * (1.0 + v1 / distance);
        // Both bounds are valid; the local one is tighter wherever it is finite.
        if (frame.local != nullptr) {
            const double local = local_growth(target, n_target, *frame.local);
            if (local < radius) radius = local;
            // The samples off their edges move images by up to about
            // 65 u (M / D + 48) (1 + V1 / D), M the largest vertex modulus of A_L1 and A_L2
            // (docs/world_model.md, "Rounding"): covered whatever M / D.
            margin += 1e-13 * (frame.local->largest_modulus / distance) * (1.0 + v1 / distance);
        }
        radius += margin;
        n = drop_edges_outward(hull, n, SCRATCH - 8);
        // (only a polygon no edge of which can be removed stays larger: not a convex one)
        check_capacity("transfer_region out", n + 3, SCRATCH);
        n = offset_outward(hull, n, radius, out);
        return drop_edges_outward(out, n, CAPACITY);
    }
    // The paper's hull: numba copies hull[:n] into out and reduces it there; reducing it
    // in hull first and copying the result gives the same out (the same operations on
    // the same values) and keeps out within SCRATCH whatever the hull's size.
    n = drop_edges_outward(hull, n, CAPACITY);
    check_capacity("transfer_region out", n, SCRATCH);
    for (int64_t i = 0; i < n; ++i) out[i] = hull[i];
    return n;
}

}  // namespace bearing::slam
