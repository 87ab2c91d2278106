// Turning Python arguments into checked views: every array the kernels take is checked
// once here (dtype, dimensions, C-contiguity, alignment, writeability, shape, bool bytes),
// and a bad one raises TypeError or ValueError naming the argument, never a crash.
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include <bearing_core/core/complex.hpp>
#include <bearing_core/core/views.hpp>

namespace bearing::bindings {

namespace nb = nanobind;

// numpy's name of each element type the kernels take.
template <class T>
constexpr const char* dtype_name() {
    if constexpr (std::is_same_v<T, double>) return "float64";
    if constexpr (std::is_same_v<T, float>) return "float32";
    if constexpr (std::is_same_v<T, int64_t>) return "int64";
    if constexpr (std::is_same_v<T, int8_t>) return "int8";
    if constexpr (std::is_same_v<T, bool>) return "bool";
    if constexpr (std::is_same_v<T, cplx>) return "complex128";
    return "";  // (no other element type is bound)
}

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

// A bool array's bytes are 0 or 1 (numpy writes no other, but a view of other bytes can
// hold any; the kernels would read such a byte as neither true nor false).
inline void check_bool_bytes(const bool* data, int64_t size, const char* name) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(data);
    for (int64_t k = 0; k < size; ++k) {
        if (bytes[k] > 1) {
            value_error(std::string(name) + " holds the byte " + std::to_string(bytes[k]) +
                        " at flat index " + std::to_string(k) + ", not a bool (0 or 1)");
        }
    }
}

// A view of the numpy array `obj` (argument `name`): dtype T, D dimensions, C-contiguous,
// aligned for T, and writeable unless T is const; a read-only bool array (const bool)
// holds only 0 and 1 (a state's bool arrays, read and written, are checked by their
// parser, read_struct). Its shape is the caller's to check (a kernel's checked entry point,
// or the struct's schema).
template <class T, int D>
View<T, D> view_of(nb::handle obj, const char* name) {
    using Element = std::remove_const_t<T>;
    // Read-only arrays are taken too (nb::ro); a view of a non-const T checks writeability
    // below, naming the argument.
    nb::ndarray<nb::numpy, nb::ro> array;
    if (!nb::try_cast(obj, array, false)) {
        type_error(std::string(name) + " must be a numpy array, not " +
                   nb::type_name(obj.type()).c_str());
    }
    if (array.dtype() != dtype_of<Element>()) {
        type_error(std::string(name) + " must have dtype " + dtype_name<Element>());
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
    }
    if constexpr (!std::is_const_v<T>) {
        if (array.size() > 0 && !nb::cast<bool>(obj.attr("flags").attr("writeable"))) {
            value_error(std::string(name) + " must be writeable");
        }
    }
    view.data = reinterpret_cast<T*>(const_cast<void*>(static_cast<const void*>(array.data())));
    if (reinterpret_cast<std::uintptr_t>(view.data) % alignof(Element) != 0) {
        value_error(std::string(name) + " must be aligned to " + std::to_string(alignof(Element)) +
                    " bytes (a view at an odd offset of a buffer is not)");
    }
    // (An output the kernel only writes may come from np.empty: its bytes are not read.)
    if constexpr (std::is_same_v<T, const bool>) check_bool_bytes(view.data, view.size(), name);
    return view;
}

// An array argument's memory, for require_apart.
struct Extent {
    const char* name;
    const void* data;
    int64_t bytes;
    bool written;  // the kernel writes it
};

template <class T, int D>
Extent extent_of(const View<T, D>& view, const char* name) {
    return {name, view.data, view.size() * static_cast<int64_t>(sizeof(T)), !std::is_const_v<T>};
}

// No array a kernel writes shares memory with another of its arguments: the kernels read
// their inputs while they write their outputs, so an overlap would change the result
// midway. ValueError naming both.
inline void require_apart(const std::vector<Extent>& arrays) {
    for (auto a = arrays.begin(); a != arrays.end(); ++a) {
        for (auto b = a + 1; b != arrays.end(); ++b) {
            if (!(a->written || b->written) || a->bytes == 0 || b->bytes == 0) continue;
            const auto* a_begin = static_cast<const char*>(a->data);
            const auto* b_begin = static_cast<const char*>(b->data);
            if (a_begin < b_begin + b->bytes && b_begin < a_begin + a->bytes) {
                value_error(std::string(a->name) + " and " + b->name +
                            " must not share memory (the kernel writes " +
                            (a->written ? a->name : b->name) + " while it reads the other)");
            }
        }
    }
}

}  // namespace bearing::bindings
