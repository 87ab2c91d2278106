// Views of C-contiguous numpy arrays owned by Python: a pointer and a shape, no ownership.
//
// The state of every batch stays in numpy arrays (so pickling, copying and Ray keep
// working through them); the bindings check each array's dtype, shape and contiguity once
// and hand the kernels these views.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace bearing {

template <class T, int D>
struct View {
    T* data = nullptr;
    std::array<int64_t, D> shape{};

    int64_t size() const {
        int64_t n = 1;
        for (int d = 0; d < D; ++d) n *= shape[d];
        return n;
    }
    // Elements between consecutive indices of axis `axis`.
    int64_t stride(int axis) const {
        int64_t s = 1;
        for (int d = D - 1; d > axis; --d) s *= shape[d];
        return s;
    }
    // The sub-array at index i of the first axis (a view of one fewer dimension), or the
    // element itself for a one-dimensional view.
    decltype(auto) operator[](int64_t i) const {
        if constexpr (D == 1) {
            return (data[i]);
        } else {
            View<T, D - 1> sub;
            sub.data = data + i * stride(0);
            for (int d = 1; d < D; ++d) sub.shape[d - 1] = shape[d];
            return sub;
        }
    }
    T& operator()(int64_t i) const {
        static_assert(D == 1);
        return data[i];
    }
    T& operator()(int64_t i, int64_t j) const {
        static_assert(D == 2);
        return data[i * shape[1] + j];
    }
    T& operator()(int64_t i, int64_t j, int64_t k) const {
        static_assert(D == 3);
        return data[(i * shape[1] + j) * shape[2] + k];
    }
    T& operator()(int64_t i, int64_t j, int64_t k, int64_t l) const {
        static_assert(D == 4);
        return data[((i * shape[1] + j) * shape[2] + k) * shape[3] + l];
    }
    // Pointer to the first element of the innermost row at the given leading indices.
    T* row(int64_t i) const { return data + i * stride(0); }
    T* row(int64_t i, int64_t j) const {
        static_assert(D >= 2);
        return data + i * stride(0) + j * stride(1);
    }
    T* row(int64_t i, int64_t j, int64_t k) const {
        static_assert(D >= 3);
        return data + i * stride(0) + j * stride(1) + k * stride(2);
    }
};

template <class T>
using View1 = View<T, 1>;
template <class T>
using View2 = View<T, 2>;
template <class T>
using View3 = View<T, 3>;
template <class T>
using View4 = View<T, 4>;

}  // namespace bearing
