// Bindings of the env step (csrc/env/): EnvInputs (a group's long-lived inputs, made once
// where core.py made kernels.inputs_ref), StepOutputs (a group's output arrays and per-call
// buffers, made once where core._outputs made them), step_rows (the whole step, the GIL
// released) and the other kernels of bearing_env/envs/kernels.py, robot_map.py and
// agents/planning.py with their Python names and return conventions.
#include <nanobind/nanobind.h>
#include <nanobind/stl/complex.h>
#include <nanobind/stl/pair.h>

#include <algorithm>
#include <atomic>
#include <complex>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <bearing_core/core/errors.hpp>
#include <bearing_core/env/kernels.hpp>
#include <bearing_core/env/planning.hpp>
#include <bearing_core/env/robot_map.hpp>
#include <bearing_core/env/types.hpp>
#include "bindings/arrays.hpp"
#include "bindings/env_args.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace {

using namespace bearing;
using bindings::Kept;
using bindings::type_error;
using bindings::value_error;
using bindings::view_of;

// ---------------------------------------------------------------------------------------
// Native objects
// ---------------------------------------------------------------------------------------

// A group's inputs (kernels.Inputs): its settings, its map update settings and map
// state, the envs' state; the Python objects behind the views are kept.
struct EnvInputs {
    env::Inputs inputs;
    int64_t num_rows = 0;  // rows of the state (and of the map batch)
    Kept kept;

    EnvInputs(nb::handle settings, nb::handle params, nb::handle maps, nb::handle state) {
        inputs.settings = bindings::settings_of(settings, kept);
        inputs.params = bindings::params_of(params);
        inputs.maps = bindings::map_state_of(maps, kept);
        inputs.state = bindings::batch_state_of(state, kept);
        bindings::check_state_for(inputs.maps, inputs.params);
        const int64_t n = inputs.settings.n, m = inputs.maps.counts.shape[1];
        if (m != n - 2) {
            value_error("maps hold " + std::to_string(m) + " mapped landmarks, settings.n - 2 is " +
                        std::to_string(n - 2));
        }
        if (inputs.state.landmarks.shape[1] < n) {
            value_error("state has " + std::to_string(inputs.state.landmarks.shape[1]) +
                        " landmark slots, settings.n is " + std::to_string(n));
        }
        if (inputs.state.noise_offsets.shape[1] < 2 * n) {
            value_error("state's noise buffers hold fewer than 2 * settings.n values");
        }
        num_rows = inputs.state.n_landmarks.shape[0];
        if (inputs.maps.counts.shape[0] != num_rows) {
            value_error("maps hold " + std::to_string(inputs.maps.counts.shape[0]) +
                        " maps, state has " + std::to_string(num_rows) + " rows");
        }
    }
};

// The rows of a call, checked: in range and (`distinct`) not repeated.
View1<const int64_t> rows_of(nb::handle rows, int64_t num_rows, std::vector<uint8_t>* seen) {
    auto r = view_of<const int64_t, 1>(rows, "rows");
    for (int64_t i = 0; i < r.shape[0]; ++i) {
        if (r[i] < 0 || r[i] >= num_rows) {
            value_error("rows holds " + std::to_string(r[i]) + ", outside [0, " +
                        std::to_string(num_rows) + ")");
        }
    }
    if (seen != nullptr) {
        bool repeated = false;
        for (int64_t i = 0; i < r.shape[0]; ++i) {
            uint8_t& flag = (*seen)[static_cast<size_t>(r[i])];
            repeated = repeated || flag != 0;
            flag = 1;
        }
        for (int64_t i = 0; i < r.shape[0]; ++i) (*seen)[static_cast<size_t>(r[i])] = 0;
        if (repeated) value_error("rows must not repeat a row");
    }
    return r;
}

constexpr const char* REPORT_FIELDS[16] = {"observations",
                                           "rewards",
                                           "terminated",
                                           "truncated",
                                           "frame_changed",
                                           "inconsistent",
                                           "path_length",
                                           "uncertainty",
                                           "path_cost",
                                           "move_cost",
                                           "landmark_area",
                                           "landmark_error",
                                           "landmark_contains_truth",
                                           "total_area",
                                           "robot_error",
                                           "outliers"};
constexpr const char* ENCODED_FIELDS[12] = {"vertices",   "counts",          "areas",
                                            "centroids",  "robot_vertices",  "robot_counts",
                                            "robot_area", "robot_centroid",  "robot_heading",
                                            "n_updates",  "n_frame_changes", "n_inconsistent"};

nb::tuple as_tuple(nb::handle obj, size_t size, const char* name) {
    if (!nb::isinstance<nb::tuple>(obj)) {
        type_error(std::string(name) + " must be a tuple (a namedtuple) of " +
                   std::to_string(size) + " arrays");
    }
    nb::tuple t = nb::borrow<nb::tuple>(obj);
    if (t.size() != size) {
        value_error(std::string(name) + " must hold " + std::to_string(size) + " arrays, not " +
                    std::to_string(t.size()));
    }
    return t;
}

