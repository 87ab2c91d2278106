// Scalar helpers shared by every kernel (bearing_env/slam/kernels/common.py).
#include <bearing_core/slam/common.hpp>

namespace bearing::slam {

std::pair<double, double> scale_of(const cplx* poly, int64_t n) {
    double lo_x = poly[0].re, hi_x = poly[0].re;
    double lo_y = poly[0].im, hi_y = poly[0].im;
    for (int64_t i = 1; i < n; ++i) {
        const double x = poly[i].re, y = poly[i].im;
        lo_x = std::min(lo_x, x);
        hi_x = std::max(hi_x, x);
        lo_y = std::min(lo_y, y);
        hi_y = std::max(hi_y, y);
    }
    const double size = std::max(hi_x - lo_x, hi_y - lo_y);
    const double magnitude = std::max(std::max(std::fabs(lo_x), std::fabs(hi_x)),
                                      std::max(std::fabs(lo_y), std::fabs(hi_y)));
    return {size, magnitude};
}

}  // namespace bearing::slam
