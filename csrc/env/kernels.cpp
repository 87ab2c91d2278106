// bearing_env/envs/kernels.py's kernels (see kernels.hpp).
#include <bearing_core/env/kernels.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

#include <bearing_core/core/errors.hpp>
#include <bearing_core/core/pymath.hpp>
#include <bearing_core/env/robot_map.hpp>
#include <bearing_core/sim/sensing.hpp>
#include <bearing_core/sim/world.hpp>
#include <bearing_core/slam/polygons.hpp>
#include <bearing_core/slam/update.hpp>

namespace bearing::env {

namespace {

constexpr double INF = std::numeric_limits<double>::infinity();

// A reading of true_bearing with the row's pre-drawn noise value `value` (kernels._noisy).
double noisy(double true_bearing, const BatchState& state, int64_t row, int64_t value) {
    if (state.noise_is_outlier(row, value)) return wrap(state.noise_replacement(row, value));
    return wrap(true_bearing + state.noise_offsets(row, value));
}

// The reading of the landmark at (lx, ly) from a pose: NaN unless the sensor sees it.
double read(const Settings& settings, double x, double y, double heading, double lx, double ly,
            double reading) {
    if (sim::visible(x, y, heading, lx, ly, settings.half_fov, settings.max_range,
                     settings.obstacles())) {
        return reading;
    }
    return std::numeric_limits<double>::quiet_NaN();
}

double potential(const Settings& settings, const double* areas) {
    return potential_of(areas, settings.n - 2, settings.log_area, settings.floor, settings.cap);
}

double coordinate(double value, double limit) { return std::min(std::max(value, -limit), limit); }

// The count of a region the kernels index, checked against its array's capacity.
int64_t checked_count(int64_t count, int64_t capacity) {
    check_capacity("a map region's vertices", count, capacity);
    return count;
}

// Fuse the movements of the rows that travelled at least min_baseline into their maps
// (kernels._update_maps).
void update_moving_maps(View2<double> start, View2<double> end, View1<const int64_t> rows,
                        const Inputs& inputs, int64_t threads, const Report& report,
                        const StepBuffers& buffers) {
    const int64_t rows_size = rows.shape[0];
    check_capacity("moving rows", rows_size, buffers.moving.shape[0]);
    int64_t size = 0;
    for (int64_t i = 0; i < rows_size; ++i) {
        if (report.path_length[i] >= inputs.settings.min_baseline) buffers.moving[size++] = i;
    }
    const int64_t n = start.shape[1];
    if (size == 0) return;
    check_capacity("map update outputs", size, buffers.out.frame_status.shape[0]);
    check_capacity("moving map rows", size, buffers.moving_rows.shape[0]);
    if (size < rows_size) {
        // start[moving], end[moving], in place: moving[k] >= k, so row moving[k] is read
        // before it could be overwritten.
        for (int64_t k = 0; k < size; ++k) {
            const int64_t from = buffers.moving[k];
            if (from == k) continue;
            std::copy(start.row(from), start.row(from) + n, start.row(k));
            std::copy(end.row(from), end.row(from) + n, end.row(k));
        }
    }
    for (int64_t k = 0; k < size; ++k) buffers.moving_rows[k] = rows[buffers.moving[k]];
    View2<const double> moving_start{start.data, {size, n}};
    View2<const double> moving_end{end.data, {size, n}};
    View1<const int64_t> moving_rows{buffers.moving_rows.data, {size}};
    slam::Outputs out;
    out.frame_status = {buffers.out.frame_status.data, {size}};
    out.landmark_status = {buffers.out.landmark_status.data,
                           {size, buffers.out.landmark_status.shape[1]}};
    out.n_bad = {buffers.out.n_bad.data, {size}};
    const int64_t blocks =
        threads > 1 && size >= slam::PARALLEL_MIN_MAPS ? std::min(size, threads) : int64_t{1};
    slam::update_maps(moving_start, moving_end, moving_rows, inputs.params, inputs.maps, out,
                      blocks);
    for (int64_t k = 0; k < size; ++k) {
        report.frame_changed[buffers.moving[k]] = out.frame_status[k] == slam::FRAME_OK;
        report.inconsistent[buffers.moving[k]] = out.n_bad[k];
    }
}

}  // namespace

Report Report::first(int64_t size) const { return first_rows(*this, size); }

Encoded Encoded::first(int64_t size) const { return first_rows(*this, size); }

double move_and_read(int64_t row, double turn, double length, const Inputs& inputs,
                     double* reading_start, double* reading_end) {
    const Settings& settings = inputs.settings;
    const BatchState& state = inputs.state;
    const int64_t n = settings.n;
    const double heading = wrap(state.headings[row] + turn);
    const double x = state.positions(row, 0), y = state.positions(row, 1);
    const sim::Move move = sim::obstructed_move(
        x, y, heading, length,
        sim::MoveSettings{settings.width, settings.height, settings.margin, settings.min_baseline},
        settings.obstacles());
    const double new_x = move.x, new_y = move.y;
    const int64_t first = state.noise_used[row];
    for (int64_t j = 0; j < n; ++j) {
        const double lx = state.landmarks(row, j, 0), ly = state.landmarks(row, j, 1);
        double reading = noisy(sim::bearing(lx, ly, x, y, heading), state, row, first + j);
        reading = read(settings, x, y, heading, lx, ly, reading);
        reading_start[j] = state.start_bearings(row, j) = reading;
        reading = noisy(sim::bearing(lx, ly, new_x, new_y, heading), state, row, first + n + j);
        reading = read(settings, new_x, new_y, heading, lx, ly, reading);
        reading_end[j] = state.latest_bearings(row, j) = reading;
    }
    state.noise_used[row] = first + 2 * n;
    state.start_positions(row, 0) = x;
    state.start_positions(row, 1) = y;
    state.positions(row, 0) = new_x;
    state.positions(row, 1) = new_y;
    state.headings[row] = heading;
    state.blocked[row] = move.blocked;
    state.moves[row] += 1;
    return move.travelled;
}

bool append_positions(View1<const int64_t> rows, View2<const double> positions,
                      View3<double> trajectory, View1<int64_t> lengths) {
    const int64_t capacity = trajectory.shape[1];
    for (int64_t i = 0; i < rows.shape[0]; ++i) {
        if (lengths[rows[i]] >= capacity) return false;
    }
    for (int64_t i = 0; i < rows.shape[0]; ++i) {
        const int64_t row = rows[i];
        trajectory(row, lengths[row], 0) = positions(row, 0);
        trajectory(row, lengths[row], 1) = positions(row, 1);
        lengths[row] += 1;
    }
    return true;
}

double potential_of(const double* areas, int64_t n_mapped, bool log_area, double floor,
                    double cap) {
    double total = 0.0;
    for (int64_t j = 0; j < n_mapped; ++j) {
        const double value = capped(areas[j], floor, cap);
        total += log_area ? std::log(value) : value;
    }
    return total;
}

void potentials(View1<const int64_t> rows, const Inputs& inputs, View1<double> out) {
    for (int64_t i = 0; i < rows.shape[0]; ++i) {
        out[i] = potential(inputs.settings, inputs.maps.areas.row(rows[i]));
    }
}

void clear_report(const Report& report) {
    std::fill_n(report.observations.data, report.observations.size(), 0.0f);
    std::fill_n(report.rewards.data, report.rewards.size(), 0.0);
    std::fill_n(report.terminated.data, report.terminated.size(), false);
    std::fill_n(report.truncated.data, report.truncated.size(), false);
    std::fill_n(report.frame_changed.data, report.frame_changed.size(), false);
    std::fill_n(report.inconsistent.data, report.inconsistent.size(), int64_t{0});
    std::fill_n(report.path_length.data, report.path_length.size(), 0.0);
    std::fill_n(report.uncertainty.data, report.uncertainty.size(), 0.0);
    std::fill_n(report.path_cost.data, report.path_cost.size(), 0.0);
    std::fill_n(report.move_cost.data, report.move_cost.size(), 0.0);
}

void finish_row(int64_t i, int64_t row, const Inputs& inputs, const Report& report) {
    const Settings& settings = inputs.settings;
    const slam::MapState& maps = inputs.maps;
    const BatchState& state = inputs.state;
    const double value = potential(settings, maps.areas.row(row));
    report.uncertainty[i] = state.potentials[row] - value;
    report.path_cost[i] = -settings.path_cost * report.path_length[i];
    report.move_cost[i] = -settings.move_cost;
    // 0.0 + turns an uncertainty of -0.0 into 0.0; the order of the sum is fixed.
    report.rewards[i] = ((0.0 + report.uncertainty[i]) + report.path_cost[i]) + report.move_cost[i];
    state.potentials[row] = value;
    bool success = true;
    for (int64_t j = 0; j < settings.n - 2; ++j) {
        if (maps.counts(row, j) == 0 || !(maps.areas(row, j) <= settings.target_area)) {
            success = false;
            break;
        }
    }
    report.terminated[i] = success;
    report.truncated[i] = !success && state.moves[row] >= settings.max_moves;
    state.done[row] = report.terminated[i] || report.truncated[i];
}

void write_observation(int64_t row, const Inputs& inputs, float* out) {
    const Settings& settings = inputs.settings;
    const slam::MapState& maps = inputs.maps;
    const BatchState& state = inputs.state;
    const double floor = settings.floor, cap = settings.cap, limit = settings.coordinate_limit;
    const int64_t bearings_at = ROBOT_FEATURES + LANDMARK_FEATURES * (settings.n_slots - 2);
    const cplx centroid = maps.robot_centroid[row];
    const bool known =
        maps.robot_counts[row] > 0 && std::isfinite(centroid.re) && std::isfinite(centroid.im);
    if (known) {
        out[0] = static_cast<float>(coordinate(centroid.re, limit));
        out[1] = static_cast<float>(coordinate(centroid.im, limit));
        out[2] = static_cast<float>(std::log(capped(maps.robot_area[row], floor, cap)));
    } else {
        out[2] = static_cast<float>(std::log(cap));
        out[3] = 1.0f;
    }
    const double heading = maps.robot_heading[row];
    if (std::isfinite(heading)) {
        out[4] = static_cast<float>(std::cos(heading));
        out[5] = static_cast<float>(std::sin(heading));
    }
    out[6] = static_cast<float>(std::min(
        static_cast<double>(state.moves[row]) / static_cast<double>(settings.max_moves), 1.0));
    out[7] = state.frame_changed[row] ? 1.0f : 0.0f;
    out[8] = state.blocked[row] ? 1.0f : 0.0f;
    for (int64_t j = 0; j < settings.n - 2; ++j) {
        const int64_t at = ROBOT_FEATURES + LANDMARK_FEATURES * j;
        out[at] = 1.0f;
        if (maps.counts(row, j) > 0) {
            out[at + 2] = static_cast<float>(coordinate(maps.centroids(row, j).re, limit));
            out[at + 3] = static_cast<float>(coordinate(maps.centroids(row, j).im, limit));
        } else {
            out[at + 1] = 1.0f;
        }
        out[at + 4] = static_cast<float>(std::log(capped(maps.areas(row, j), floor, cap)));
    }
    const auto& latest = state.latest_bearings;
    for (int64_t k = 0; k < settings.n; ++k) {
        const int64_t at = bearings_at + BEARING_FEATURES * k;
        out[at] = 1.0f;
        if (!std::isnan(latest(row, k))) {  // a missed reading reads (0, 0)
            out[at + 1] = static_cast<float>(std::cos(latest(row, k)));
            out[at + 2] = static_cast<float>(std::sin(latest(row, k)));
        }
    }
    if (settings.shape_features) {
        const int64_t shapes_at = bearings_at + BEARING_FEATURES * settings.n_slots;
        const int64_t capacity = maps.vertices.shape[2];
        for (int64_t j = 0; j < settings.n - 2; ++j) {
            const int64_t count = maps.counts(row, j);
            if (count >= 3) {
                write_shape(maps.vertices.row(row, j), checked_count(count, capacity),
                            out + shapes_at, j);
            }
        }
    }
}

void write_shape(const cplx* vertices, int64_t count, float* out, int64_t j) {
    const cplx origin = vertices[0];
    double area2 = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, syy = 0.0, sxy = 0.0;
    for (int64_t k = 0; k < count; ++k) {
        const cplx p = vertices[k] - origin, q = vertices[py_mod(k + 1, count)] - origin;
        const double c = p.re * q.im - q.re * p.im;
        area2 += c;
        sx += c * (p.re + q.re);
        sy += c * (p.im + q.im);
        sxx += c * (p.re * p.re + p.re * q.re + q.re * q.re);
        syy += c * (p.im * p.im + p.im * q.im + q.im * q.im);
        const double cross_terms = p.re * q.im + q.re * p.im;
        sxy += c * (2.0 * p.re * p.im + cross_terms + 2.0 * q.re * q.im);
    }
    if (!(std::fabs(area2) > 0.0)) return;
    // Central moments per unit area (the signs of a clockwise ring cancel).
    const double cx = sx / (3.0 * area2), cy = sy / (3.0 * area2);
    const double a = sxx / (6.0 * area2) - cx * cx;
    const double b = sxy / (12.0 * area2) - cx * cy;
    const double d = syy / (6.0 * area2) - cy * cy;
    const double half_difference = 0.5 * (a - d);
    const double radius = std::sqrt(half_difference * half_difference + b * b);
    const double mean = 0.5 * (a + d);
    const double longest = mean + radius, shortest = mean - radius;
    const int64_t at = SHAPE_FEATURES * j;
    if (!(shortest > 0.0) || longest > shortest * std::exp(2.0 * ELONGATION_LIMIT)) {
        out[at] = static_cast<float>(ELONGATION_LIMIT);
    } else {
        out[at] = static_cast<float>(0.5 * std::log(longest / shortest));
    }
    if (radius > 0.0) {
        out[at + 1] = static_cast<float>(half_difference / radius);
        out[at + 2] = static_cast<float>(b / radius);
    }
}

void write_info(int64_t i, int64_t row, const Inputs& inputs, const Report& report) {
    const Settings& settings = inputs.settings;
    const slam::MapState& maps = inputs.maps;
    const BatchState& state = inputs.state;
    const int64_t capacity = maps.vertices.shape[2];
    double total = 0.0;
    for (int64_t j = 0; j < settings.n - 2; ++j) {
        const double area = maps.areas(row, j);
        report.landmark_area(i, j) = area;
        total += area;
        report.outliers(i, j) = maps.outliers(row, j);
        const int64_t count = maps.counts(row, j);
        if (count > 0) {
            const cplx truth = state.landmarks_fl(row, j);
            report.landmark_error(i, j) = abs(maps.centroids(row, j) - truth);
            report.landmark_contains_truth(i, j) =
                slam::contains_point(maps.vertices.row(row, j), checked_count(count, capacity),
                                     truth, settings.tolerance);
        } else {
            report.landmark_error(i, j) = INF;
            report.landmark_contains_truth(i, j) = false;
        }
    }
    report.total_area[i] = total;
    const cplx centroid = maps.robot_centroid[row];
    if (std::isfinite(centroid.re) && std::isfinite(centroid.im)) {
        const cplx position(state.positions(row, 0), state.positions(row, 1));
        const cplx truth = (position - state.frame_origin[row]) / state.frame_unit[row];
        report.robot_error[i] = abs(centroid - truth);
    } else {
        report.robot_error[i] = INF;
    }
}

void observe(View1<const int64_t> rows, const Inputs& inputs, const Report& report) {
    for (int64_t i = 0; i < rows.shape[0]; ++i) {
        write_observation(rows[i], inputs, report.observations.row(i));
        write_info(i, rows[i], inputs, report);
    }
}

int64_t observation_size(const Settings& settings) {
    const int64_t slots = settings.n_slots;
    const int64_t size = ROBOT_FEATURES + LANDMARK_FEATURES * (slots - 2) +
                         BEARING_FEATURES * slots + settings.appended;
    return settings.shape_features ? size + SHAPE_FEATURES * (slots - 2) : size;
}

StepStatus room_for_step(View1<const int64_t> rows, const Inputs& inputs,
                         View1<const int64_t> trajectory_length, int64_t capacity) {
    const BatchState& state = inputs.state;
    const int64_t n = inputs.settings.n;
    for (int64_t i = 0; i < rows.shape[0]; ++i) {
        const int64_t row = rows[i];
        if (state.noise_used[row] + 2 * n > state.noise_filled[row]) return STEP_NEEDS_NOISE;
    }
    for (int64_t i = 0; i < rows.shape[0]; ++i) {
        if (trajectory_length[rows[i]] >= capacity) return STEP_NEEDS_TRAJECTORY;
    }
    return STEP_DONE;
}

StepStatus step_rows(View1<const int64_t> rows, View1<const double> turns,
                     View1<const double> lengths, const Inputs& inputs, View3<double> trajectory,
                     int64_t threads, const Report& full_report, const StepBuffers& buffers,
                     const Encoded* encoded) {
    const BatchState& state = inputs.state;
    const int64_t size = rows.shape[0], n = inputs.settings.n;
    View1<const int64_t> trajectory_length{state.trajectory_length.data,
                                           state.trajectory_length.shape};
    const StepStatus status = room_for_step(rows, inputs, trajectory_length, trajectory.shape[1]);
    if (status != STEP_DONE) return status;
    // What the check above promises, against the noise arrays' size (a corrupt state
    // raises instead of reading out of bounds; the bindings checked that no count is
    // negative).
    for (int64_t i = 0; i < size; ++i) {
        const int64_t row = rows[i];
        check_capacity("noise values of a move", state.noise_used[row] + 2 * n,
                       state.noise_offsets.shape[1]);
    }
    check_capacity("report rows", size, full_report.rewards.shape[0]);
    check_capacity("step readings", size, buffers.start.shape[0]);
    check_capacity("step reading slots", n, buffers.start.shape[1]);
    const Report report = full_report.first(size);
    clear_report(report);
    View2<double> start{buffers.start.data, {size, n}};
    View2<double> end{buffers.end.data, {size, n}};
    for (int64_t i = 0; i < size; ++i) {
        const int64_t row = rows[i];
        report.path_length[i] =
            move_and_read(row, turns[i], lengths[i], inputs, start.row(i), end.row(i));
        const int64_t at = state.trajectory_length[row];
        trajectory(row, at, 0) = state.positions(row, 0);
        trajectory(row, at, 1) = state.positions(row, 1);
        state.trajectory_length[row] = at + 1;
    }
    update_moving_maps(start, end, rows, inputs, threads, report, buffers);
    for (int64_t i = 0; i < size; ++i) {
        state.frame_changed[rows[i]] = report.frame_changed[i];
        finish_row(i, rows[i], inputs, report);
    }
    observe(rows, inputs, report);
    if (encoded != nullptr) {
        check_capacity("encoded map rows", size, encoded->n_updates.shape[0]);
        encode_map_into(inputs.maps, rows, encoded->first(size));
    }
    return STEP_DONE;
}

template <class T>
ActionsStatus decode_continuous(View2<const T> actions, double lo, double hi, View1<double> turns,
                                View1<double> lengths) {
    for (int64_t i = 0; i < actions.shape[0]; ++i) {
        double a = static_cast<double>(actions(i, 0)), b = static_cast<double>(actions(i, 1));
        if (!(std::isfinite(a) && std::isfinite(b))) return ACTIONS_NOT_FINITE;
        if (std::fabs(a) > 1.0 + 1e-6 || std::fabs(b) > 1.0 + 1e-6) return ACTIONS_OUTSIDE;
        a = std::min(std::max(a, -1.0), 1.0);
        b = std::min(std::max(b, -1.0), 1.0);
        turns[i] = PI * a;
        lengths[i] = lo + 0.5 * (b + 1.0) * (hi - lo);
    }
    return ACTIONS_OK;
}

template ActionsStatus decode_continuous<float>(View2<const float>, double, double, View1<double>,
                                                View1<double>);
template ActionsStatus decode_continuous<double>(View2<const double>, double, double, View1<double>,
                                                 View1<double>);

}  // namespace bearing::env
