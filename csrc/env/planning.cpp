// agents/planning.py's kernels (see planning.hpp).
#include <bearing_core/env/planning.hpp>

#include <cmath>
#include <vector>

#include <bearing_core/core/pymath.hpp>
#include <bearing_core/env/kernels.hpp>
#include <bearing_core/slam/update.hpp>

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

namespace {

// The bearing of target from a robot at `from` facing heading (bearings_of's).
double bearing_from(cplx from, double heading, cplx target) {
    const cplx d = target - from;
    return wrap(std::atan2(d.im, d.re) - heading);
}

}  // namespace

void bearings_of(View1<const cplx> differences, View1<const double> headings, View1<double> out) {
    for (int64_t k = 0; k < differences.shape[0]; ++k) {
        out[k] = wrap(std::atan2(differences[k].im, differences[k].re) - headings[k]);
    }
}

void score_rows(const slam::MapState& maps, View1<const int64_t> rows, const slam::Params& params,
                View2<const double> start, View2<const double> end, const Scoring& scoring,
                const slam::MapState& trials, View1<double> out, int64_t threads) {
    const int64_t m = maps.counts.shape[1], size = rows.shape[0];
    if (size == 0) return;
    std::vector<int64_t> trial_rows(static_cast<size_t>(size));
    for (int64_t i = 0; i < size; ++i) trial_rows[static_cast<size_t>(i)] = i;
    slam::copy_maps(maps, rows, trials);
    std::vector<int8_t> frame_status(trial_rows.size()), landmark_status(trial_rows.size() * m);
    std::vector<int64_t> n_bad(trial_rows.size());
    const slam::Outputs outputs{
        {frame_status.data(), {size}}, {landmark_status.data(), {size, m}}, {n_bad.data(), {size}}};
    slam::update_maps(start, end, {trial_rows.data(), {size}}, params, trials, outputs, threads);
    for (int64_t i = 0; i < size; ++i) {
        out[i] =
            potential_of(trials.areas.row(i), m, scoring.log_area, scoring.floor, scoring.area_cap);
    }
}

void score_readings(const slam::MapState& maps, int64_t row, const slam::Params& params,
                    const Readings& readings, const Scoring& scoring, const slam::MapState& trials,
                    View1<double> out) {
    const int64_t m = maps.counts.shape[1], size = readings.moving.shape[0];
    const double current =
        potential_of(maps.areas.row(row), m, scoring.log_area, scoring.floor, scoring.area_cap);
    for (int64_t k = 0; k < out.shape[0]; ++k) out[k] = current;
    std::vector<int64_t> rows(static_cast<size_t>(size), row);
    std::vector<double> scores(rows.size());
    score_rows(maps, {rows.data(), {size}}, params, readings.start, readings.end, scoring, trials,
               {scores.data(), {size}}, 1);
    for (int64_t i = 0; i < size; ++i) out[readings.moving[i]] = scores[static_cast<size_t>(i)];
}

void simulate_potentials(const slam::MapState& maps, int64_t row, const slam::Params& params,
                         const Candidates& candidates, const Scoring& scoring,
                         const slam::MapState& trials, View1<double> out) {
    const int64_t n = maps.counts.shape[1] + 2, count = candidates.headings.shape[0];
    std::vector<int64_t> moving;
    for (int64_t k = 0; k < count; ++k) {
        if (candidates.distances[k] >= candidates.min_distance) moving.push_back(k);
    }
    const auto size = static_cast<int64_t>(moving.size());
    // The readings at both ends of each moving candidate (an unknown landmark is read at
    // the start's bearing twice: no region).
    std::vector<double> start(static_cast<size_t>(size * n)), end(start.size());
    for (int64_t i = 0; i < size; ++i) {
        const int64_t k = moving[static_cast<size_t>(i)];
        const double heading = candidates.headings[k];
        const cplx to =
            candidates.start + candidates.distances[k] * cplx(std::cos(heading), std::sin(heading));
        for (int64_t j = 0; j < n; ++j) {
            const cplx landmark = candidates.landmarks[j];
            const bool known = std::isfinite(landmark.re) && std::isfinite(landmark.im);
            const cplx target = known ? landmark : cplx(0.0, 0.0);
            const double before = bearing_from(candidates.start, heading, target);
            start[static_cast<size_t>(i * n + j)] = before;
            end[static_cast<size_t>(i * n + j)] =
                known ? bearing_from(to, heading, target) : before;
        }
    }
    const Readings readings{
        {moving.data(), {size}}, {start.data(), {size, n}}, {end.data(), {size, n}}};
    score_readings(maps, row, params, readings, scoring, trials, out);
}

}  // namespace bearing::env
