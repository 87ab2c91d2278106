// The compiled kernels of agents/planning.py (the one-step look-ahead planner).
#pragma once

#include <cstdint>

#include <bearing_core/core/complex.hpp>
#include <bearing_core/core/views.hpp>
#include <bearing_core/slam/state.hpp>

namespace bearing::env {

// potential_of of every row of areas (rows, m) into out (rows,).
void potentials_of_rows(View2<const double> rows, bool log_area, double floor, double cap,
                        View1<double> out);
// out[k] = start + distances[k] * (cos(headings[k]) + i sin(headings[k])).
void move_ends(cplx start, View1<const double> headings, View1<const double> distances,
               View1<cplx> out);

// out[k]: the bearing of a point at differences[k] (point - position) from a robot facing
// headings[k], wrap(atan2 - heading) (agents/planning.py's bearings_from).
void bearings_of(View1<const cplx> differences, View1<const double> headings, View1<double> out);

// What simulate_potentials scores: candidate k turns to headings[k] and travels
// distances[k] (FL units) from `start`; the map's landmarks are at `landmarks` (n, FL; NaN
// where unknown: parallel readings, no region). A candidate shorter than min_distance
// does not update the map.
struct Candidates {
    cplx start;
    View1<const cplx> landmarks;    // (n,) L1 = 0, L2 = 1 first
    View1<const double> headings;   // (K,)
    View1<const double> distances;  // (K,)
    double min_distance = 0.0;
};

// How a simulated map is scored: the env's uncertainty potential.
struct Scoring {
    double area_cap = 0.0;
    double floor = 0.0;
    bool log_area = true;
};

// The readings of the moving candidates: candidate moving[i] reads start[i] and end[i]
// (n each; NaN for a missed landmark).
struct Readings {
    View1<const int64_t> moving;  // (K',) candidate indices
    View2<const double> start;    // (K', n)
    View2<const double> end;      // (K', n)
};

// trials' map i becomes a copy of map rows[i] of `maps`, fused from the readings start[i]
// and end[i] (n each; NaN for a missed landmark); out[i] its potential (Lookahead's beam
// expansions). threads > 1 splits the update over that many threads (same results).
void score_rows(const slam::MapState& maps, View1<const int64_t> rows, const slam::Params& params,
                View2<const double> start, View2<const double> end, const Scoring& scoring,
                const slam::MapState& trials, View1<double> out, int64_t threads);

// The potential after each candidate into out (K,): the map's own potential for a
// candidate that does not move; moving candidate moving[i] fused into its own copy of map
// `row` of `maps` (trials' map i) from its readings. The caller checks the sizes.
void score_readings(const slam::MapState& maps, int64_t row, const slam::Params& params,
                    const Readings& readings, const Scoring& scoring, const slam::MapState& trials,
                    View1<double> out);

// agents/planning.py's simulate_potentials without a visibility prediction, in one call,
// the same bits: the potential after each candidate move into out (K,), each moving
// candidate fused into its own copy of map `row` of `maps` (noise-free readings of the
// landmarks from `start` and from the move's end), the copies in `trials`' first maps.
// The caller checks that trials holds K maps of maps' shape, row, and the sizes.
void simulate_potentials(const slam::MapState& maps, int64_t row, const slam::Params& params,
                         const Candidates& candidates, const Scoring& scoring,
                         const slam::MapState& trials, View1<double> out);

}  // namespace bearing::env
