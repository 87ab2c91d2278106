// Python's (and numba's) semantics for the scalar operations whose C++ spelling differs.
#pragma once

#include <cmath>
#include <cstdint>

namespace bearing {

inline constexpr double PI = 3.141592653589793;
inline constexpr double TWO_PI = 2.0 * PI;

// a % b for floats, as Python (and numba) define it: the sign of the divisor.
inline double py_fmod(double a, double b) {
    double mod = std::fmod(a, b);
    if (mod != 0.0) {
        if ((b < 0.0) != (mod < 0.0)) mod += b;
    } else {
        mod = std::copysign(0.0, b);
    }
    return mod;
}

// a // b and a % b for integers, as Python defines them (floor, the divisor's sign).
inline int64_t py_floordiv(int64_t a, int64_t b) {
    int64_t q = a / b;
    if ((a % b != 0) && ((a < 0) != (b < 0))) --q;
    return q;
}
inline int64_t py_mod(int64_t a, int64_t b) {
    int64_t r = a % b;
    if (r != 0 && ((r < 0) != (b < 0))) r += b;
    return r;
}

// An angle wrapped to [-pi, pi): (angle + pi) % 2pi - pi, with Python's %.
inline double wrap(double angle) { return py_fmod(angle + PI, TWO_PI) - PI; }

}  // namespace bearing
