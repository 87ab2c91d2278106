// The env kernels with their arguments checked (checked.hpp).
#include <bearing_core/env/checked.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <bearing_core/core/checks.hpp>
#include <bearing_core/core/errors.hpp>
#include <bearing_core/core/schema.hpp>
#include <bearing_core/env/kernels.hpp>
#include <bearing_core/env/robot_map.hpp>
#include <bearing_core/slam/checked.hpp>

namespace bearing::env::checked {

namespace {

// Another state `trials` of maps' landmarks and fusion arrays, with the arrays params'
// fusion needs and a map per `copies` (one per `each`; `what` in messages).
void check_trials(const slam::MapState& maps, const slam::Params& params,
                  const slam::MapState& trials, int64_t copies, const char* what,
                  const char* each) {
    slam::checked::check_copyable(maps, trials, what);
    slam::checked::check_state_for(trials, params);
    require(trials.vertices.shape[0] >= copies, std::string("trials must hold a map per ") + each);
}

void check_row(const slam::MapState& maps, int64_t row) {
    require(row >= 0 && row < maps.vertices.shape[0], "row is not a map of maps");
}

// rows (distinct) of the state, within the report's rows and encoded's (unless null).
void check_report_rows(View1<const int64_t> rows, const Inputs& inputs, const Report& report,
                       const Encoded* encoded) {
    slam::checked::check_rows(rows, inputs.state.n_landmarks.shape[0], true);
    const int64_t room = report.rewards.shape[0];
    require(rows.shape[0] <= room, "rows has " + std::to_string(rows.shape[0]) +
                                       " rows, the report holds " + std::to_string(room));
    if (encoded != nullptr) check_encoded(*encoded, room, inputs.maps.vertices.shape[1]);
}

// Bearings are finite or NaN (a missed reading).
void check_bearings(View2<const double> start, View2<const double> end) {
    for (const auto& bearings : {start, end}) {
        if (std::any_of(bearings.data, bearings.data + bearings.size(),
                        [](double b) { return std::isinf(b); })) {
            invalid_argument("start and end must be finite bearings or NaN (a missed reading)");
        }
    }
}

}  // namespace

void validate(const Settings& s) {
    sim::Obstacles::checked({s.obstacle_vertices.data, s.obstacle_vertices.shape},
                            {s.obstacle_starts.data, s.obstacle_starts.shape},
                            "settings.obstacle_vertices", "settings.obstacle_starts");
    require(s.n >= 2, "settings.n must be at least 2, got " + std::to_string(s.n));
    require(s.n_slots >= s.n, "settings.n_slots (" + std::to_string(s.n_slots) +
                                  ") must be at least settings.n (" + std::to_string(s.n) + ")");
    // Far above any env's slots (max_landmarks is at most 1024), and low enough that the
    // observation's size (about 8 floats a slot) is computed without overflow.
    constexpr int64_t MAX_SLOTS = int64_t{1} << 20;
    require(s.n_slots <= MAX_SLOTS, "settings.n_slots (" + std::to_string(s.n_slots) +
                                        ") must be at most " + std::to_string(MAX_SLOTS));
    constexpr int64_t MAX_APPENDED = int64_t{1} << 31;
    require(s.appended >= 0 && s.appended <= MAX_APPENDED,
            "settings.appended must be in [0, " + std::to_string(MAX_APPENDED) + "], got " +
                std::to_string(s.appended));
}

void check_inputs(const Inputs& in) {
    const int64_t n = in.settings.n, slots = in.state.landmarks.shape[1];
    const int64_t values = in.state.noise_offsets.shape[1];
    if (slots < n || values < 2 * n) {
        invalid_argument("state has " + std::to_string(slots) +
                         " landmark slots and noise buffers of " + std::to_string(values) +
                         " values; settings.n = " + std::to_string(n) +
                         " needs at least n and 2 n");
    }
    slam::checked::check_state_for(in.maps, in.params);
}

OwnedStepBuffers::OwnedStepBuffers(int64_t capacity, int64_t n) {
    require(capacity >= 0 && n >= 2, "a step's buffers need capacity >= 0 and n >= 2");
    const auto rows = static_cast<size_t>(capacity);
    start_.assign(rows * static_cast<size_t>(n), 0.0);
    end_.assign(rows * static_cast<size_t>(n), 0.0);
    moving_.assign(rows, 0);
    moving_rows_.assign(rows, 0);
    n_bad_.assign(rows, 0);
    frame_status_.assign(rows, 0);
    landmark_status_.assign(rows * static_cast<size_t>(n - 2), 0);
    views_.start = {start_.data(), {capacity, n}};
    views_.end = {end_.data(), {capacity, n}};
    views_.moving = {moving_.data(), {capacity}};
    views_.moving_rows = {moving_rows_.data(), {capacity}};
    views_.out.frame_status = {frame_status_.data(), {capacity}};
    views_.out.landmark_status = {landmark_status_.data(), {capacity, n - 2}};
    views_.out.n_bad = {n_bad_.data(), {capacity}};
}

void check_encoded(const Encoded& encoded, int64_t rows, int64_t mapped) {
    check_axis(encoded.vertices, 0, rows, "encoded.vertices");
    if (encoded.vertices.shape[1] < mapped) {
        invalid_argument("encoded.vertices has " + std::to_string(encoded.vertices.shape[1]) +
                         " landmark slots, the maps map " + std::to_string(mapped));
    }
}

StepOutputs::StepOutputs(const Inputs& inputs, const Report& report, std::optional<Encoded> encoded)
    : inputs_(&inputs), report_(report), encoded_(std::move(encoded)) {
    const int64_t n = inputs.settings.n;
    schema::Sizes sizes{{"m", n - 2}, {"obs", observation_size(inputs.settings)}};
    schema::check_shapes(report_, sizes, "report");
    if (encoded_) {
        schema::Sizes map_sizes{{"CAPACITY", slam::CAPACITY}};
        schema::check_shapes(*encoded_, map_sizes, "encoded");
        check_encoded(*encoded_, capacity(), n - 2);
    }
    buffers_ = OwnedStepBuffers(capacity(), n);
}

// A call that writes into outputs: made for these inputs, with the encoded arrays when
// with_map, and in use by this call alone (two threads may not step one group at once).
class Writing {
public:
    Writing(StepOutputs& outputs, const Inputs& inputs, bool with_map) : busy_(outputs.busy_) {
        require(outputs.inputs_ == &inputs,
                "outputs were made for other inputs (StepOutputs(inputs, ...))");
        require(!with_map || outputs.with_map(),
                "with_map needs outputs made with the encoded arrays");
        if (busy_.exchange(true)) {
            throw std::runtime_error("these StepOutputs are in use by another thread");
        }
        report = outputs.report_;
        buffers = outputs.buffers_.views();
        encoded = with_map ? &*outputs.encoded_ : nullptr;
    }
    ~Writing() { busy_.store(false); }
    Writing(const Writing&) = delete;
    Writing& operator=(const Writing&) = delete;