// A Report's views (16 arrays of `rows` rows, -1: any) for the group of `inputs`.
env::Report report_of(nb::handle obj, const env::Inputs& inputs, int64_t rows, Kept& kept) {
    nb::tuple t = as_tuple(obj, 16, "report");
    const int64_t m = inputs.settings.n - 2, size = env::observation_size(inputs.settings);
    env::Report r;
    r.observations = view_of<float, 2>(t[0], "report.observations", {rows, size});
    rows = r.observations.shape[0];
    if (r.observations.shape[1] != size) value_error("report.observations has the wrong size");
    r.rewards = view_of<double, 1>(t[1], "report.rewards", {rows});
    r.terminated = view_of<bool, 1>(t[2], "report.terminated", {rows});
    r.truncated = view_of<bool, 1>(t[3], "report.truncated", {rows});
    r.frame_changed = view_of<bool, 1>(t[4], "report.frame_changed", {rows});
    r.inconsistent = view_of<int64_t, 1>(t[5], "report.inconsistent", {rows});
    r.path_length = view_of<double, 1>(t[6], "report.path_length", {rows});
    r.uncertainty = view_of<double, 1>(t[7], "report.uncertainty", {rows});
    r.path_cost = view_of<double, 1>(t[8], "report.path_cost", {rows});
    r.move_cost = view_of<double, 1>(t[9], "report.move_cost", {rows});
    r.landmark_area = view_of<double, 2>(t[10], "report.landmark_area", {rows, m});
    r.landmark_error = view_of<double, 2>(t[11], "report.landmark_error", {rows, m});
    r.landmark_contains_truth =
        view_of<bool, 2>(t[12], "report.landmark_contains_truth", {rows, m});
    r.total_area = view_of<double, 1>(t[13], "report.total_area", {rows});
    r.robot_error = view_of<double, 1>(t[14], "report.robot_error", {rows});
    r.outliers = view_of<int64_t, 2>(t[15], "report.outliers", {rows, m});
    const std::array<int64_t, 16> firsts{r.observations.shape[0],
                                         r.rewards.shape[0],
                                         r.terminated.shape[0],
                                         r.truncated.shape[0],
                                         r.frame_changed.shape[0],
                                         r.inconsistent.shape[0],
                                         r.path_length.shape[0],
                                         r.uncertainty.shape[0],
                                         r.path_cost.shape[0],
                                         r.move_cost.shape[0],
                                         r.landmark_area.shape[0],
                                         r.landmark_error.shape[0],
                                         r.landmark_contains_truth.shape[0],
                                         r.total_area.shape[0],
                                         r.robot_error.shape[0],
                                         r.outliers.shape[0]};
    const std::array<int64_t, 4> seconds{r.landmark_area.shape[1], r.landmark_error.shape[1],
                                         r.landmark_contains_truth.shape[1], r.outliers.shape[1]};
    for (size_t k = 0; k < firsts.size(); ++k) {
        if (firsts[k] != rows) {
            value_error(std::string("report.") + REPORT_FIELDS[k] + " has " +
                        std::to_string(firsts[k]) + " rows, expected " + std::to_string(rows));
        }
    }
    for (int64_t second : seconds) {
        if (second != m)
            value_error("report's per-landmark arrays must have settings.n - 2 columns");
    }
    for (size_t k = 0; k < 16; ++k) kept.push_back(nb::borrow(t[k]));
    return r;
}

