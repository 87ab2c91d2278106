// Bindings of the env step (csrc/env/): EnvInputs (a group's long-lived inputs, made once
// where core.py made kernels.inputs_ref), StepOutputs (a group's output arrays and per-call
// buffers, made once where core._outputs made them), step_rows (the whole step, the GIL
// released) and the other kernels of bearing_env/envs/kernels.py, robot_map.py and
// agents/planning.py with their Python names and return conventions.
#include <nanobind/nanobind.h>
#include <nanobind/stl/complex.h>
#include <nanobind/stl/map.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <complex>
#include <limits>
#include <map>
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
#include "bindings/structs.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace {

using namespace bearing;
using bindings::Kept;
using bindings::type_error;
using bindings::value_error;
using bindings::view_of;
namespace schema = bearing::schema;

// A group's inputs (kernels.Inputs): its settings, its map update settings and map
// state, the envs' state; the Python objects behind the views are kept.
struct EnvInputs {
    env::Inputs inputs;
    int64_t num_rows = 0;  // rows of the state (and of the map batch)
    schema::Sizes map_sizes = bindings::map_sizes();
    Kept kept;

    EnvInputs(nb::handle settings, nb::handle params, nb::handle maps, nb::handle state) {
        inputs.settings = bindings::settings_of(settings, kept);
        inputs.params = bindings::params_of(params);
        schema::Sizes sizes;
        inputs.state = bindings::read_struct<env::BatchState>(state, "", sizes, kept, true);
        num_rows = sizes.at("N");
        const int64_t n = inputs.settings.n;
        if (sizes.at("slots") < n || sizes.at("values") < 2 * n) {
            value_error("state has " + std::to_string(sizes.at("slots")) +
                        " landmark slots and noise buffers of " +
                        std::to_string(sizes.at("values")) +
                        " values; settings.n = " + std::to_string(n) + " needs at least n and 2 n");
        }
        map_sizes.bind("maps", num_rows, "state.n_landmarks");
        map_sizes.bind("m", n - 2, "settings.n - 2");
        inputs.maps = bindings::map_state_of(maps, map_sizes, kept);
        bindings::check_state_for(inputs.maps, inputs.params);
    }
};

// The map state the codec reads, and its axes: an EnvInputs' (no arrays checked again:
// the cheap form for a step's info), or what map_state_of takes.
slam::MapState maps_of(nb::handle obj, schema::Sizes& sizes, Kept& kept) {
    EnvInputs* inputs = nullptr;
    if (nb::try_cast(obj, inputs) && inputs != nullptr) {
        kept.push_back(nb::borrow(obj));
        sizes = inputs->map_sizes;
        return inputs->inputs.maps;
    }
    sizes = bindings::map_sizes();
    return bindings::map_state_of(obj, sizes, kept);
}

// encode_map's arrays (`rows` rows, or any if unbound) for a map state of axes
// `map_sizes`: its landmark slots at least the state's mapped landmarks.
env::Encoded encoded_of(nb::handle obj, const schema::Sizes& map_sizes, int64_t rows, Kept& kept) {
    schema::Sizes sizes{{"CAPACITY", slam::CAPACITY}};
    if (rows >= 0) sizes.bind("maps", rows, "rows");
    const auto e = bindings::read_struct<env::Encoded>(obj, "encoded", sizes, kept, false);
    if (sizes.at("m") < map_sizes.at("m")) {
        value_error("encoded.vertices has " + std::to_string(sizes.at("m")) +
                    " landmark slots, the maps map " + std::to_string(map_sizes.at("m")));
    }
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
    env::StepBuffers buffers;
    std::atomic<bool> busy{false};
    Kept kept;

    StepOutputs(nb::handle inputs_handle, nb::handle report_handle, nb::handle encoded_handle) {
        if (!nb::try_cast(inputs_handle, inputs) || inputs == nullptr) {
            type_error(std::string("inputs must be an EnvInputs, not ") +
                       nb::type_name(inputs_handle.type()).c_str());
        }
        inputs_object = nb::borrow(inputs_handle);
        const int64_t n = inputs->inputs.settings.n;
        schema::Sizes sizes{{"m", n - 2}, {"obs", env::observation_size(inputs->inputs.settings)}};
        report = bindings::read_struct<env::Report>(report_handle, "report", sizes, kept, false);
        capacity = sizes.at("rows");
        if (!encoded_handle.is_none()) {
            encoded = encoded_of(encoded_handle, inputs->map_sizes, capacity, kept);
            with_map = true;
        }
        const auto cap = static_cast<size_t>(capacity);
        start.assign(cap * static_cast<size_t>(n), 0.0);
        end.assign(cap * static_cast<size_t>(n), 0.0);
        moving.assign(cap, 0);
        moving_rows.assign(cap, 0);
        n_bad.assign(cap, 0);
        frame_status.assign(cap, 0);
        landmark_status.assign(cap * static_cast<size_t>(n - 2), 0);
        buffers.start = {start.data(), {capacity, n}};
        buffers.end = {end.data(), {capacity, n}};
        buffers.moving = {moving.data(), {capacity}};
        buffers.moving_rows = {moving_rows.data(), {capacity}};
        buffers.out.frame_status = {frame_status.data(), {capacity}};
        buffers.out.landmark_status = {landmark_status.data(), {capacity, n - 2}};
        buffers.out.n_bad = {n_bad.data(), {capacity}};
    }
};

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
// rows, none repeated.
View1<const int64_t> rows_for_outputs(nb::handle rows, const EnvInputs& inputs,
                                      const StepOutputs& outputs, bool with_map) {
    if (outputs.inputs != &inputs) {
        value_error("outputs were made for other inputs (StepOutputs(inputs, ...))");
    }
    if (with_map && !outputs.with_map) {
        value_error("with_map needs outputs made with the encoded arrays");
    }
    auto r = bindings::rows_of(rows, inputs.num_rows, true);
    if (r.shape[0] > outputs.capacity) {
        value_error("rows has " + std::to_string(r.shape[0]) + " rows, outputs hold " +
                    std::to_string(outputs.capacity));
    }
    return r;
}