    Report report;  // the outputs' arrays the call writes
    StepBuffers buffers;
    const Encoded* encoded = nullptr;  // (none without with_map)

private:
    std::atomic<bool>& busy_;
};

StepStatus step_into(View1<const int64_t> rows, View1<const double> turns,
                     View1<const double> lengths, const Inputs& inputs, View3<double> trajectory,
                     int64_t threads, StepOutputs& outputs, bool with_map) {
    const Writing writing(outputs, inputs, with_map);
    return checked::step_rows(rows, turns, lengths, inputs, trajectory, threads, writing.report,
                              writing.buffers, writing.encoded);
}

void report_into(View1<const int64_t> rows, const Inputs& inputs, StepOutputs& outputs,
                 bool with_map) {
    const Writing writing(outputs, inputs, with_map);
    checked::report_rows(rows, inputs, writing.report, writing.encoded);
}

StepStatus step_rows(View1<const int64_t> rows, View1<const double> turns,
                     View1<const double> lengths, const Inputs& inputs, View3<double> trajectory,
                     int64_t threads, const Report& report, const StepBuffers& buffers,
                     const Encoded* encoded) {
    const int64_t size = rows.shape[0];
    const BatchState& state = inputs.state;
    check_report_rows(rows, inputs, report, encoded);
    check_room(size, buffers.moving.shape[0], "the step's buffers");
    check_axis(turns, 0, size, "turns");
    check_axis(lengths, 0, size, "lengths");
    check_axis(trajectory, 0, state.n_landmarks.shape[0], "trajectory");
    check_axis(trajectory, 2, 2, "trajectory");
    for (int64_t i = 0; i < size; ++i) {
        require(state.noise_used[rows[i]] >= 0 && state.trajectory_length[rows[i]] >= 0,
                "the state's noise_used and trajectory_length must not be negative");
    }
    return env::step_rows(rows, turns, lengths, inputs, trajectory, threads, report, buffers,
                          encoded);
}

void report_rows(View1<const int64_t> rows, const Inputs& inputs, const Report& report,
                 const Encoded* encoded) {
    check_report_rows(rows, inputs, report, encoded);
    const Report views = report.first(rows.shape[0]);
    clear_report(views);
    observe(rows, inputs, views);
    if (encoded != nullptr) env::encode_map_into(inputs.maps, rows, encoded->first(rows.shape[0]));
}

void check_encoding(const slam::MapState& state, View1<const int64_t> rows, int64_t slots) {
    slam::checked::check_rows(rows, state.vertices.shape[0], false);
    const int64_t mapped = state.vertices.shape[1];
    require(slots >= mapped, "slots (" + std::to_string(slots) +
                                 ") must be at least the mapped landmarks (" +
                                 std::to_string(mapped) + ")");
}

void encode_map_into(const slam::MapState& state, View1<const int64_t> rows,
                     const Encoded& encoded) {
    slam::checked::check_rows(rows, state.vertices.shape[0], false);
    check_encoded(encoded, rows.shape[0], state.vertices.shape[1]);
    env::encode_map_into(state, rows, encoded);
}

void potentials(View1<const int64_t> rows, const Inputs& inputs, View1<double> out) {
    slam::checked::check_rows(rows, inputs.state.n_landmarks.shape[0], false);
    check_axis(out, 0, rows.shape[0], "out");
    env::potentials(rows, inputs, out);
}

double move_and_read(int64_t row, double turn, double length, const Inputs& in,
                     View1<double> reading_start, View1<double> reading_end) {
    const int64_t n = in.settings.n;
    require(row >= 0 && row < in.state.n_landmarks.shape[0], "row is out of range");
    require(reading_start.shape[0] >= n && reading_end.shape[0] >= n,
            "reading_start and reading_end must hold settings.n values");
    require(in.state.noise_used[row] >= 0, "the row's noise_used is negative");
    check_capacity("noise values of a move", in.state.noise_used[row] + 2 * n,
                   in.state.noise_offsets.shape[1]);
    return env::move_and_read(row, turn, length, in, reading_start.data, reading_end.data);
}

bool append_positions(View1<const int64_t> rows, View2<const double> positions,
                      View3<double> trajectory, View1<int64_t> lengths) {
    const int64_t num_rows = lengths.shape[0];
    slam::checked::check_rows(rows, num_rows, false);
    check_axis(positions, 0, num_rows, "positions");
    check_axis(positions, 1, 2, "positions");
    check_axis(trajectory, 0, num_rows, "trajectory");
    check_axis(trajectory, 2, 2, "trajectory");
    // A repeated row appends twice: count the appends per row before writing.
    std::vector<int64_t> appended(static_cast<size_t>(num_rows), 0);
    for (int64_t i = 0; i < rows.shape[0]; ++i) {
        const int64_t row = rows[i];
        require(lengths[row] >= 0, "lengths must not be negative");
        if (lengths[row] < trajectory.shape[1]) {
            check_capacity("trajectory positions",
                           lengths[row] + ++appended[static_cast<size_t>(row)],
                           trajectory.shape[1]);
        }
    }
    return env::append_positions(rows, positions, trajectory, lengths);
}

double potential_of(View1<const double> areas, int64_t n_mapped, bool log_area, double floor,
                    double cap) {
    require(n_mapped <= areas.shape[0], "n_mapped (" + std::to_string(n_mapped) +
                                            ") exceeds len(areas) (" +
                                            std::to_string(areas.shape[0]) + ")");
    return env::potential_of(areas.data, n_mapped, log_area, floor, cap);
}

void write_shape(View1<const cplx> vertices, int64_t count, View1<float> out, int64_t j) {
    require(count <= vertices.shape[0] && vertices.shape[0] >= 1,
            "count must be at most len(vertices) (at least 1)");
    require(j >= 0 && SHAPE_FEATURES * (j + 1) <= out.shape[0],
            "out has no shape block " + std::to_string(j));
    env::write_shape(vertices.data, count, out.data, j);
}

template <class T>
ActionsStatus decode_continuous(View2<const T> actions, double lo, double hi, View1<double> turns,
                                View1<double> lengths) {
    check_axis(actions, 1, 2, "actions");
    check_axis(turns, 0, actions.shape[0], "turns");
    check_axis(lengths, 0, actions.shape[0], "lengths");
    return env::decode_continuous<T>(actions, lo, hi, turns, lengths);
}
template ActionsStatus decode_continuous<float>(View2<const float>, double, double, View1<double>,
                                                View1<double>);
template ActionsStatus decode_continuous<double>(View2<const double>, double, double, View1<double>,
                                                 View1<double>);

void potentials_of_rows(View2<const double> rows, bool log_area, double floor, double cap,
                        View1<double> out) {
    check_axis(out, 0, rows.shape[0], "out");
    env::potentials_of_rows(rows, log_area, floor, cap, out);
}

void bearings_of(View1<const cplx> differences, View1<const double> headings, View1<double> out) {
    check_axis(headings, 0, differences.shape[0], "headings");
    check_axis(out, 0, differences.shape[0], "out");
    env::bearings_of(differences, headings, out);
}

void move_ends(cplx start, View1<const double> headings, View1<const double> distances,
               View1<cplx> out) {
    check_axis(distances, 0, headings.shape[0], "distances");
    check_axis(out, 0, headings.shape[0], "out");
    env::move_ends(start, headings, distances, out);
}

void simulate_potentials(const slam::MapState& maps, int64_t row, const slam::Params& params,
                         const Candidates& c, const Scoring& scoring, const slam::MapState& trials,
                         View1<double> out) {
    const int64_t count = c.headings.shape[0];
    check_row(maps, row);
    check_trials(maps, params, trials, count, "_simulate_potentials", "candidate");
    check_axis(c.landmarks, 0, maps.vertices.shape[1] + 2, "landmarks");
    check_axis(c.distances, 0, count, "distances");
    check_axis(out, 0, count, "out");
    env::simulate_potentials(maps, row, params, c, scoring, trials, out);
}

void score_readings(const slam::MapState& maps, int64_t row, const slam::Params& params,
                    const Readings& r, const Scoring& scoring, const slam::MapState& trials,
                    View1<double> out) {
    const int64_t moving = r.moving.shape[0], n = maps.vertices.shape[1] + 2;
    check_row(maps, row);
    check_trials(maps, params, trials, moving, "_score_readings", "move");
    slam::checked::check_rows(r.moving, out.shape[0], true, "moving");
    check_axis(r.start, 0, moving, "start");
    check_axis(r.start, 1, n, "start");
    check_axis(r.end, 0, moving, "end");
    check_axis(r.end, 1, n, "end");
    check_bearings(r.start, r.end);
    env::score_readings(maps, row, params, r, scoring, trials, out);
}

void score_rows(const slam::MapState& maps, View1<const int64_t> rows, const slam::Params& params,
                View2<const double> start, View2<const double> end, const Scoring& scoring,
                const slam::MapState& trials, View1<double> out, int64_t threads) {
    const int64_t size = rows.shape[0], n = maps.vertices.shape[1] + 2;
    slam::checked::check_rows(rows, maps.vertices.shape[0], false);
    check_trials(maps, params, trials, size, "_score_rows", "row");
    check_axis(start, 0, size, "start");
    check_axis(start, 1, n, "start");
    check_axis(end, 0, size, "end");
    check_axis(end, 1, n, "end");
    check_axis(out, 0, size, "out");
    require(threads >= 1, "threads must be at least 1");
    check_bearings(start, end);
    env::score_rows(maps, rows, params, start, end, scoring, trials, out, threads);
}

}  // namespace bearing::env::checked
