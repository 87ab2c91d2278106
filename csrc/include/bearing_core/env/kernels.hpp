// The envs' step (bearing_env/envs/kernels.py, ported function for function, same order of
// operations): a group of rows moves, reads, updates its maps, and gets its rewards,
// terminations, observations and infos in one call.
#pragma once

#include <algorithm>
#include <cstdint>

#include <bearing_core/env/types.hpp>

namespace bearing::env {

// Turn, read, move, read again: row `row`'s movement; returns the distance travelled.
// The readings go to reading_start[:n] and reading_end[:n].
double move_and_read(int64_t row, double turn, double length, const Inputs& inputs,
                     double* reading_start, double* reading_end);

// Append each row's position to its trajectory; false (nothing written) when some row's
// trajectory is full.
bool append_positions(View1<const int64_t> rows, View2<const double> positions,
                      View3<double> trajectory, View1<int64_t> lengths);

double potential_of(const double* areas, int64_t n_mapped, bool log_area, double floor, double cap);
void potentials(View1<const int64_t> rows, const Inputs& inputs, View1<double> out);

// report's first rows as kernels._new_report makes them (zero observations and reward
// parts, no episode end).
void clear_report(const Report& report);
void finish_row(int64_t i, int64_t row, const Inputs& inputs, const Report& report);
// Row `row`'s observation into out[:observation_size(settings)] (zeros).
void write_observation(int64_t row, const Inputs& inputs, float* out);
// Region j's shape block into out[SHAPE_FEATURES * j:][:SHAPE_FEATURES].
void write_shape(const cplx* vertices, int64_t count, float* out, int64_t j);
void write_info(int64_t i, int64_t row, const Inputs& inputs, const Report& report);
void observe(View1<const int64_t> rows, const Inputs& inputs, const Report& report);
int64_t observation_size(const Settings& settings);

StepStatus room_for_step(View1<const int64_t> rows, const Inputs& inputs,
                         View1<const int64_t> trajectory_length, int64_t capacity);

// One movement of every row of a group (kernels.step_rows_bare), into report's first
// len(rows) rows; the per-call buffers are `buffers` (capacity >= len(rows)). With
// `encoded` (not null), the robot map's arrays too (kernels.step_rows).
StepStatus step_rows(View1<const int64_t> rows, View1<const double> turns,
                     View1<const double> lengths, const Inputs& inputs, View3<double> trajectory,
                     int64_t threads, const Report& report, const StepBuffers& buffers,
                     const Encoded* encoded);

// Turn angles and move lengths of continuous actions (N, 2) in [-1, 1]^2.
template <class T>
ActionsStatus decode_continuous(View2<const T> actions, double lo, double hi, View1<double> turns,
                                View1<double> lengths);

inline double capped(double area, double floor, double cap) {
    return std::min(std::max(area, floor), cap);
}

}  // namespace bearing::env
