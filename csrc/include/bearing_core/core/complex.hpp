// Complex numbers with numba's semantics, bit for bit.
//
// The world model keeps points as complex numbers (x + iy). The kernels were first written
// in numba, and the native core must give the same bits: std::complex does not (its
// division scales differently, and GCC may fuse its products into FMAs). So every
// operation here is spelled as numba spells it:
// - a real operand is promoted to (x, 0) first (numba unifies complex op real to complex);
// - a product is (ac - bd, ad + bc);
// - a quotient is CPython's algorithm (numba's `complex_div`, from `_Py_c_quot`);
// - abs is hypot(re, im).
// The build compiles with -ffp-contract=off so that no product is fused (CMakeLists.txt).
#pragma once

#include <cmath>
#include <limits>

namespace bearing {

struct cplx {
    double re = 0.0;
    double im = 0.0;
    constexpr cplx() = default;
    constexpr cplx(double real, double imag = 0.0)
        : re(real), im(imag) {}  // NOLINT: implicit like numba's promotion
};

inline cplx operator+(cplx a, cplx b) { return {a.re + b.re, a.im + b.im}; }
inline cplx operator-(cplx a, cplx b) { return {a.re - b.re, a.im - b.im}; }
inline cplx operator-(cplx a) { return {-a.re, -a.im}; }
inline cplx operator*(cplx a, cplx b) {
    return {a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re};
}
// CPython's _Py_c_quot, as numba 0.68 implements it (`complex_div` in
// numba/cpython/numbers.py). numba raises ZeroDivisionError on a zero divisor; the kernels
// never divide by a zero complex (they test for it first), and here it gives NaN.
inline cplx operator/(cplx a, cplx b) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double abs_re = std::fabs(b.re), abs_im = std::fabs(b.im);
    if (abs_re >= abs_im) {
        if (abs_re == 0.0) return {nan, nan};
        const double ratio = b.im / b.re;
        const double denom = b.re + b.im * ratio;
        return {(a.re + a.im * ratio) / denom, (a.im - a.re * ratio) / denom};
    }
    if (abs_im >= abs_re) {
        const double ratio = b.re / b.im;
        const double denom = b.re * ratio + b.im;
        return {(a.re * ratio + a.im) / denom, (a.im * ratio - a.re) / denom};
    }
    return {nan, nan};  // a NaN in the divisor
}
// Mixed operands: promoted, as numba does (so (x, -0) + 0.0 gives (x, +0), like numba).
inline cplx operator+(cplx a, double b) { return a + cplx(b); }
inline cplx operator+(double a, cplx b) { return cplx(a) + b; }
inline cplx operator-(cplx a, double b) { return a - cplx(b); }
inline cplx operator-(double a, cplx b) { return cplx(a) - b; }
inline cplx operator*(cplx a, double b) { return a * cplx(b); }
inline cplx operator*(double a, cplx b) { return cplx(a) * b; }
inline cplx operator/(cplx a, double b) { return a / cplx(b); }
inline cplx operator/(double a, cplx b) { return cplx(a) / b; }
inline cplx& operator+=(cplx& a, cplx b) { return a = a + b; }
inline cplx& operator-=(cplx& a, cplx b) { return a = a - b; }
inline cplx& operator*=(cplx& a, cplx b) { return a = a * b; }
inline cplx& operator/=(cplx& a, cplx b) { return a = a / b; }
inline bool operator==(cplx a, cplx b) { return a.re == b.re && a.im == b.im; }
inline bool operator!=(cplx a, cplx b) { return !(a == b); }

inline double abs(cplx z) { return std::hypot(z.re, z.im); }
inline cplx conj(cplx z) { return {z.re, -z.im}; }
inline bool isfinite(cplx z) { return std::isfinite(z.re) && std::isfinite(z.im); }
inline bool isnan(cplx z) { return std::isnan(z.re) || std::isnan(z.im); }
inline cplx complex_nan() {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {nan, nan};
}

// 2-D cross and dot products of points as vectors.
inline double cross(cplx a, cplx b) { return a.re * b.im - a.im * b.re; }
inline double dot(cplx a, cplx b) { return a.re * b.re + a.im * b.im; }

static_assert(sizeof(cplx) == 2 * sizeof(double), "cplx must match numpy's complex128");

}  // namespace bearing
