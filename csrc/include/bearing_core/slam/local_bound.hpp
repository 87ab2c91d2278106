// The conservative transfer's local growth bound (docs/world_model.md, "The local bound").
//
// The boundaries of A_L1 and A_L2 are cut into pieces between consecutive boundary
// samples. A sub-square is one piece P1 = [a, b] of L1's boundary times one piece
// P2 = [c, d] of L2's. For a target point z, every image T(h1, h2)(z) with h1 in P1 and
// h2 in P2 lies within sigma(z) of the hull of the four corner images, where sigma is the
// smaller of two orders' bounds:
//
//   order A (h2 fixed at the corners c, d while h1 runs along P1, then h2 runs along P2):
//     max(|z - c| exact1(P1; c), |z - d| exact1(P1; d)) + max(|z - a|, |z - b|) moving2
//   order B (h1 fixed at the corners a, b, then h1 runs along P1):
//     max(|z - a| exact2(a; P2), |z - b| exact2(b; P2)) + max(|z - c|, |z - d|) moving1
//
// exact1(P1; c) = |b - a| tan(phi / 2) / (2 |a - c| |b - c|) is the sagitta factor of the
// arc that 1 / (c - h1) traces as h1 runs along P1 (phi: the angle P1 subtends at c);
// moving2 = |d - c|^2 / (4 dist(c, P1) dist(d, P1) dist(P1, P2)) bounds the same factor
// for h2 along P2 seen from any h1 of P1. The bounds hold at any angle (the page's arc
// fact), but the kernels use them only where the proof's checked conditions hold, phi <=
// 90 degrees and |d - c| <= 2 dist(P1, P2), which frame_plan's piece lengths always meet;
// a factor outside them is INVALID_FACTOR, a finite stand-in far above any valid bound,
// so that the other order (or the global bound) wins.
#pragma once

#include <cstdint>

#include <bearing_core/slam/common.hpp>

namespace bearing::slam {

// What a factor whose condition fails is worth: far above any valid bound, yet finite,
// so that a distance of 0 times it is 0 (as the image it scales is a single point).
inline constexpr double INVALID_FACTOR = 1e300;

// One movement's sub-squares: the boundary samples of A_L1 and A_L2 and, per piece pair,
// the target-independent factors of the two orders. Piece i of L1 runs from s1[i] to
// s1[(i + 1) % m1]; piece j of L2 from s2[j] to s2[(j + 1) % m2].
struct SubSquares {
    int64_t m1 = 0;
    int64_t m2 = 0;
    cplx s1[MAX_SAMPLES];
    cplx s2[MAX_SAMPLES];
    double exact1[MAX_SAMPLES][MAX_SAMPLES];   // [piece i of L1][sample j of L2]
    double exact2[MAX_SAMPLES][MAX_SAMPLES];   // [sample i of L1][piece j of L2]
    double moving1[MAX_SAMPLES][MAX_SAMPLES];  // [piece i][piece j]: h1 along piece i
    double moving2[MAX_SAMPLES][MAX_SAMPLES];  // [piece i][piece j]: h2 along piece j
    // Per piece i of L1, the largest exact1[i][:] and moving2[i][:]: with a target point's
    // distances they bound order A, hence sigma, over the whole row of sub-squares.
    double row_exact1[MAX_SAMPLES];
    double row_moving2[MAX_SAMPLES];
    // The largest vertex modulus of A_L1 and A_L2 (M of the rounding margin).
    double largest_modulus = 0.0;
    SubSquares() {}  // NOLINT: deliberately uninitialised (33 KB); plan_sub_squares fills it
};

// The sub-squares of A_L1 = a1[:n1] and A_L2 = a2[:n2] cut per_edge times per edge
// (the samples boundary_samples gives). CapacityError beyond MAX_SAMPLES per region.
void plan_sub_squares(const cplx* a1, int64_t n1, const cplx* a2, int64_t n2, int64_t per_edge,
                      SubSquares& out);

// The bound sigma(z) of target point z for sub-square (i, j).
double sub_square_growth(cplx z, const SubSquares& sub, int64_t i, int64_t j);

// The largest sigma over the points target[:n_target] and every sub-square: every image
// of the target under hypotheses on the boundaries lies within it of the hull of the
// sampled images.
double local_growth(const cplx* target, int64_t n_target, const SubSquares& sub);

}  // namespace bearing::slam