// encode_map into new arrays (robot_map.encode_map; padding: zeros, inf areas and inf +
// inf j centroids).
nb::tuple encode_map_new(const slam::MapState& maps, const schema::Sizes& map_sizes,
                         View1<const int64_t> rows, int64_t slots) {
    if (slots < map_sizes.at("m")) {
        value_error("slots (" + std::to_string(slots) +
                    ") must be at least the mapped landmarks (" +
                    std::to_string(map_sizes.at("m")) + ")");
    }
    env::Encoded e;
    nb::tuple arrays = bindings::new_struct(
        {{"maps", rows.shape[0]}, {"m", slots}, {"CAPACITY", slam::CAPACITY}}, e);
    const double inf = std::numeric_limits<double>::infinity();
    std::fill_n(e.areas.data, e.areas.size(), inf);
    std::fill_n(e.centroids.data, e.centroids.size(), cplx(inf, inf));
    nb::gil_scoped_release release;
    env::encode_map_into(maps, rows, e);
    return arrays;
}

// A codec's new arrays (encode_window's, encode_levels'): the state's axes, `size` rows
// and `slots` landmark slots.
template <class Struct, class Encode>
nb::tuple encode_new(nb::handle maps, nb::handle rows, int64_t slots, Encode encode) {
    Kept kept;
    schema::Sizes sizes;
    const slam::MapState state = maps_of(maps, sizes, kept);
    auto r = bindings::rows_of(rows, sizes.at("maps"), false);
    if (slots < sizes.at("m")) value_error("slots must be at least the mapped landmarks");
    sizes.bind("maps", r.shape[0], "rows");  // (found first: the new arrays' own axes)
    sizes.bind("m", slots, "slots");
    Struct out;
    nb::tuple arrays = bindings::new_struct(sizes, out);
    nb::gil_scoped_release release;
    encode(state, r, out);
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

#define BEARING_BINDINGS_ENUM_VALUE(member, number) .value(#member, env::member)

void bind_env(nb::module_& m) {
    // The observation's block sizes and the shape block's limit (observations.py checks its
    // feature names against the blocks, and reads the limit).
    m.attr("ROBOT_BLOCK") = env::ROBOT_FEATURES;
    m.attr("LANDMARK_BLOCK") = env::LANDMARK_FEATURES;
    m.attr("BEARING_BLOCK") = env::BEARING_FEATURES;
    m.attr("SHAPE_BLOCK") = env::SHAPE_FEATURES;
    m.attr("ELONGATION_LIMIT") = env::ELONGATION_LIMIT;
    nb::enum_<env::StepStatus>(m, "StepStatus", nb::is_arithmetic())
        BEARING_CORE_STEP_STATUS(BEARING_BINDINGS_ENUM_VALUE)
            .export_values();
    nb::enum_<env::ActionsStatus>(m, "ActionsStatus", nb::is_arithmetic())
        BEARING_CORE_ACTIONS_STATUS(BEARING_BINDINGS_ENUM_VALUE)
            .export_values();
    nb::dict schemas = m.attr("SCHEMAS");
    schemas["Report"] = bindings::array_schema<env::Report>();
    schemas["BatchState"] = bindings::array_schema<env::BatchState>();
    schemas["Encoded"] = bindings::array_schema<env::Encoded>();
    schemas["Window"] = bindings::array_schema<env::Window>();
    schemas["Levels"] = bindings::array_schema<env::Levels>();
    nb::list fields;
    BEARING_CORE_SETTINGS(BEARING_BINDINGS_SETTING_ROW)
    schemas["Settings"] = nb::tuple(fields) + bindings::array_schema<env::Settings>();

    m.def(
        "new_arrays",
        [](const std::string& schema_name, const std::map<std::string, int64_t>& lengths) {
            schema::Sizes sizes{{"CAPACITY", slam::CAPACITY}};
            for (const auto& [axis, length] : lengths) {
                if (axis == "CAPACITY" || length < 0) {
                    value_error("lengths[" + axis + "] = " + std::to_string(length) +
                                ": an axis length is at least 0, and CAPACITY is fixed");
                }
                sizes.bind(axis, length, "");
            }
            slam::MapState state;
            env::BatchState batch;
            env::Report report;
            if (schema_name == "State") return bindings::new_struct(sizes, state);
            if (schema_name == "BatchState") return bindings::new_struct(sizes, batch);
            if (schema_name == "Report") return bindings::new_struct(sizes, report);
            value_error("new_arrays makes State, BatchState or Report arrays, not " + schema_name);
        },
        "schema"_a, "lengths"_a,
        "New zero-filled arrays of a struct of arrays (State, BatchState, Report), in its "
        "fields' order, shaped by its rules (SCHEMAS) and the axes' lengths.");

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
            auto traj = view_of<double, 3>(trajectory, "trajectory", {inputs.num_rows, -1, 2});
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
            env::Report report;
            const env::Settings& settings = inputs.inputs.settings;
            return bindings::new_struct(
                {{"rows", size}, {"m", settings.n - 2}, {"obs", env::observation_size(settings)}},
                report);
        },
        "size"_a, "inputs"_a, "A Report's arrays of size rows for the group of inputs, zeros.");
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
            auto r = bindings::rows_of(rows, inputs.num_rows, false);
            auto o = view_of<double, 1>(out, "out", {r.shape[0]});
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
            auto r = bindings::rows_of(rows, num_rows, false);
            auto p = view_of<const double, 2>(positions, "positions", {num_rows, 2});
            auto t = view_of<double, 3>(trajectory, "trajectory", {num_rows, -1, 2});
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
            schema::Sizes sizes;
            const slam::MapState state = maps_of(maps, sizes, kept);
            return encode_map_new(state, sizes, bindings::rows_of(rows, sizes.at("maps"), false),
                                  slots);
        },
        "state"_a, "rows"_a, "slots"_a,
        "The arrays every fusion uses (Encoded), for rows, landmark slots padded to slots; "
        "state is a MapState, a State, an object with State's arrays, or an EnvInputs.");
    m.def(
        "encode_map_into",
        [](nb::handle maps, nb::handle rows, nb::handle encoded) {
            Kept kept;
            schema::Sizes sizes;
            const slam::MapState state = maps_of(maps, sizes, kept);
            auto r = bindings::rows_of(rows, sizes.at("maps"), false);
            const env::Encoded e = encoded_of(encoded, sizes, r.shape[0], kept);
            nb::gil_scoped_release release;
            env::encode_map_into(state, r, e);
        },
        "state"_a, "rows"_a, "encoded"_a, "encode_map into its arrays encoded (len(rows) rows).");
    m.def(
        "encode_window",
        [](nb::handle maps, nb::handle rows, int64_t slots) {
            return encode_new<env::Window>(maps, rows, slots, env::encode_window_into);
        },
        "state"_a, "rows"_a, "slots"_a, "The relaxed fusion's arrays (Window), as encode_map.");
    m.def(
        "encode_levels",
        [](nb::handle maps, nb::handle rows, int64_t slots) {
            return encode_new<env::Levels>(maps, rows, slots, env::encode_levels_into);
        },
        "state"_a, "rows"_a, "slots"_a, "The robust fusion's arrays (Levels), as encode_map.");

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
        "_bearings_of",
        [](nb::handle differences, nb::handle headings, nb::handle out) {
            auto d = view_of<const cplx, 1>(differences, "differences");
            auto h = view_of<const double, 1>(headings, "headings", {d.shape[0]});
            auto o = view_of<double, 1>(out, "out", {d.shape[0]});
            env::bearings_of(d, h, o);
        },
        "differences"_a, "headings"_a, "out"_a,
        "out[k] = wrap(angle(differences[k]) - headings[k]), with libm's atan2.");
    m.def(
        "_simulate_potentials",
        [](const bindings::PyMapState& maps, int64_t row, const slam::Params& params,
           std::complex<double> start, nb::handle landmarks, nb::handle headings,
           nb::handle distances, double area_cap, double floor, double min_distance, bool log_area,
           const bindings::PyMapState& trials, nb::handle out) {
            if (row < 0 || row >= maps.maps) value_error("row is not a map of maps");
            bindings::require_copyable(maps, trials, "_simulate_potentials");
            bindings::check_state_for(trials.views, params);
            env::Candidates c{{start.real(), start.imag()},
                              view_of<const cplx, 1>(landmarks, "landmarks", {maps.mapped + 2}),
                              view_of<const double, 1>(headings, "headings"),
                              {}};
            const int64_t count = c.headings.shape[0];
            c.distances = view_of<const double, 1>(distances, "distances", {count});
            auto o = view_of<double, 1>(out, "out", {count});
            if (trials.maps < count) value_error("trials must hold a map per candidate");
            nb::gil_scoped_release release;
            env::simulate_potentials(maps.views, row, params, c,
                                     {area_cap, floor, min_distance, log_area}, trials.views, o);
        },
        "maps"_a, "row"_a, "params"_a, "start"_a, "landmarks"_a, "headings"_a, "distances"_a,
        "area_cap"_a, "floor"_a, "min_distance"_a, "log_area"_a, "trials"_a, "out"_a,
        "The potential after each candidate move, simulated on copies of map row in trials' "
        "first maps (agents/planning.py's simulate_potentials without a sensor).");
    m.def(
        "_score_readings",
        [](const bindings::PyMapState& maps, int64_t row, const slam::Params& params,
           nb::handle moving, nb::handle start, nb::handle end, double area_cap, double floor,
           bool log_area, const bindings::PyMapState& trials, nb::handle out) {
            if (row < 0 || row >= maps.maps) value_error("row is not a map of maps");
            bindings::require_copyable(maps, trials, "_score_readings");
            bindings::check_state_for(trials.views, params);
            auto o = view_of<double, 1>(out, "out");
            const env::Readings r{
                bindings::rows_of(moving, o.shape[0], true, "moving"),
                view_of<const double, 2>(start, "start", {bindings::ANY_LENGTH, maps.mapped + 2}),
                view_of<const double, 2>(end, "end", {bindings::ANY_LENGTH, maps.mapped + 2})};
            if (r.start.shape[0] != r.moving.shape[0] || r.end.shape[0] != r.moving.shape[0]) {
                value_error("start and end must have a row per moving candidate");
            }
            if (trials.maps < r.moving.shape[0]) value_error("trials must hold a map per move");
            for (const auto& bearings : {r.start, r.end}) {
                if (std::any_of(bearings.data, bearings.data + bearings.size(),
                                [](double b) { return std::isinf(b); })) {
                    value_error("start and end must be finite bearings or NaN (a missed reading)");
                }
            }
            nb::gil_scoped_release release;
            env::score_readings(maps.views, row, params, r, {area_cap, floor, 0.0, log_area},
                                trials.views, o);
        },
        "maps"_a, "row"_a, "params"_a, "moving"_a, "start"_a, "end"_a, "area_cap"_a, "floor"_a,
        "log_area"_a, "trials"_a, "out"_a,
        "The potential after each candidate into out: moving[i] fused from readings start[i], "
        "end[i] into its own copy of map row (trials' map i); the others the map's own.");
    m.def(
        "_score_rows",
        [](const bindings::PyMapState& maps, nb::handle rows, const slam::Params& params,
           nb::handle start, nb::handle end, double area_cap, double floor, bool log_area,
           const bindings::PyMapState& trials, nb::handle out, int64_t threads) {
            bindings::require_copyable(maps, trials, "_score_rows");
            bindings::check_state_for(trials.views, params);
            auto r = bindings::rows_of(rows, maps.maps, false);
            const int64_t size = r.shape[0], n = maps.mapped + 2;
            auto s = view_of<const double, 2>(start, "start", {size, n});
            auto e = view_of<const double, 2>(end, "end", {size, n});
            auto o = view_of<double, 1>(out, "out", {size});
            if (trials.maps < size) value_error("trials must hold a map per row");
            if (threads < 1) value_error("threads must be at least 1");
            for (const auto& bearings : {s, e}) {
                if (std::any_of(bearings.data, bearings.data + bearings.size(),
                                [](double b) { return std::isinf(b); })) {
                    value_error("start and end must be finite bearings or NaN (a missed reading)");
                }
            }
            nb::gil_scoped_release release;
            env::score_rows(maps.views, r, params, s, e, {area_cap, floor, 0.0, log_area},
                            trials.views, o, threads);
        },
        "maps"_a, "rows"_a, "params"_a, "start"_a, "end"_a, "area_cap"_a, "floor"_a, "log_area"_a,
        "trials"_a, "out"_a, "threads"_a = 1,
        "trials' map i: a copy of map rows[i] fused from readings start[i], end[i]; out[i] "
        "its potential (Lookahead's beam expansions).");
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
