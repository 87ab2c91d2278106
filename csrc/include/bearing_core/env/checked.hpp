// The env kernels (kernels.hpp, planning.hpp) with their arguments checked: each checks
// its arrays' shapes against each other and the inputs, its rows and counts against
// what they index, and the state's cursors it reads, then runs the kernel. A bad argument
// throws std::invalid_argument naming it (the Python bindings are these).
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <vector>

#include <bearing_core/core/complex.hpp>
#include <bearing_core/core/views.hpp>
#include <bearing_core/env/planning.hpp>
#include <bearing_core/env/types.hpp>

namespace bearing::env::checked {

// A group's settings: n >= 2 landmarks, n <= n_slots <= 2^20, obstacles within their
// vertices.
void validate(const Settings& settings);
// A group's inputs agree: the state's landmark slots and noise buffers hold n and 2 n,
// and the map state has the arrays the update settings' fusion needs.
void check_inputs(const Inputs& inputs);

// A step's per-call buffers (StepBuffers) for `capacity` rows of n landmarks, owned.
class OwnedStepBuffers {
public:
    explicit OwnedStepBuffers(int64_t capacity = 0, int64_t n = 2);
    const StepBuffers& views() const { return views_; }

private:
    std::vector<double> start_, end_;
    std::vector<int64_t> moving_, moving_rows_, n_bad_;
    std::vector<int8_t> frame_status_, landmark_status_;
    StepBuffers views_;
};

// The encoded arrays of `rows` maps hold every one of `mapped` landmarks.
void check_encoded(const Encoded& encoded, int64_t rows, int64_t mapped);

// A group's step outputs, made once for its inputs: a Report's views of `capacity` rows
// (shaped for the settings' landmarks and observation), the robot map's encoded views
// (optional) and the step's buffers (owned). step_into and report_into write their first
// len(rows) rows, one call at a time: a second thread's call throws std::runtime_error.
class StepOutputs {
public:
    StepOutputs(const Inputs& inputs, const Report& report, std::optional<Encoded> encoded);
    int64_t capacity() const { return report_.rewards.shape[0]; }
    bool with_map() const { return encoded_.has_value(); }

private:
    friend class Writing;
    const Inputs* inputs_;
    Report report_;
    std::optional<Encoded> encoded_;
    OwnedStepBuffers buffers_;
    std::atomic<bool> busy_{false};
};

// step_rows into outputs made for `inputs` (with the encoded arrays when with_map).
StepStatus step_into(View1<const int64_t> rows, View1<const double> turns,
                     View1<const double> lengths, const Inputs& inputs, View3<double> trajectory,
                     int64_t threads, StepOutputs& outputs, bool with_map);
// report_rows into outputs made for `inputs`, as step_into writes them.
void report_into(View1<const int64_t> rows, const Inputs& inputs, StepOutputs& outputs,
                 bool with_map);

// step_rows (kernels.hpp) with its arguments checked: the rows (none repeated) in the
// state and within the report's and the buffers' rows, the actions, the trajectory and
// the rows' cursors.
StepStatus step_rows(View1<const int64_t> rows, View1<const double> turns,
                     View1<const double> lengths, const Inputs& inputs, View3<double> trajectory,
                     int64_t threads, const Report& report, const StepBuffers& buffers,
                     const Encoded* encoded);
// The rows' observations and infos as they stand into report's (and encoded's, unless
// null) first len(rows) rows (kernels.report_rows).
void report_rows(View1<const int64_t> rows, const Inputs& inputs, const Report& report,
                 const Encoded* encoded);
// A codec's new arrays can take `rows` of `state` in `slots` landmark slots: the rows are
// in the state, the slots at least its mapped landmarks.
void check_encoding(const slam::MapState& state, View1<const int64_t> rows, int64_t slots);
// encode_map_into (robot_map.hpp) with `rows` in the state and encoded's rows and slots
// checked.
void encode_map_into(const slam::MapState& state, View1<const int64_t> rows,
                     const Encoded& encoded);
void potentials(View1<const int64_t> rows, const Inputs& inputs, View1<double> out);
double move_and_read(int64_t row, double turn, double length, const Inputs& inputs,
                     View1<double> reading_start, View1<double> reading_end);
bool append_positions(View1<const int64_t> rows, View2<const double> positions,
                      View3<double> trajectory, View1<int64_t> lengths);
double potential_of(View1<const double> areas, int64_t n_mapped, bool log_area, double floor,
                    double cap);
void write_shape(View1<const cplx> vertices, int64_t count, View1<float> out, int64_t j);
template <class T>
ActionsStatus decode_continuous(View2<const T> actions, double lo, double hi, View1<double> turns,
                                View1<double> lengths);

void potentials_of_rows(View2<const double> rows, bool log_area, double floor, double cap,
                        View1<double> out);
void bearings_of(View1<const cplx> differences, View1<const double> headings, View1<double> out);
void move_ends(cplx start, View1<const double> headings, View1<const double> distances,
               View1<cplx> out);
void simulate_potentials(const slam::MapState& maps, int64_t row, const slam::Params& params,
                         const Candidates& candidates, const Scoring& scoring,
                         const slam::MapState& trials, View1<double> out);
void score_readings(const slam::MapState& maps, int64_t row, const slam::Params& params,
                    const Readings& readings, const Scoring& scoring, const slam::MapState& trials,
                    View1<double> out);
void score_rows(const slam::MapState& maps, View1<const int64_t> rows, const slam::Params& params,
                View2<const double> start, View2<const double> end, const Scoring& scoring,
                const slam::MapState& trials, View1<double> out, int64_t threads);

}  // namespace bearing::env::checked
