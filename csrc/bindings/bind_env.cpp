// Bindings of the env step (csrc/env/): EnvInputs (a group's long-lived inputs, made once
// where core.py made kernels.inputs_ref), StepOutputs (the library's, over a group's output
// arrays, made once where core._outputs made them), step_rows (the whole step, the GIL
// released) and the other kernels of bearing_env/envs/kernels.py, robot_map.py and
// agents/planning.py with their Python names and return conventions.
#include <nanobind/nanobind.h>
#include <nanobind/stl/map.h>
#include <nanobind/stl/string.h>

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>

#include <bearing_core/env/checked.hpp>
#include <bearing_core/env/kernels.hpp>
#include <bearing_core/env/robot_map.hpp>
#include "bindings/def.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace {

using namespace bearing;
using bindings::def;
using bindings::def_released;
using bindings::Kept;
using bindings::PyMapState;
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
        map_sizes.bind("maps", num_rows, "state.n_landmarks");
        map_sizes.bind("m", inputs.settings.n - 2, "settings.n - 2");
        inputs.maps = bindings::map_state_of(maps, map_sizes, kept);
        env::checked::check_inputs(inputs);
    }
};

// A group's step outputs (the library's StepOutputs) over Python's arrays: a Report's
// (any number of rows) and the robot map's Encoded (None without it), kept alive with the
// group's inputs.
struct PyStepOutputs {
    Kept kept;
    env::checked::StepOutputs outputs;

    PyStepOutputs(nb::handle inputs, nb::handle report, nb::handle encoded)
        : outputs(inputs_of(inputs), read<env::Report>(report, "report"),
                  encoded.is_none() ? std::nullopt
                                    : std::optional(read<env::Encoded>(encoded, "encoded"))) {}

    const env::Inputs& inputs_of(nb::handle obj) {
        EnvInputs* inputs = nullptr;
        if (!nb::try_cast(obj, inputs) || inputs == nullptr) {
            type_error(std::string("inputs must be an EnvInputs, not ") +
                       nb::type_name(obj.type()).c_str());
        }
        kept.push_back(nb::borrow(obj));
        return inputs->inputs;
    }
    template <class Struct>
    Struct read(nb::handle source, const char* label) {
        schema::Sizes sizes = bindings::map_sizes();
        return bindings::read_struct<Struct>(source, label, sizes, kept, false);
    }
};

}  // namespace

namespace bearing::bindings {
// A group's inputs: an EnvInputs'.
template <>
struct Param<env::Inputs> {
    using Args = std::tuple<const EnvInputs&>;
    static const env::Inputs& from(Taken&, size_t, const EnvInputs& s) { return s.inputs; }
};
// A group's step outputs: a StepOutputs binding's.
template <>
struct Param<env::checked::StepOutputs&> {
    using Args = std::tuple<PyStepOutputs&>;
    static env::checked::StepOutputs& from(Taken&, size_t, PyStepOutputs& s) { return s.outputs; }
};
// The planners' structs, each from one Python argument per field.
template <>
struct Param<env::Candidates> : Fields<env::Candidates, cplx, View1<const cplx>,
                                       View1<const double>, View1<const double>, double> {};
template <>
struct Param<env::Scoring> : Fields<env::Scoring, double, double, bool> {};
template <>
struct Param<env::Readings>
    : Fields<env::Readings, View1<const int64_t>, View2<const double>, View2<const double>> {};
}  // namespace bearing::bindings

