// Turning Python arguments into checked views: every array the kernels take is checked
// once here (dtype, dimensions, C-contiguity, writeability, shape), and a bad one raises
// TypeError or ValueError naming the argument, never a crash.
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstdint>
#include <string>
#include <type_traits>

#include <bearing_core/core/complex.hpp>
#include <bearing_core/core/views.hpp>

namespace bearing::bindings {

namespace nb = nanobind;

template <class T>
struct dtype_name;
template <>
struct dtype_name<double> {
    static constexpr const char* value = "float64";
};
template <>
struct dtype_name<float> {
    static constexpr const char* value = "float32";
};
template <>
struct dtype_name<int64_t> {
    static constexpr const char* value = "int64";
};
template <>
struct dtype_name<int8_t> {
    static constexpr const char* value = "int8";
};
template <>
struct dtype_name<bool> {
    static constexpr const char* value = "bool";
};
template <>
struct dtype_name<cplx> {
    static constexpr const char* value = "complex128";
};

template <class T>
nb::dlpack::dtype dtype_of() {
    if constexpr (std::is_same_v<T, cplx>) {
        return nb::dlpack::dtype{static_cast<uint8_t>(nb::dlpack::dtype_code::Complex), 128, 1};
    } else {
        return nb::dtype<T>();
    }
}

[[noreturn]] inline void type_error(const std::string& message) {
    throw nb::type_error(message.c_str());
}
[[noreturn]] inline void value_error(const std::string& message) {
    throw nb::value_error(message.c_str());
}

// A view of the numpy array `obj` (argument `name`): dtype T, D dimensions, C-contiguous,
// and writeable unless T is const. `shape[d] >= 0` entries must match.
template <class T, int D>
View<T, D> view_of(nb::handle obj, const char* name, const std::array<int64_t, D>& expect = {}) {
    using Element = std::remove_const_t<T>;
    // Read-only arrays are taken too (nb::ro); a view of a non-const T checks writeability
    // below, naming the argument.
    nb::ndarray<nb::numpy, nb::ro> array;
    if (!nb::try_cast(obj, array, false)) {
        type_error(std::string(name) + " must be a numpy array, not " +
                   nb::type_name(obj.type()).c_str());
    }
    if (array.dtype() != dtype_of<Element>()) {
        type_error(std::string(name) + " must have dtype " + dtype_name<Element>::value);
    }
    if (static_cast<int>(array.ndim()) != D) {
        value_error(std::string(name) + " must have " + std::to_string(D) + " dimensions, not " +
                    std::to_string(array.ndim()));
    }
    View<T, D> view;
    int64_t expected_stride = 1;
    for (int d = D - 1; d >= 0; --d) {
        view.shape[d] = static_cast<int64_t>(array.shape(static_cast<size_t>(d)));
        // (An empty array is contiguous whatever its strides: numpy gives it zero strides.)
        if (array.size() > 0 && view.shape[d] > 1 &&
            array.stride(static_cast<size_t>(d)) != expected_stride) {
            value_error(std::string(name) + " must be C-contiguous");
        }
        expected_stride *= view.shape[d];
        if (expect[d] > 0 && view.shape[d] != expect[d]) {
            value_error(std::string(name) + " has axis " + std::to_string(d) + " of length " +
                        std::to_string(view.shape[d]) + ", expected " + std::to_string(expect[d]));
        }
    }
    if constexpr (!std::is_const_v<T>) {
        if (array.size() > 0 && !nb::cast<bool>(obj.attr("flags").attr("writeable"))) {
            value_error(std::string(name) + " must be writeable");
        }
    }
    view.data = reinterpret_cast<T*>(const_cast<void*>(static_cast<const void*>(array.data())));
    return view;
}

}  // namespace bearing::bindings
