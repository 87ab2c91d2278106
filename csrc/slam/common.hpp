// Scalar helpers shared by every kernel of the world model (bearing_env/slam/kernels/common.py).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

#include "core/complex.hpp"
#include "core/pymath.hpp"
#include "slam/state.hpp"

namespace bearing::slam {

// (bounding-box size, largest coordinate magnitude) of poly[:n].
std::pair<double, double> scale_of(const cplx* poly, int64_t n);

// Distance below which two features count as touching, for polygons of that scale.
inline double tolerance_of(double size, double magnitude) {
    return RELATIVE_TOLERANCE * size + 4e-16 * magnitude;
}

}  // namespace bearing::slam
