// Per-thread scratch arrays on the heap, for kernels whose temporaries are too large for
// a thread's stack (a secondary thread may have 128 KB to 512 KB: musl's default, macOS's,
// a pool's setting), and that would otherwise allocate on every call.
//
// A ScratchArray is grown on need and never shrunk, so a thread allocates once for the
// largest input it met; the storage is left uninitialised (the kernels write every slot
// before they read it: zero-filling a hull's few thousand slots per call cost more than
// the hull). Each kernel keeps its arrays in a thread_local of its own, so a kernel never
// hands out an array another kernel on the same thread still uses.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <type_traits>

namespace bearing {

template <class T>
class ScratchArray {
    static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>,
                  "a ScratchArray holds plain values, left uninitialised");

public:
    ScratchArray() = default;
    ScratchArray(const ScratchArray&) = delete;
    ScratchArray& operator=(const ScratchArray&) = delete;
    ~ScratchArray() { release(); }

    // Room for at least n values (their contents unspecified); the pointer stays valid
    // until the next call that needs more room.
    T* at_least(int64_t n) {
        if (n > capacity_) {
            release();
            data_ = std::allocator<T>().allocate(static_cast<std::size_t>(n));
            capacity_ = n;
        }
        return data_;
    }

private:
    void release() {
        if (data_ != nullptr)
            std::allocator<T>().deallocate(data_, static_cast<std::size_t>(capacity_));
        data_ = nullptr;
        capacity_ = 0;
    }

    T* data_ = nullptr;
    int64_t capacity_ = 0;
};

}  // namespace bearing