// encode_map's arrays (12, of `rows` rows, -1: any) for the map state of `inputs`.
env::Encoded encoded_of(nb::handle obj, const slam::MapState& maps, int64_t rows, Kept& kept) {
    nb::tuple t = as_tuple(obj, 12, "encoded");
    const int64_t capacity = maps.vertices.shape[2], robot_capacity = maps.robot_vertices.shape[1];
    env::Encoded e;
    e.vertices = view_of<cplx, 3>(t[0], "encoded.vertices", {rows, -1, capacity});
    rows = e.vertices.shape[0];
    const int64_t slots = e.vertices.shape[1];
    if (slots < maps.counts.shape[1]) {
        value_error("encoded.vertices has " + std::to_string(slots) +
                    " landmark slots, the maps map " + std::to_string(maps.counts.shape[1]));
    }
    if (e.vertices.shape[2] != capacity) value_error("encoded.vertices has the wrong capacity");
    e.counts = view_of<int64_t, 2>(t[1], "encoded.counts", {rows, slots});
    e.areas = view_of<double, 2>(t[2], "encoded.areas", {rows, slots});
    e.centroids = view_of<cplx, 2>(t[3], "encoded.centroids", {rows, slots});
    e.robot_vertices = view_of<cplx, 2>(t[4], "encoded.robot_vertices", {rows, robot_capacity});
    e.robot_counts = view_of<int64_t, 1>(t[5], "encoded.robot_counts", {rows});
    e.robot_area = view_of<double, 1>(t[6], "encoded.robot_area", {rows});
    e.robot_centroid = view_of<cplx, 1>(t[7], "encoded.robot_centroid", {rows});
    e.robot_heading = view_of<double, 1>(t[8], "encoded.robot_heading", {rows});
    e.n_updates = view_of<int64_t, 1>(t[9], "encoded.n_updates", {rows});
    e.n_frame_changes = view_of<int64_t, 1>(t[10], "encoded.n_frame_changes", {rows});
    e.n_inconsistent = view_of<int64_t, 1>(t[11], "encoded.n_inconsistent", {rows});
    const std::array<int64_t, 12> firsts{
        e.vertices.shape[0],   e.counts.shape[0],          e.areas.shape[0],
        e.centroids.shape[0],  e.robot_vertices.shape[0],  e.robot_counts.shape[0],
        e.robot_area.shape[0], e.robot_centroid.shape[0],  e.robot_heading.shape[0],
        e.n_updates.shape[0],  e.n_frame_changes.shape[0], e.n_inconsistent.shape[0]};
    for (size_t k = 0; k < firsts.size(); ++k) {
        if (firsts[k] != rows) {
            value_error(std::string("encoded.") + ENCODED_FIELDS[k] + " has " +
                        std::to_string(firsts[k]) + " rows, expected " + std::to_string(rows));
        }
    }
    const bool slots_match = e.counts.shape[1] == slots && e.areas.shape[1] == slots &&
                             e.centroids.shape[1] == slots &&
                             e.robot_vertices.shape[1] == robot_capacity;
    if (!slots_match) value_error("encoded's arrays do not match in shape");
    for (size_t k = 0; k < 12; ++k) kept.push_back(nb::borrow(t[k]));
    return e;
}

// A group's step outputs: a Report's arrays and (optionally) the robot map's encoded
// arrays, of `capacity` rows (a step of len(rows) <= capacity rows writes their first
// len(rows) rows), and the step's per-call buffers, all made once.
struct StepOutputs {
    nb::object inputs_object;  // the EnvInputs these outputs were made for (kept alive)
    const EnvInputs* inputs = nullptr;
    env::Report report;
    env::Encoded encoded;
    bool with_map = false;
    int64_t capacity = 0;
    std::vector<double> start, end;
    std::vector<int64_t> moving, moving_rows, n_bad;
    std::vector<int8_t> frame_status, landmark_status;
    std::vector<uint8_t> seen;  // one flag per state row (rows must not repeat)
    env::StepBuffers buffers;
    std::atomic<bool> busy{false};
    Kept kept;

    StepOutputs(nb::handle inputs_handle, nb::handle report_handle, nb::handle encoded_handle) {
        if (!nb::try_cast(inputs_handle, inputs) || inputs == nullptr) {
            type_error(std::string("inputs must be an EnvInputs, not ") +
                       nb::type_name(inputs_handle.type()).c_str());
        }
        inputs_object = nb::borrow(inputs_handle);
        report = report_of(report_handle, inputs->inputs, -1, kept);
        capacity = report.rewards.shape[0];
        if (!encoded_handle.is_none()) {
            encoded = encoded_of(encoded_handle, inputs->inputs.maps, capacity, kept);
            with_map = true;
        }
        const int64_t n = inputs->inputs.settings.n;
        const auto cap = static_cast<size_t>(capacity);
        start.assign(cap * static_cast<size_t>(n), 0.0);
        end.assign(cap * static_cast<size_t>(n), 0.0);
        moving.assign(cap, 0);
        moving_rows.assign(cap, 0);
        n_bad.assign(cap, 0);
        frame_status.assign(cap, 0);
        landmark_status.assign(cap * static_cast<size_t>(n - 2), 0);
        seen.assign(static_cast<size_t>(inputs->num_rows), 0);
        buffers.start = {start.data(), {capacity, n}};
        buffers.end = {end.data(), {capacity, n}};
        buffers.moving = {moving.data(), {capacity}};
        buffers.moving_rows = {moving_rows.data(), {capacity}};
        buffers.out.frame_status = {frame_status.data(), {capacity}};
        buffers.out.landmark_status = {landmark_status.data(), {capacity, n - 2}};
        buffers.out.n_bad = {n_bad.data(), {capacity}};
    }
};

// The map state the codec reads: an EnvInputs' (no arrays checked again: the cheap form
// for a step's info), or what map_state_of takes (MapState, State tuple, batch).
slam::MapState maps_of(nb::handle obj, Kept& kept) {
    EnvInputs* inputs = nullptr;
    if (nb::try_cast(obj, inputs) && inputs != nullptr) {
        kept.push_back(nb::borrow(obj));
        return inputs->inputs.maps;
    }
    return bindings::map_state_of(obj, kept);
}

