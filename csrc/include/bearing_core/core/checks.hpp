// Argument checks of the library's checked entry points: each throws std::invalid_argument
// with a message that names the bad argument (the Python bindings raise it as ValueError).
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

#include <bearing_core/core/views.hpp>

namespace bearing {

[[noreturn]] inline void invalid_argument(const std::string& message) {
    throw std::invalid_argument(message);
}

// `ok`, or std::invalid_argument(message).
inline void require(bool ok, const std::string& message) {
    if (!ok) invalid_argument(message);
}

// A count `n` (argument `name`) of elements of an array `array` of `length` elements:
// 0 <= n <= length, and the array holds at least `least` elements.
inline void check_count(int64_t n, const char* name, int64_t length, const char* array,
                        int64_t least = 0) {
    require(n >= 0, std::string(name) + " must not be negative, got " + std::to_string(n));
    if (n > length) {
        invalid_argument(std::string(name) + " = " + std::to_string(n) + " exceeds the length of " +
                         array + " (" + std::to_string(length) + ")");
    }
    if (length < least) {
        invalid_argument(std::string(array) + " must hold at least " + std::to_string(least) +
                         " points, it has " + std::to_string(length));
    }
}

// An output array `array` of `length` elements must hold `needed`.
inline void check_room(int64_t needed, int64_t length, const char* array) {
    if (length < needed) {
        invalid_argument(std::string(array) + " must hold at least " + std::to_string(needed) +
                         " elements, it has " + std::to_string(length));
    }
}

// n * m without overflow (INT64_MAX past it), 0 if either is not positive.
inline int64_t product(int64_t n, int64_t m) {
    if (n <= 0 || m <= 0) return 0;
    if (n > INT64_MAX / m) return INT64_MAX;
    return n * m;
}

// Axis `axis` of the array `name` has length `expected`.
template <class T, int D>
void check_axis(const View<T, D>& view, int axis, int64_t expected, const char* name) {
    if (view.shape[axis] != expected) {
        invalid_argument(std::string(name) + " has axis " + std::to_string(axis) + " of length " +
                         std::to_string(view.shape[axis]) + ", expected " +
                         std::to_string(expected));
    }
}

// The array `name` has the shape of `like` (the array a kernel loops over).
template <class T, class U, int D>
void check_shape(const View<T, D>& view, const View<U, D>& like, const char* name) {
    for (int d = 0; d < D; ++d) check_axis(view, d, like.shape[d], name);
}

}  // namespace bearing
