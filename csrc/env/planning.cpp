// agents/planning.py's kernels (see planning.hpp).
#include <bearing_core/env/planning.hpp>

#include <cmath>

#include <bearing_core/env/kernels.hpp>

namespace bearing::env {

void potentials_of_rows(View2<const double> rows, bool log_area, double floor, double cap,
                        View1<double> out) {
    for (int64_t i = 0; i < rows.shape[0]; ++i) {
        out[i] = potential_of(rows.row(i), rows.shape[1], log_area, floor, cap);
    }
}

void move_ends(cplx start, View1<const double> headings, View1<const double> distances,
               View1<cplx> out) {
    for (int64_t k = 0; k < headings.shape[0]; ++k) {
        out[k] = start + distances[k] * cplx(std::cos(headings[k]), std::sin(headings[k]));
    }
}

}  // namespace bearing::env
