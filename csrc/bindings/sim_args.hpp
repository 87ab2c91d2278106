// Checked arguments of the simulator's kernels, shared by bind_sim.cpp and bind_env.cpp.
#pragma once

#include <nanobind/nanobind.h>

#include <string>

#include <bearing_core/sim/sensing.hpp>
#include "bindings/arrays.hpp"

namespace bearing::bindings {

// Packed obstacles (vertices (V, 2) float64, starts (k + 1,) int64), checked so that no
// polygon's vertex range leaves the vertex array (the kernels index it unchecked).
inline sim::Obstacles obstacles_of(nb::handle vertices, nb::handle starts,
                                   const char* vertices_name = "vertices",
                                   const char* starts_name = "starts") {
    sim::Obstacles obstacles;
    obstacles.vertices = view_of<const double, 2>(vertices, vertices_name, {-1, 2});
    obstacles.starts = view_of<const int64_t, 1>(starts, starts_name);
    const int64_t count = obstacles.vertices.shape[0];
    for (int64_t p = 0; p + 1 < obstacles.starts.shape[0]; ++p) {
        const int64_t first = obstacles.starts[p], last = obstacles.starts[p + 1];
        if (first < last && (first < 0 || last > count)) {
            value_error(std::string(starts_name) + " indexes past the " + std::to_string(count) +
                        " obstacle vertices (polygon " + std::to_string(p) + ": " +
                        std::to_string(first) + " to " + std::to_string(last) + ")");
        }
    }
    return obstacles;
}

}  // namespace bearing::bindings
