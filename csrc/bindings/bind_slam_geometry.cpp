// Bindings of the polygon and frame kernels (csrc/slam/polygons.hpp, frames.hpp).
#include <nanobind/nanobind.h>

namespace nb = nanobind;

void bind_slam_geometry(nb::module_& m) {
    (void)m;
}
