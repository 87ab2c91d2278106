// The world model's bindings: the polygon and frame kernels (bind_slam_geometry.cpp) and
// the batched map update (bind_slam_update.cpp).
#include <nanobind/nanobind.h>

namespace nb = nanobind;

void bind_slam_geometry(nb::module_& m);
void bind_slam_update(nb::module_& m);

void bind_slam(nb::module_& m) {
    bind_slam_geometry(m);
    bind_slam_update(m);
}
