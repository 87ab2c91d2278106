// The extension module bearing_env._core: one module, its parts bound by topic
// (bind_slam.cpp, bind_sim.cpp, bind_env.cpp), each only when its part is built.
#include <nanobind/nanobind.h>

#include <bearing_core/core/errors.hpp>

namespace nb = nanobind;

#if BEARING_ENV_WITH_SLAM
void bind_slam(nb::module_& m);
#endif
#if BEARING_ENV_WITH_SIM
void bind_sim(nb::module_& m);
#endif
#if BEARING_ENV_WITH_ENV
void bind_env(nb::module_& m);
#endif

NB_MODULE(_core, m) {
    m.doc() = "bearing_env's native core (C++17): the world model, the simulator and the env step.";
    nb::exception<bearing::CapacityError>(m, "CapacityError", PyExc_RuntimeError);
#if BEARING_ENV_WITH_SLAM
    bind_slam(m);
#endif
#if BEARING_ENV_WITH_SIM
    bind_sim(m);
#endif
#if BEARING_ENV_WITH_ENV
    bind_env(m);
#endif
}
