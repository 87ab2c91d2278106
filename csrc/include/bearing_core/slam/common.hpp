// Scalar helpers shared by every kernel of the world model (bearing_env/slam/kernels/common.py).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

#include <bearing_core/core/complex.hpp>
#include <bearing_core/core/pymath.hpp>
#include <bearing_core/slam/state.hpp>

namespace bearing::slam {

// (bounding-box size, largest coordinate magnitude) of poly[:n].
std::pair<double, double> scale_of(const cplx* poly, int64_t n);

// Distance below which two features count as touching, for polygons of that scale.
inline double tolerance_of(double size, double magnitude) {
    return RELATIVE_TOLERANCE * size + 4e-16 * magnitude;
}

// N points of stack storage left uninitialised (an array of cplx would be zero-filled by
// cplx's default member initialisers: 70 KB per convex_hull call, for a few used slots).
// Every slot used is written before it is read.
template <int64_t N>
struct PointBuffer {
    union {
        cplx data[N];
    };
    PointBuffer() {}  // NOLINT: deliberately leaves data uninitialised
};

// How hypot(d.re, d.im) (abs(d)) compares with `limit`, decided on squared lengths when
// that is conclusive: -1 if certainly abs(d) < limit, +1 if certainly abs(d) > limit,
// 0 if the squares cannot tell (then the caller evaluates its original expression on
// abs(d), so every decision is the one hypot gives).
//
// Why -1/+1 are certain: s and t are taken only in [2^-1000, 2^1000] (no overflow; the
// squares' underflow, at most 2 * 2^-1075 absolute, is below 2^-70 relative), and `limit`
// > 0, d finite. Then s = r^2 (1 + a) with r the exact length, |a| <= 2u + u^2 (two
// squares, one sum, u = 2^-53), t = limit^2 (1 + b), |b| <= u, and the band's product
// rounds by (1 + g), |g| <= u. So s < t (1 - 1e-12) gives r^2 < limit^2 (1 - 1e-12 + 5u),
// r < limit (1 - 4e-13), and hypot, within one ulp (2u relative) of r, is < limit. The
// same for s > t (1 + 1e-12): r > limit (1 + 4e-13), hypot > limit. (No FMA: the build
// has -ffp-contract=off.)
inline int length_versus(cplx d, double limit) {
    constexpr double LO = 0x1p-1000, HI = 0x1p+1000;
    const double s = d.re * d.re + d.im * d.im;
    const double t = limit * limit;
    if (!(limit > 0.0 && s >= LO && s <= HI && t >= LO && t <= HI)) return 0;
    if (s < t * (1.0 - 1e-12)) return -1;
    if (s > t * (1.0 + 1e-12)) return 1;
    return 0;
}

// abs(d) <= limit, as that expression decides it (see length_versus).
inline bool length_at_most(cplx d, double limit) {
    const int side = length_versus(d, limit);
    if (side != 0) return side < 0;
    return abs(d) <= limit;
}

}  // namespace bearing::slam
