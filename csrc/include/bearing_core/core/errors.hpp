// Errors a kernel raises instead of corrupting memory: a fixed-capacity buffer or a
// recursion guard would overflow. The bindings turn them into Python exceptions.
#pragma once

#include <stdexcept>
#include <string>

namespace bearing {

// A capacity the kernels were sized for was exceeded (a bug or an absurd input).
struct CapacityError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

[[noreturn]] inline void capacity_exceeded(const char* what, long long needed, long long capacity) {
    throw CapacityError(std::string("bearing_env native core: ") + what + " needs " +
                        std::to_string(needed) + " slots, capacity is " + std::to_string(capacity));
}

// Check `needed <= capacity`, raising CapacityError otherwise.
inline void check_capacity(const char* what, long long needed, long long capacity) {
    if (needed > capacity) capacity_exceeded(what, needed, capacity);
}

}  // namespace bearing
