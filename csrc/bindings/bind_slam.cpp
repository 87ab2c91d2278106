// The world model's bindings: the polygon and frame kernels (bind_slam_geometry.cpp), then
// the batched map update (csrc/include/bearing_core/slam/update.hpp): MapState, Params, the
// codes, update_maps, the batch helpers (copy_maps, check_indices, none_infinite,
// contains_points), binomial_q, and the constants the Python side reads.
#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>

#include <cstdint>

#include <bearing_core/slam/checked.hpp>
#include <bearing_core/slam/robust.hpp>
#include <bearing_core/slam/state.hpp>
#include <bearing_core/slam/update.hpp>
#include "bindings/def.hpp"

namespace nb = nanobind;
using namespace nb::literals;
using bearing::bindings::PyMapState;
namespace checked = bearing::slam::checked;
namespace slam = bearing::slam;

#define BEARING_BINDINGS_PARAM(T, name, value, doc) , T name
#define BEARING_BINDINGS_PARAM_SET(T, name, value, doc) p.name = name;
#define BEARING_BINDINGS_PARAM_ARG(T, name, value, doc) , nb::arg(#name) = slam::Params{}.name
#define BEARING_BINDINGS_PARAM_READ(T, name, value, doc) .def_ro(#name, &slam::Params::name, doc)

void bind_slam_geometry(nb::module_& m);

void bind_slam(nb::module_& m) {
    bind_slam_geometry(m);
    using namespace bearing::slam;
    using bearing::bindings::def;
    using bearing::bindings::def_released;
    BEARING_BINDINGS_ENUM(m, FrStatus, BEARING_CORE_FR_STATUS)
    BEARING_BINDINGS_ENUM(m, FrameStatus, BEARING_CORE_FRAME_STATUS)
    BEARING_BINDINGS_ENUM(m, LandmarkStatus, BEARING_CORE_LANDMARK_STATUS)
    BEARING_BINDINGS_ENUM(m, Transfer, BEARING_CORE_TRANSFER)
    BEARING_BINDINGS_ENUM(m, Inconsistency, BEARING_CORE_INCONSISTENCY)
    BEARING_BINDINGS_ENUM(m, Fusion, BEARING_CORE_FUSION)
    BEARING_BINDINGS_ENUM(m, IndexCheck, BEARING_CORE_INDEX_CHECK)

    nb::class_<PyMapState>(m, "MapState",
                           "A batch's state (a State) as the native update takes it: every "
                           "array checked once, kept alive.")
        .def(nb::init<nb::handle>(), "state"_a)
        .def_prop_ro("state", [](const PyMapState& s) { return s.state; })
        .def_prop_ro("num_maps", [](const PyMapState& s) { return s.sizes.at("maps"); })
        .def_prop_ro("n_mapped", [](const PyMapState& s) { return s.sizes.at("m"); })
        .def_prop_ro("window", [](const PyMapState& s) { return s.sizes.at("w"); })
        .def_prop_ro("levels", [](const PyMapState& s) { return s.sizes.at("levels"); })
        .def_prop_ro("history", [](const PyMapState& s) { return s.sizes.at("h"); });

    nb::class_<Params>(m, "Params", "One update call's settings, validated.")
        .def("__init__",
             [](Params* self BEARING_CORE_PARAMS(BEARING_BINDINGS_PARAM)) {
                 Params p;
                 BEARING_CORE_PARAMS(BEARING_BINDINGS_PARAM_SET)
                 validate(p);
                 new (self) Params(p);
             } BEARING_CORE_PARAMS(BEARING_BINDINGS_PARAM_ARG))
            BEARING_CORE_PARAMS(BEARING_BINDINGS_PARAM_READ);

    def_released(m, "update_maps", &checked::update_maps, "bearings_start"_a, "bearings_end"_a,
                 "rows"_a, "params"_a, "state"_a, "out"_a, "threads"_a = 1,
                 "Fuse one movement into each map rows[i] (bearings row i), in place, reporting to "
                 "out (an Outputs); threads > 1 splits the rows into that many blocks.");
    def(m, "copy_maps", &checked::copy_maps, "from_state"_a, "rows"_a, "to_state"_a,
        "Map i of to_state becomes a copy of map rows[i] of from_state (rows may repeat; "
        "same landmarks and fusion arrays).");
    def(m, "check_indices", &checked::check_indices, "indices"_a, "size"_a, "distinct"_a,
        "INDEX_OK, INDEX_OUT_OF_RANGE or INDEX_REPEATED for int64 indices into [0, size).");
    def(m, "none_infinite", &checked::none_infinite, "values"_a,
        "Whether no element of values (float64, 1-D: a C-contiguous array's reshape(-1)) is "
        "+-inf (NaN allowed).");
    def_released(m, "contains_points", &checked::contains_points, "vertices"_a, "counts"_a,
                 "rows"_a, "points"_a, "relative"_a, "out"_a,
                 "out[i, j]: region j of map rows[i] contains points[i, j].");
    def(m, "relaxed_region", &checked::relaxed_region, "state"_a, "row"_a, "j"_a, "slots"_a,
        "use_base"_a, "max_outliers"_a, "out"_a,
        "(n, q): landmark j's q-relaxed region over the window slots, into out[:n].");
    def(m, "update_levels", &checked::update_levels, "state"_a, "row"_a, "j"_a, "fresh"_a,
        "Fuse the region `fresh` into landmark j's robust levels of map `row`.");
    m.def("binomial_q", &binomial_q, "n"_a, "p"_a, "risk"_a, "q_cap"_a,
          "The smallest q (at most q_cap) with P(Bin(n, p) > q) < risk.");

    // The structs' schemas (each declared once in C++): tests/tools/generate_stubs.py
    // writes the typed namedtuples and the stub from them.
    nb::dict schemas = m.attr("SCHEMAS") = nb::dict();
    schemas["State"] = bearing::bindings::array_schema<MapState>();
    schemas["Outputs"] = bearing::bindings::array_schema<Outputs>();
    nb::list fields;
    BEARING_CORE_PARAMS(BEARING_BINDINGS_SETTING_ROW)
    schemas["Params"] = nb::tuple(fields);

    // Constants the Python side reads.
#define BEARING_BINDINGS_CONSTANT(name) m.attr(#name) = name;
    BEARING_CORE_SLAM_CONSTANTS(BEARING_BINDINGS_CONSTANT)
#undef BEARING_BINDINGS_CONSTANT
}