// Marks outputs as in use for one call (two threads may not step one group at once).
struct InUse {
    std::atomic<bool>& busy;
    explicit InUse(std::atomic<bool>& flag) : busy(flag) {
        if (busy.exchange(true)) {
            throw std::runtime_error("these StepOutputs are in use by another thread");
        }
    }
    ~InUse() { busy.store(false); }
    InUse(const InUse&) = delete;
    InUse& operator=(const InUse&) = delete;
};

// The rows of a call that writes into outputs (step_rows, report_rows_into), checked:
// outputs made for these inputs, with the encoded arrays when with_map, and room for the
// rows. The caller holds the outputs (InUse) first: the rows' check uses their buffer.
View1<const int64_t> rows_for_outputs(nb::handle rows, const EnvInputs& inputs,
                                      StepOutputs& outputs, bool with_map) {
    if (outputs.inputs != &inputs) {
        value_error("outputs were made for other inputs (StepOutputs(inputs, ...))");
    }
    if (with_map && !outputs.with_map) {
        value_error("with_map needs outputs made with the encoded arrays");
    }
    auto r = rows_of(rows, inputs.num_rows, &outputs.seen);
    if (r.shape[0] > outputs.capacity) {
        value_error("rows has " + std::to_string(r.shape[0]) + " rows, outputs hold " +
                    std::to_string(outputs.capacity));
    }
    return r;
}

// ---------------------------------------------------------------------------------------
// New arrays (the calls that hand out new arrays, as the numba kernels did)
// ---------------------------------------------------------------------------------------

nb::object numpy_call(const char* function, nb::tuple shape, const char* dtype) {
    return nb::module_::import_("numpy").attr(function)(shape, "dtype"_a = dtype);
}
nb::object zeros(nb::tuple shape, const char* dtype = "float64") {
    return numpy_call("zeros", std::move(shape), dtype);
}
nb::object empty(nb::tuple shape, const char* dtype = "float64") {
    return numpy_call("empty", std::move(shape), dtype);
}
nb::object full(nb::tuple shape, nb::object value, const char* dtype) {
    return nb::module_::import_("numpy").attr("full")(shape, value, "dtype"_a = dtype);
}

// kernels._new_report: zero observations and reward parts, no episode end.
nb::tuple new_report_arrays(int64_t size, int64_t n_mapped, int64_t observation_size) {
    const nb::tuple one = nb::make_tuple(size), two = nb::make_tuple(size, n_mapped);
    return nb::make_tuple(zeros(nb::make_tuple(size, observation_size), "float32"), zeros(one),
                          zeros(one, "bool"), zeros(one, "bool"), zeros(one, "bool"),
                          zeros(one, "int64"), zeros(one), zeros(one), zeros(one), zeros(one),
                          empty(two), empty(two), empty(two, "bool"), empty(one), empty(one),
                          empty(two, "int64"));
}

// robot_map.encode_map's new arrays (padding: zeros, inf areas, inf + inf j centroids).
nb::tuple new_encoded_arrays(const slam::MapState& maps, int64_t size, int64_t slots) {
    const int64_t capacity = maps.vertices.shape[2];
    const nb::tuple one = nb::make_tuple(size), two = nb::make_tuple(size, slots);
    const double inf = std::numeric_limits<double>::infinity();
    return nb::make_tuple(zeros(nb::make_tuple(size, slots, capacity), "complex128"),
                          zeros(two, "int64"), full(two, nb::float_(inf), "float64"),
                          full(two, nb::cast(std::complex<double>(inf, inf)), "complex128"),
                          zeros(nb::make_tuple(size, maps.robot_vertices.shape[1]), "complex128"),
                          empty(one, "int64"), empty(one), empty(one, "complex128"), empty(one),
                          empty(one, "int64"), empty(one, "int64"), empty(one, "int64"));
}

// encode_map into new arrays (robot_map.encode_map).
nb::tuple encode_map_new(const slam::MapState& maps, View1<const int64_t> rows, int64_t slots) {
    if (slots < maps.counts.shape[1]) {
        value_error("slots (" + std::to_string(slots) +
                    ") must be at least the mapped landmarks (" +
                    std::to_string(maps.counts.shape[1]) + ")");
    }
    nb::tuple arrays = new_encoded_arrays(maps, rows.shape[0], slots);
    Kept kept;
    const env::Encoded encoded = encoded_of(arrays, maps, rows.shape[0], kept);
    {
        nb::gil_scoped_release release;
        env::encode_map_into(maps, rows, encoded);
    }
    return arrays;
}

