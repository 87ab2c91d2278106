// The conservative transfer's local growth bound (see local_bound.hpp and
// docs/world_model.md, "The local bound", for the proof each factor follows).
#include <bearing_core/slam/local_bound.hpp>

#include <algorithm>
#include <cmath>

#include <bearing_core/core/errors.hpp>
#include <bearing_core/slam/frames.hpp>

namespace bearing::slam {

namespace {

// |d| as sqrt(x^2 + y^2): within an ulp of hypot, without its overflow care (FR regions
// lie within MAX_FR_EXTENT of the origin) and at a fraction of its cost; the bound's
// margin absorbs the difference (docs/world_model.md, "Rounding").
inline double length(cplx d) { return std::sqrt(d.re * d.re + d.im * d.im); }

// Sagitta factor of the arc that 1 / (c - h) traces as h runs along the piece [a, b]
// (Lemma 1): half its chord |b - a| / (|a - c| |b - c|) times tan(phi / 2), phi the angle
// the piece subtends at c, tan(phi / 2) = |cross| / (|a - c| |b - c| + dot). Used only
// for phi <= 90 degrees (dot >= 0), else INVALID_FACTOR (see local_bound.hpp).
double exact_factor(cplx a, cplx b, cplx c, double piece, double to_a, double to_b) {
    const cplx ca = a - c;
    const cplx cb = b - c;
    const double lengths = to_a * to_b;
    const double cosine_part = dot(ca, cb);
    if (!(lengths > 0.0) || !(cosine_part >= 0.0)) return INVALID_FACTOR;
    const double factor =
        piece * std::fabs(cross(ca, cb)) / (2.0 * lengths * (lengths + cosine_part));
    return std::isfinite(factor) ? factor : INVALID_FACTOR;
}

// Distance from c to the piece [a, b] of length `piece`, given |c - a| and |c - b|.
inline double to_piece(cplx c, cplx a, cplx b, double piece, double to_a, double to_b) {
    const cplx along = b - a;
    const double t = dot(c - a, along);
    if (!(t > 0.0)) return to_a;
    if (!(t < piece * piece)) return to_b;
    return std::fabs(cross(along, c - a)) / piece;
}

// Bound on the same factor for h2 running along [c, d] seen from any h1 of a piece P1
// whose distances to c, to d and to [c, d] are at least near_c, near_d and gap (Lemma 2
// bounds tan(psi / 2) by |d - c| / (2 gap)); used only for |d - c| <= 2 gap.
double moving_factor(double length, double near_c, double near_d, double gap) {
    if (!(gap > 0.0) || !(length <= 2.0 * gap)) return INVALID_FACTOR;
    const double factor = (length * length) / (4.0 * near_c * near_d * gap);
    return std::isfinite(factor) ? factor : INVALID_FACTOR;
}

inline int64_t next_index(int64_t i, int64_t m) { return i + 1 == m ? 0 : i + 1; }

}  // namespace

void plan_sub_squares(const cplx* a1, int64_t n1, const cplx* a2, int64_t n2, int64_t per_edge,
                      SubSquares& out) {
    int64_t m1 = 0, m2 = 0;
    if (__builtin_mul_overflow(n1, per_edge, &m1)) m1 = MAX_SAMPLES + 1;
    if (__builtin_mul_overflow(n2, per_edge, &m2)) m2 = MAX_SAMPLES + 1;
    check_capacity("plan_sub_squares samples of a1", m1, MAX_SAMPLES);
    check_capacity("plan_sub_squares samples of a2", m2, MAX_SAMPLES);
    out.m1 = boundary_samples(a1, n1, per_edge, out.s1);
    out.m2 = boundary_samples(a2, n2, per_edge, out.s2);
    m1 = out.m1;
    m2 = out.m2;
    double largest = 0.0;
    for (int64_t j = 0; j < n1; ++j) largest = std::max(largest, abs(a1[j]));
    for (int64_t j = 0; j < n2; ++j) largest = std::max(largest, abs(a2[j]));
    out.largest_modulus = largest;
    const cplx* s1 = out.s1;
    const cplx* s2 = out.s2;
    // Sample-to-sample distances and piece lengths, each used by several factors.
    double apart[MAX_SAMPLES][MAX_SAMPLES];  // |s1[i] - s2[j]|
    double piece1[MAX_SAMPLES], piece2[MAX_SAMPLES];
    for (int64_t i = 0; i < m1; ++i) {
        for (int64_t j = 0; j < m2; ++j) apart[i][j] = length(s1[i] - s2[j]);
        piece1[i] = length(s1[next_index(i, m1)] - s1[i]);
    }
    for (int64_t j = 0; j < m2; ++j) piece2[j] = length(s2[next_index(j, m2)] - s2[j]);
    double to_piece1[MAX_SAMPLES][MAX_SAMPLES];  // [piece i of L1][sample j of L2]
    double to_piece2[MAX_SAMPLES][MAX_SAMPLES];  // [sample i of L1][piece j of L2]
    for (int64_t i = 0; i < m1; ++i) {
        const int64_t i_next = next_index(i, m1);
        const cplx a = s1[i], b = s1[i_next];
        for (int64_t j = 0; j < m2; ++j) {
            const int64_t j_next = next_index(j, m2);
            const cplx c = s2[j], d = s2[j_next];
            to_piece1[i][j] = to_piece(c, a, b, piece1[i], apart[i][j], apart[i_next][j]);
            to_piece2[i][j] = to_piece(a, c, d, piece2[j], apart[i][j], apart[i][j_next]);
            out.exact1[i][j] = exact_factor(a, b, c, piece1[i], apart[i][j], apart[i_next][j]);
            out.exact2[i][j] = exact_factor(c, d, a, piece2[j], apart[i][j], apart[i][j_next]);
        }
    }
    for (int64_t i = 0; i < m1; ++i) {
        const int64_t i_next = next_index(i, m1);
        double row_exact1 = 0.0, row_moving2 = 0.0;
        for (int64_t j = 0; j < m2; ++j) {
            const int64_t j_next = next_index(j, m2);
            // The distance between two disjoint segments is attained at an end of one.
            const double gap = std::min(std::min(to_piece2[i][j], to_piece2[i_next][j]),
                                        std::min(to_piece1[i][j], to_piece1[i][j_next]));
            out.moving1[i][j] =
                moving_factor(piece1[i], to_piece2[i][j], to_piece2[i_next][j], gap);
            out.moving2[i][j] =
                moving_factor(piece2[j], to_piece1[i][j], to_piece1[i][j_next], gap);
            row_exact1 = std::max(row_exact1, out.exact1[i][j]);
            row_moving2 = std::max(row_moving2, out.moving2[i][j]);
        }
        out.row_exact1[i] = row_exact1;
        out.row_moving2[i] = row_moving2;
    }
}

double sub_square_growth(cplx z, const SubSquares& sub, int64_t i, int64_t j) {
    const int64_t i_next = next_index(i, sub.m1), j_next = next_index(j, sub.m2);
    const double ra = length(z - sub.s1[i]), rb = length(z - sub.s1[i_next]);
    const double rc = length(z - sub.s2[j]), rd = length(z - sub.s2[j_next]);
    const double order_a = std::max(rc * sub.exact1[i][j], rd * sub.exact1[i][j_next]) +
                           std::max(ra, rb) * sub.moving2[i][j];
    const double order_b = std::max(ra * sub.exact2[i][j], rb * sub.exact2[i_next][j]) +
                           std::max(rc, rd) * sub.moving1[i][j];
    return std::min(order_a, order_b);
}

double local_growth(const cplx* target, int64_t n_target, const SubSquares& sub) {
    const int64_t m1 = sub.m1, m2 = sub.m2;
    double r1[MAX_SAMPLES], r2[MAX_SAMPLES];
    double growth = 0.0;
    for (int64_t v = 0; v < n_target; ++v) {
        const cplx z = target[v];
        for (int64_t i = 0; i < m1; ++i) r1[i] = length(z - sub.s1[i]);
        double r2_max = 0.0;
        for (int64_t j = 0; j < m2; ++j) {
            r2[j] = length(z - sub.s2[j]);
            r2_max = std::max(r2_max, r2[j]);
        }
        // Rows in two passes: first the one whose bound is largest, so that its sigma
        // lets the bound skip most other rows (only the maximum is needed).
        int64_t first = 0;
        double first_bound = -1.0;
        for (int64_t i = 0; i < m1; ++i) {
            const double bound = r2_max * sub.row_exact1[i] +
                                 std::max(r1[i], r1[next_index(i, m1)]) * sub.row_moving2[i];
            if (bound > first_bound) {
                first_bound = bound;
                first = i;
            }
        }
        for (int64_t pass = 0; pass < 2; ++pass) {
            for (int64_t i = pass == 0 ? first : 0; i < (pass == 0 ? first + 1 : m1); ++i) {
                if (pass == 1 && i == first) continue;
                const int64_t i_next = next_index(i, m1);
                const double ra = r1[i], rb = r1[i_next];
                const double far1 = std::max(ra, rb);
                // Order A over the row is at most this; sigma is at most order A.
                if (r2_max * sub.row_exact1[i] + far1 * sub.row_moving2[i] <= growth) continue;
                const double* exact1 = sub.exact1[i];
                const double* moving1 = sub.moving1[i];
                const double* moving2 = sub.moving2[i];
                const double* exact2_a = sub.exact2[i];
                const double* exact2_b = sub.exact2[i_next];
                for (int64_t j = 0; j < m2; ++j) {
                    const int64_t j_next = next_index(j, m2);
                    const double rc = r2[j], rd = r2[j_next];
                    const double order_a =
                        std::max(rc * exact1[j], rd * exact1[j_next]) + far1 * moving2[j];
                    // sigma = min(order_a, order_b) can raise the growth only if both do.
                    if (order_a <= growth) continue;
                    const double order_b = std::max(ra * exact2_a[j], rb * exact2_b[j]) +
                                           std::max(rc, rd) * moving1[j];
                    const double sigma = std::min(order_a, order_b);
                    // NaN (from NaN inputs) is returned as it is: the caller then keeps
                    // the global bound, which a max would silently have replaced.
                    if (std::isnan(sigma)) return sigma;
                    growth = std::max(growth, sigma);
                }
            }
        }
    }
    return growth;
}

}  // namespace bearing::slam
