// The compiled kernels of agents/planning.py (the one-step look-ahead planner).
#pragma once

#include <cstdint>

#include <bearing_core/core/complex.hpp>
#include <bearing_core/core/views.hpp>

namespace bearing::env {

// potential_of of every row of areas (rows, m) into out (rows,).
void potentials_of_rows(View2<const double> rows, bool log_area, double floor, double cap,
                        View1<double> out);
// out[k] = start + distances[k] * (cos(headings[k]) + i sin(headings[k])).
void move_ends(cplx start, View1<const double> headings, View1<const double> distances,
               View1<cplx> out);

}  // namespace bearing::env