namespace {

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

// A codec's new arrays (encode_map's, encode_window's, encode_levels'): `rows` of the map
// state `maps` (an EnvInputs or what map_state_of takes), `slots` landmark slots, padded.
template <class Struct, void (*encode)(const slam::MapState&, View1<const int64_t>, const Struct&)>
nb::tuple encode_new(nb::handle maps, nb::handle rows, int64_t slots) {
    Kept kept;
    schema::Sizes sizes;
    const slam::MapState state = maps_of(maps, sizes, kept);
    const auto r = view_of<const int64_t, 1>(rows, "rows");
    env::checked::check_encoding(state, r, slots);
    sizes.bind("maps", r.shape[0], "rows");  // (found first: the new arrays' own axes)
    sizes.bind("m", slots, "slots");
    Struct out;
    nb::tuple arrays = bindings::new_struct(sizes, out);
    if constexpr (std::is_same_v<Struct, env::Encoded>) env::pad_encoded(out);
    nb::gil_scoped_release release;
    encode(state, r, out);
    return arrays;
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
    using env::ActionsStatus;
    using env::StepStatus;
    BEARING_BINDINGS_ENUM(m, StepStatus, BEARING_CORE_STEP_STATUS)
    BEARING_BINDINGS_ENUM(m, ActionsStatus, BEARING_CORE_ACTIONS_STATUS)
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

    nb::class_<PyStepOutputs>(m, "StepOutputs",
                              "A group's step outputs, made once: a Report's arrays (any number "
                              "of rows: a step writes the first len(rows)), the robot map's "
                              "encoded arrays (encode_map's, complex views; None without the "
                              "robot_map info) and the step's buffers.")
        .def(nb::init<nb::handle, nb::handle, nb::handle>(), "inputs"_a, "report"_a,
             "encoded"_a = nb::none())
        .def_prop_ro("capacity", [](const PyStepOutputs& self) { return self.outputs.capacity(); })
        .def_prop_ro("with_map", [](const PyStepOutputs& self) { return self.outputs.with_map(); });

    def_released(m, "step_rows", &env::checked::step_into, "rows"_a, "turns"_a, "lengths"_a,
                 "inputs"_a, "trajectory"_a, "threads"_a, "outputs"_a, "with_map"_a,
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
    def_released(m, "report_rows_into", &env::checked::report_into, "rows"_a, "inputs"_a,
                 "outputs"_a, "with_map"_a,
                 "report_rows into outputs' first len(rows) rows (a step's reused arrays, as "
                 "step_rows writes them): the rows' observations and infos as they stand.");
    def(m, "potentials", &env::checked::potentials, "rows"_a, "inputs"_a, "out"_a,
        "The uncertainty potential of each row's map into out.");
    def(m, "move_and_read", &env::checked::move_and_read, "row"_a, "turn"_a, "length"_a, "inputs"_a,
        "reading_start"_a, "reading_end"_a,
        "Turn, read, move, read again: one row's movement; returns the distance travelled.");
    def(m, "append_positions", &env::checked::append_positions, "rows"_a, "positions"_a,
        "trajectory"_a, "lengths"_a,
        "Append each row's position to its trajectory; False (nothing written) when some "
        "row's trajectory is full.");
    def(m, "capped", &env::capped, "area"_a, "floor"_a, "cap"_a);
    def(m, "potential_of", &env::checked::potential_of, "areas"_a, "n_mapped"_a, "log_area"_a,
        "floor"_a, "cap"_a, "The uncertainty potential of one map's landmark areas.");
    def(m, "_write_shape", &env::checked::write_shape, "vertices"_a, "count"_a, "out"_a, "j"_a,
        "Region j's shape block (SHAPE_FEATURES) into out.");
    def(
        m, "decode_continuous",
        +[](nb::handle actions, double lo, double hi, View1<double> turns,
            View1<double> lengths) -> int64_t {
            nb::ndarray<nb::ro> probe;
            if (nb::try_cast(actions, probe, false) && probe.dtype() == nb::dtype<float>()) {
                return env::checked::decode_continuous(view_of<const float, 2>(actions, "actions"),
                                                       lo, hi, turns, lengths);
            }
            return env::checked::decode_continuous(view_of<const double, 2>(actions, "actions"), lo,
                                                   hi, turns, lengths);
        },
        "actions"_a, "lo"_a, "hi"_a, "turns"_a, "lengths"_a,
        "Turn angles and move lengths of continuous actions (N, 2) in [-1, 1]^2 (float32 or "
        "float64); returns ACTIONS_OK or why not.");

    // bearing_env/envs/robot_map.py
    def(m, "_known", &env::known, "value"_a,
        "A complex point, inf + inf j if unknown (NaN in either part).");
    m.def("encode_map", &encode_new<env::Encoded, env::encode_map_into>, "state"_a, "rows"_a,
          "slots"_a,
          "The arrays every fusion uses (Encoded), for rows, landmark slots padded to slots; "
          "state is a MapState, a State, an object with State's arrays, or an EnvInputs.");
    def(
        m, "encode_map_into",
        +[](nb::handle maps, View1<const int64_t> rows, env::Encoded encoded) {
            Kept kept;
            schema::Sizes sizes;
            const slam::MapState state = maps_of(maps, sizes, kept);
            nb::gil_scoped_release release;
            env::checked::encode_map_into(state, rows, encoded);
        },
        "state"_a, "rows"_a, "encoded"_a, "encode_map into its arrays encoded (len(rows) rows).");
    m.def("encode_window", &encode_new<env::Window, env::encode_window_into>, "state"_a, "rows"_a,
          "slots"_a, "The relaxed fusion's arrays (Window), as encode_map.");
    m.def("encode_levels", &encode_new<env::Levels, env::encode_levels_into>, "state"_a, "rows"_a,
          "slots"_a, "The robust fusion's arrays (Levels), as encode_map.");

    // agents/planning.py
    def(m, "_potentials_of_rows", &env::checked::potentials_of_rows, "rows"_a, "log_area"_a,
        "floor"_a, "cap"_a, "out"_a, "potential_of of every row of areas (rows, m) into out.");
    def(m, "_bearings_of", &env::checked::bearings_of, "differences"_a, "headings"_a, "out"_a,
        "out[k] = wrap(angle(differences[k]) - headings[k]), with libm's atan2.");
    def_released(
        m, "_simulate_potentials", &env::checked::simulate_potentials, "maps"_a, "row"_a,
        "params"_a, "start"_a, "landmarks"_a, "headings"_a, "distances"_a, "min_distance"_a,
        "area_cap"_a, "floor"_a, "log_area"_a, "trials"_a, "out"_a,
        "The potential after each candidate move, simulated on copies of map row in trials' "
        "first maps (agents/planning.py's simulate_potentials without a sensor).");
    def_released(
        m, "_score_readings", &env::checked::score_readings, "maps"_a, "row"_a, "params"_a,
        "moving"_a, "start"_a, "end"_a, "area_cap"_a, "floor"_a, "log_area"_a, "trials"_a, "out"_a,
        "The potential after each candidate into out: moving[i] fused from readings start[i], "
        "end[i] into its own copy of map row (trials' map i); the others the map's own.");
    def_released(
        m, "_score_rows", &env::checked::score_rows, "maps"_a, "rows"_a, "params"_a, "start"_a,
        "end"_a, "area_cap"_a, "floor"_a, "log_area"_a, "trials"_a, "out"_a, "threads"_a = 1,
        "trials' map i: a copy of map rows[i] fused from readings start[i], end[i]; out[i] "
        "its potential (Lookahead's beam expansions).");
    def(m, "_move_ends", &env::checked::move_ends, "start"_a, "headings"_a, "distances"_a, "out"_a,
        "out[k]: where candidate k ends, start + distances[k] * (cos + i sin)(headings[k]).");
}