template <class T>
int64_t decode_with(nb::handle actions, double lo, double hi, nb::handle turns,
                    nb::handle lengths) {
    auto a = view_of<const T, 2>(actions, "actions", {-1, 2});
    auto t = view_of<double, 1>(turns, "turns", {a.shape[0]});
    auto l = view_of<double, 1>(lengths, "lengths", {a.shape[0]});
    if (a.shape[1] != 2 || t.shape[0] != a.shape[0] || l.shape[0] != a.shape[0]) {
        value_error("actions must be (N, 2), turns and lengths (N,)");
    }
    return env::decode_continuous<T>(a, lo, hi, t, l);
}

}  // namespace

void bind_env(nb::module_& m) {
    // The observation's block sizes and the shape block's limit (observations.py checks its
    // feature names against the blocks, and reads the limit).
    m.attr("ROBOT_BLOCK") = env::ROBOT_FEATURES;
    m.attr("LANDMARK_BLOCK") = env::LANDMARK_FEATURES;
    m.attr("BEARING_BLOCK") = env::BEARING_FEATURES;
    m.attr("SHAPE_BLOCK") = env::SHAPE_FEATURES;
    m.attr("ELONGATION_LIMIT") = env::ELONGATION_LIMIT;
    m.attr("STEP_DONE") = static_cast<int64_t>(env::STEP_DONE);
    m.attr("STEP_NEEDS_NOISE") = static_cast<int64_t>(env::STEP_NEEDS_NOISE);
    m.attr("STEP_NEEDS_TRAJECTORY") = static_cast<int64_t>(env::STEP_NEEDS_TRAJECTORY);
    m.attr("ACTIONS_OK") = static_cast<int64_t>(env::ACTIONS_OK);
    m.attr("ACTIONS_NOT_FINITE") = static_cast<int64_t>(env::ACTIONS_NOT_FINITE);
    m.attr("ACTIONS_OUTSIDE") = static_cast<int64_t>(env::ACTIONS_OUTSIDE);

    nb::class_<EnvInputs>(m, "EnvInputs",
                          "A group's kernel inputs (kernels.Inputs), made once per group and "
                          "state: its Settings, the map update's Params and MapState, the envs' "
                          "BatchState (its arrays, checked and kept).")
        .def(nb::init<nb::handle, nb::handle, nb::handle, nb::handle>(), "settings"_a, "params"_a,
             "maps"_a, "state"_a)
        .def_prop_ro("n", [](const EnvInputs& self) { return self.inputs.settings.n; })
        .def_prop_ro("num_rows", [](const EnvInputs& self) { return self.num_rows; })
        .def_prop_ro("observation_size", [](const EnvInputs& self) {
            return env::observation_size(self.inputs.settings);
        });

    nb::class_<StepOutputs>(m, "StepOutputs",
                            "A group's step outputs, made once: a Report's arrays (any number "
                            "of rows: a step writes the first len(rows)), the robot map's "
                            "encoded arrays (encode_map's, complex views; None without the "
                            "robot_map info) and the step's buffers.")
        .def(nb::init<nb::handle, nb::handle, nb::handle>(), "inputs"_a, "report"_a,
             "encoded"_a = nb::none())
        .def_prop_ro("capacity", [](const StepOutputs& self) { return self.capacity; })
        .def_prop_ro("with_map", [](const StepOutputs& self) { return self.with_map; });

    m.def(
        "step_rows",
        [](nb::handle rows, nb::handle turns, nb::handle lengths, EnvInputs& inputs,
           nb::handle trajectory, int64_t threads, StepOutputs& outputs, bool with_map) {
            InUse in_use(outputs.busy);
            auto r = rows_for_outputs(rows, inputs, outputs, with_map);
            const int64_t size = r.shape[0];
            auto t = view_of<const double, 1>(turns, "turns", {size});
            auto l = view_of<const double, 1>(lengths, "lengths", {size});
            if (t.shape[0] != size || l.shape[0] != size) {
                value_error("turns and lengths must have len(rows) elements");
            }
            auto traj = view_of<double, 3>(trajectory, "trajectory", {inputs.num_rows, -1, 2});
            if (traj.shape[0] != inputs.num_rows) {
                value_error("trajectory must have a row per state row");
            }
            const env::BatchState& state = inputs.inputs.state;
            for (int64_t i = 0; i < size; ++i) {
                if (state.noise_used[r[i]] < 0 || state.trajectory_length[r[i]] < 0) {
                    value_error(
                        "the state's noise_used and trajectory_length must not be negative");
                }
            }
            const env::Encoded* encoded = with_map ? &outputs.encoded : nullptr;
            nb::gil_scoped_release release;
            return static_cast<int64_t>(env::step_rows(r, t, l, inputs.inputs, traj, threads,
                                                       outputs.report, outputs.buffers, encoded));
        },
        "rows"_a, "turns"_a, "lengths"_a, "inputs"_a, "trajectory"_a, "threads"_a, "outputs"_a,
        "with_map"_a,
        "One movement of every row of a group into outputs' first len(rows) rows "
        "(kernels.step_rows, or step_rows_bare without with_map); returns the status "
        "(STEP_DONE, or nothing done: STEP_NEEDS_NOISE, STEP_NEEDS_TRAJECTORY).");

    m.def(
        "new_report",
        [](int64_t size, const EnvInputs& inputs) {
            return new_report_arrays(size, inputs.inputs.settings.n - 2,
                                     env::observation_size(inputs.inputs.settings));
        },
        "size"_a, "inputs"_a,
        "A report's 16 arrays (kernels.Report's order) of size rows for the group of inputs.");
    m.def(
        "report_rows_into",
        [](nb::handle rows, EnvInputs& inputs, StepOutputs& outputs, bool with_map) {
            InUse in_use(outputs.busy);
            auto r = rows_for_outputs(rows, inputs, outputs, with_map);
            const int64_t size = r.shape[0];
            nb::gil_scoped_release release;
            const env::Report views = outputs.report.first(size);
            env::clear_report(views);
            env::observe(r, inputs.inputs, views);
            if (with_map) env::encode_map_into(inputs.inputs.maps, r, outputs.encoded.first(size));
        },
        "rows"_a, "inputs"_a, "outputs"_a, "with_map"_a,
        "report_rows into outputs' first len(rows) rows (a step's reused arrays, as step_rows "
        "writes them): the rows' observations and infos as they stand.");
    m.def(
        "potentials",
        [](nb::handle rows, const EnvInputs& inputs, nb::handle out) {
            auto r = rows_of(rows, inputs.num_rows, nullptr);
            auto o = view_of<double, 1>(out, "out", {r.shape[0]});
            if (o.shape[0] != r.shape[0]) value_error("out must have len(rows) elements");
            env::potentials(r, inputs.inputs, o);
        },
        "rows"_a, "inputs"_a, "out"_a, "The uncertainty potential of each row's map into out.");
    m.def(
        "move_and_read",
        [](int64_t row, double turn, double length, const EnvInputs& inputs,
           nb::handle reading_start, nb::handle reading_end) {
            const env::Inputs& in = inputs.inputs;
            const int64_t n = in.settings.n;
            if (row < 0 || row >= inputs.num_rows) value_error("row is out of range");
            auto s = view_of<double, 1>(reading_start, "reading_start");
            auto e = view_of<double, 1>(reading_end, "reading_end");
            if (s.shape[0] < n || e.shape[0] < n) {
                value_error("reading_start and reading_end must hold settings.n values");
            }
            if (in.state.noise_used[row] < 0) value_error("the row's noise_used is negative");
            check_capacity("noise values of a move", in.state.noise_used[row] + 2 * n,
                           in.state.noise_offsets.shape[1]);
            return env::move_and_read(row, turn, length, in, s.data, e.data);
        },
        "row"_a, "turn"_a, "length"_a, "inputs"_a, "reading_start"_a, "reading_end"_a,
        "Turn, read, move, read again: one row's movement; returns the distance travelled.");
    m.def(
        "append_positions",
        [](nb::handle rows, nb::handle positions, nb::handle trajectory, nb::handle lengths) {
            auto len = view_of<int64_t, 1>(lengths, "lengths");
            const int64_t num_rows = len.shape[0];
            auto r = rows_of(rows, num_rows, nullptr);
            auto p = view_of<const double, 2>(positions, "positions", {num_rows, 2});
            auto t = view_of<double, 3>(trajectory, "trajectory", {num_rows, -1, 2});
            if (p.shape[0] != num_rows || t.shape[0] != num_rows) {
                value_error("positions, trajectory and lengths must have one row per row");
            }
            // A repeated row appends twice: count the appends per row before writing.
            std::vector<int64_t> appended(static_cast<size_t>(num_rows), 0);
            for (int64_t i = 0; i < r.shape[0]; ++i) {
                const int64_t row = r[i];
                if (len[row] < 0) value_error("lengths must not be negative");
                if (len[row] < t.shape[1]) {
                    check_capacity("trajectory positions",
                                   len[row] + ++appended[static_cast<size_t>(row)], t.shape[1]);
                }
            }
            return env::append_positions(r, p, t, len);
        },
        "rows"_a, "positions"_a, "trajectory"_a, "lengths"_a,
        "Append each row's position to its trajectory; False (nothing written) when some "
        "row's trajectory is full.");
    m.def("capped", &env::capped, "area"_a, "floor"_a, "cap"_a);
    m.def(
        "potential_of",
        [](nb::handle areas, int64_t n_mapped, bool log_area, double floor, double cap) {
            auto a = view_of<const double, 1>(areas, "areas");
            if (n_mapped > a.shape[0]) {
                value_error("n_mapped (" + std::to_string(n_mapped) + ") exceeds len(areas) (" +
                            std::to_string(a.shape[0]) + ")");
            }
            return env::potential_of(a.data, n_mapped, log_area, floor, cap);
        },
        "areas"_a, "n_mapped"_a, "log_area"_a, "floor"_a, "cap"_a,
        "The uncertainty potential of one map's landmark areas.");
    m.def(
        "_write_shape",
        [](nb::handle vertices, int64_t count, nb::handle out, int64_t j) {
            auto v = view_of<const cplx, 1>(vertices, "vertices");
            auto o = view_of<float, 1>(out, "out");
            if (count > v.shape[0] || v.shape[0] < 1) {
                value_error("count must be at most len(vertices) (at least 1)");
            }
            if (j < 0 || env::SHAPE_FEATURES * (j + 1) > o.shape[0]) {
                value_error("out has no shape block " + std::to_string(j));
            }
            env::write_shape(v.data, count, o.data, j);
        },
        "vertices"_a, "count"_a, "out"_a, "j"_a,
        "Region j's shape block (SHAPE_FEATURES) into out.");
    m.def(
        "decode_continuous",
        [](nb::handle actions, double lo, double hi, nb::handle turns, nb::handle lengths) {
            nb::ndarray<nb::ro> probe;
            if (nb::try_cast(actions, probe, false) && probe.dtype() == nb::dtype<float>()) {
                return decode_with<float>(actions, lo, hi, turns, lengths);
            }
            return decode_with<double>(actions, lo, hi, turns, lengths);
        },
        "actions"_a, "lo"_a, "hi"_a, "turns"_a, "lengths"_a,
        "Turn angles and move lengths of continuous actions (N, 2) in [-1, 1]^2 (float32 or "
        "float64); returns ACTIONS_OK or why not.");

    // bearing_env/envs/robot_map.py
    m.def(
        "_known",
        [](std::complex<double> value) {
            const cplx k = env::known({value.real(), value.imag()});
            return std::complex<double>(k.re, k.im);
        },
        "value"_a, "A complex point, inf + inf j if unknown (NaN in either part).");
    m.def(
        "encode_map",
        [](nb::handle maps, nb::handle rows, int64_t slots) {
            Kept kept;
            const slam::MapState state = maps_of(maps, kept);
            auto r = rows_of(rows, state.counts.shape[0], nullptr);
            return encode_map_new(state, r, slots);
        },
        "state"_a, "rows"_a, "slots"_a,
        "The arrays every fusion uses, for rows, landmark slots padded to slots; state is a "
        "MapState, a State tuple, an object with State's arrays, or an EnvInputs (its maps).");
    m.def(
        "encode_map_into",
        [](nb::handle maps, nb::handle rows, nb::handle encoded) {
            Kept kept;
            const slam::MapState state = maps_of(maps, kept);
            auto r = rows_of(rows, state.counts.shape[0], nullptr);
            const env::Encoded e = encoded_of(encoded, state, r.shape[0], kept);
            nb::gil_scoped_release release;
            env::encode_map_into(state, r, e);
        },
        "state"_a, "rows"_a, "encoded"_a, "encode_map into its arrays encoded (len(rows) rows).");
    m.def(
        "encode_window",
        [](nb::handle maps, nb::handle rows, int64_t slots) {
            Kept kept;
            const slam::MapState s = maps_of(maps, kept);
            auto r = rows_of(rows, s.counts.shape[0], nullptr);
            const int64_t size = r.shape[0], window = s.window_vertices.shape[1];
            if (slots < s.counts.shape[1])
                value_error("slots must be at least the mapped landmarks");
            nb::tuple arrays = nb::make_tuple(
                zeros(nb::make_tuple(size, window, slots, s.window_vertices.shape[3]),
                      "complex128"),
                zeros(nb::make_tuple(size, window, slots), "int64"),
                zeros(nb::make_tuple(size, window, slots), "bool"),
                empty(nb::make_tuple(size, window), "bool"), empty(nb::make_tuple(size), "int64"),
                empty(nb::make_tuple(size), "int64"),
                zeros(nb::make_tuple(size, slots, s.base_vertices.shape[2]), "complex128"),
                zeros(nb::make_tuple(size, slots), "int64"),
                zeros(nb::make_tuple(size, slots), "int64"),
                zeros(nb::make_tuple(size, slots), "int64"));
            env::Window w;
            w.window_vertices = view_of<cplx, 4>(arrays[0], "window_vertices");
            w.window_counts = view_of<int64_t, 3>(arrays[1], "window_counts");
            w.window_inlier = view_of<bool, 3>(arrays[2], "window_inlier");
            w.window_rejected = view_of<bool, 2>(arrays[3], "window_rejected");
            w.window_length = view_of<int64_t, 1>(arrays[4], "window_length");
            w.window_next = view_of<int64_t, 1>(arrays[5], "window_next");
            w.base_vertices = view_of<cplx, 3>(arrays[6], "base_vertices");
            w.base_counts = view_of<int64_t, 2>(arrays[7], "base_counts");
            w.n_dropped = view_of<int64_t, 2>(arrays[8], "n_dropped");
            w.outliers = view_of<int64_t, 2>(arrays[9], "outliers");
            {
                nb::gil_scoped_release release;
                env::encode_window_into(s, r, w);
            }
            return arrays;
        },
        "state"_a, "rows"_a, "slots"_a,
        "The relaxed fusion's arrays (RELAXED_STATE_ARRAYS), as encode_map.");
    m.def(
        "encode_levels",
        [](nb::handle maps, nb::handle rows, int64_t slots) {
            Kept kept;
            const slam::MapState s = maps_of(maps, kept);
            auto r = rows_of(rows, s.counts.shape[0], nullptr);
            const int64_t size = r.shape[0], levels = s.level_vertices.shape[2];
            const int64_t history = s.history_bearings.shape[1];
            if (slots < s.counts.shape[1])
                value_error("slots must be at least the mapped landmarks");
            nb::tuple arrays = nb::make_tuple(
                zeros(nb::make_tuple(size, slots), "int64"),
                zeros(nb::make_tuple(size, slots, levels, s.level_vertices.shape[3]), "complex128"),
                zeros(nb::make_tuple(size, slots, levels), "int64"),
                zeros(nb::make_tuple(size, slots), "int64"), empty(nb::make_tuple(size), "int64"),
                empty(nb::make_tuple(size)), empty(nb::make_tuple(size), "int64"),
                zeros(nb::make_tuple(size, slots, s.probe_vertices.shape[2]), "complex128"),
                zeros(nb::make_tuple(size, slots), "int64"),
                empty(nb::make_tuple(size, s.history_frame_bearings.shape[1], 2, 2)),
                zeros(nb::make_tuple(size, history, 2, slots)),
                empty(nb::make_tuple(size), "int64"), empty(nb::make_tuple(size), "int64"));
            env::Levels out;
            out.outliers = view_of<int64_t, 2>(arrays[0], "outliers");
            out.level_vertices = view_of<cplx, 4>(arrays[1], "level_vertices");
            out.level_counts = view_of<int64_t, 3>(arrays[2], "level_counts");
            out.n_regions = view_of<int64_t, 2>(arrays[3], "n_regions");
            out.robot_fixed_at = view_of<int64_t, 1>(arrays[4], "robot_fixed_at");
            out.noise_scale = view_of<double, 1>(arrays[5], "noise_scale");
            out.bound_events = view_of<int64_t, 1>(arrays[6], "bound_events");
            out.probe_vertices = view_of<cplx, 3>(arrays[7], "probe_vertices");
            out.probe_counts = view_of<int64_t, 2>(arrays[8], "probe_counts");
            out.history_frame_bearings = view_of<double, 4>(arrays[9], "history_frame_bearings");
            out.history_bearings = view_of<double, 4>(arrays[10], "history_bearings");
            out.history_length = view_of<int64_t, 1>(arrays[11], "history_length");
            out.history_next = view_of<int64_t, 1>(arrays[12], "history_next");
            {
                nb::gil_scoped_release release;
                env::encode_levels_into(s, r, out);
            }
            return arrays;
        },
        "state"_a, "rows"_a, "slots"_a,
        "The robust fusion's arrays (ROBUST_STATE_ARRAYS), as encode_map.");

    // agents/planning.py
    m.def(
        "_potentials_of_rows",
        [](nb::handle rows, bool log_area, double floor, double cap, nb::handle out) {
            auto r = view_of<const double, 2>(rows, "rows");
            auto o = view_of<double, 1>(out, "out", {r.shape[0]});
            if (o.shape[0] != r.shape[0]) value_error("out must have a value per row");
            env::potentials_of_rows(r, log_area, floor, cap, o);
        },
        "rows"_a, "log_area"_a, "floor"_a, "cap"_a, "out"_a,
        "potential_of of every row of areas (rows, m) into out.");
    m.def(
        "_move_ends",
        [](std::complex<double> start, nb::handle headings, nb::handle distances, nb::handle out) {
            auto h = view_of<const double, 1>(headings, "headings");
            auto d = view_of<const double, 1>(distances, "distances", {h.shape[0]});
            auto o = view_of<cplx, 1>(out, "out", {h.shape[0]});
            if (d.shape[0] != h.shape[0] || o.shape[0] != h.shape[0]) {
                value_error("headings, distances and out must have one length");
            }
            env::move_ends({start.real(), start.imag()}, h, d, o);
        },
        "start"_a, "headings"_a, "distances"_a, "out"_a,
        "out[k]: where candidate k ends, start + distances[k] * (cos + i sin)(headings[k]).");
}
