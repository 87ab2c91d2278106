// Bindings of the batched map update (csrc/include/bearing_core/slam/update.hpp): MapState,
// Params, the codes, update_maps, the batch helpers (copy_maps, check_indices,
// none_infinite, contains_points), binomial_q, and the constants the Python side reads.
#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <bearing_core/slam/fusion.hpp>
#include <bearing_core/slam/robust.hpp>
#include <bearing_core/slam/scratch.hpp>
#include <bearing_core/slam/state.hpp>
#include <bearing_core/slam/update.hpp>
#include "bindings/arrays.hpp"
#include "bindings/state_args.hpp"
#include "bindings/structs.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace bearing::bindings {
template <>
const char* python_type<slam::Transfer>() {
    return "Transfer";
}
template <>
const char* python_type<slam::Inconsistency>() {
    return "Inconsistency";
}
template <>
const char* python_type<slam::Fusion>() {
    return "Fusion";
}
}  // namespace bearing::bindings

namespace {

using bearing::cplx;
using bearing::bindings::value_error;
using bearing::bindings::view_of;
namespace slam = bearing::slam;
namespace schema = bearing::schema;

using bearing::bindings::PyMapState;

void require(bool ok, const std::string& message) {
    if (!ok) value_error(message);
}

void update_maps_binding(nb::handle bearings_start, nb::handle bearings_end, nb::handle rows,
                         const slam::Params& params, const PyMapState& state, nb::handle out,
                         int64_t threads) {
    require(threads >= 1, "threads must be at least 1, not " + std::to_string(threads));
    // Threads write their maps concurrently: a map in two blocks would race.
    auto r = bearing::bindings::rows_of(rows, state.maps, threads > 1);
    const int64_t n_landmarks = state.mapped + 2;
    auto start =
        view_of<const double, 2>(bearings_start, "bearings_start", {r.shape[0], n_landmarks});
    auto end = view_of<const double, 2>(bearings_end, "bearings_end", {r.shape[0], n_landmarks});
    schema::Sizes sizes{{"rows", r.shape[0]}, {"m", state.mapped}};
    bearing::bindings::Kept kept;
    const auto outputs =
        bearing::bindings::read_struct<slam::Outputs>(out, "out", sizes, kept, false);
    bearing::bindings::check_state_for(state.views, params);
    nb::gil_scoped_release release;
    slam::update_maps(start, end, r, params, state.views, outputs, threads);
}

void copy_maps_binding(const PyMapState& from, nb::handle rows, const PyMapState& to) {
    bearing::bindings::require_copyable(from, to, "copy_maps");
    auto r = bearing::bindings::rows_of(rows, from.maps, false);
    require(r.shape[0] <= to.maps, "rows has " + std::to_string(r.shape[0]) +
                                       " entries, more than to's " + std::to_string(to.maps) +
                                       " maps");
    slam::copy_maps(from.views, r, to.views);
}

int64_t check_indices_binding(nb::handle indices, int64_t size, bool distinct) {
    auto view = view_of<const int64_t, 1>(indices, "indices");
    if (distinct && size < 0) value_error("size must not be negative, got " + std::to_string(size));
    const int64_t n = view.shape[0];
    if (!distinct) return slam::check_indices(view.data, n, size, false, nullptr);
    // The kernel's table of seen indices needs a slot per index in range only up to the
    // largest one given, not `size` slots (a huge size would allocate and clear that
    // much): with `limit` for `size`, an index is in range exactly when it was before.
    int64_t limit = 0;
    for (int64_t k = 0; k < n; ++k) {
        if (view(k) >= 0 && view(k) < size) limit = std::max(limit, view(k) + 1);
    }
    constexpr int64_t MAX_TABLE = int64_t{1} << 20;
    if (limit <= MAX_TABLE) {
        std::unique_ptr<bool[]> seen(new bool[static_cast<size_t>(limit)]);
        return slam::check_indices(view.data, n, limit, true, seen.get());
    }
    // Sparse large indices: the kernel's answer (the first problem in order) from a sorted
    // copy of the indices before the first one out of range.
    int64_t stop = 0;
    while (stop < n && view(stop) >= 0 && view(stop) < size) ++stop;
    std::vector<int64_t> sorted(view.data, view.data + stop);
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
        return slam::INDEX_REPEATED;
    }
    return stop < n ? slam::INDEX_OUT_OF_RANGE : slam::INDEX_OK;
}

bool none_infinite_binding(nb::handle values) {
    nb::ndarray<nb::numpy, nb::ro> array;  // read-only arrays too: it only reads them
    if (!nb::try_cast(values, array, false)) {
        bearing::bindings::type_error(std::string("values must be a numpy array, not ") +
                                      nb::type_name(values.type()).c_str());
    }
    if (array.dtype() != nb::dtype<double>()) {
        bearing::bindings::type_error("values must have dtype float64");
    }
    const size_t ndim = array.ndim();
    const auto* data = static_cast<const double*>(array.data());
    if (array.size() == 0) return true;
    // Any strides (numba's ravel() takes any layout): an odometer over the indices.
    std::vector<int64_t> index(ndim, 0);
    while (true) {
        int64_t offset = 0;
        for (size_t d = 0; d < ndim; ++d) offset += index[d] * array.stride(d);
        if (std::isinf(data[offset])) return false;
        size_t d = ndim;
        while (d > 0) {
            --d;
            if (++index[d] < static_cast<int64_t>(array.shape(d))) break;
            index[d] = 0;
            if (d == 0) return true;
        }
        if (ndim == 0) return true;
    }
}

void contains_points_binding(nb::handle vertices, nb::handle counts, nb::handle rows,
                             nb::handle points, double relative, nb::handle out) {
    auto v = view_of<const cplx, 3>(vertices, "vertices");
    auto c = view_of<const int64_t, 2>(counts, "counts", {v.shape[0], v.shape[1]});
    auto r = view_of<const int64_t, 1>(rows, "rows");
    auto p = view_of<const cplx, 2>(points, "points", {r.shape[0], c.shape[1]});
    auto o = view_of<bool, 2>(out, "out", {p.shape[0], p.shape[1]});
    bearing::bindings::require_apart(
        {bearing::bindings::extent_of(v, "vertices"), bearing::bindings::extent_of(c, "counts"),
         bearing::bindings::extent_of(r, "rows"), bearing::bindings::extent_of(p, "points"),
         bearing::bindings::extent_of(o, "out")});
    for (int64_t i = 0; i < r.shape[0]; ++i) {
        if (r(i) < 0 || r(i) >= v.shape[0]) {
            value_error("rows must be map indices in [0, " + std::to_string(v.shape[0]) +
                        "), got " + std::to_string(r(i)));
        }
        for (int64_t j = 0; j < c.shape[1]; ++j) {
            if (c(r(i), j) > v.shape[2]) {
                value_error("counts must not exceed vertices' last axis (" +
                            std::to_string(v.shape[2]) + "), got " + std::to_string(c(r(i), j)));
            }
        }
    }
    nb::gil_scoped_release release;
    slam::contains_points(v, c, r, p, relative, o);
}

// A vertex count the kernels read a region of the state with (from an array a user can
// write, as the update's own check of a map does): within the region's `slots`.
void check_region_count(int64_t n, int64_t slots, const char* name) {
    if (n < 0 || n > slots) {
        value_error(std::string("state.") + name + " holds " + std::to_string(n) +
                    ", outside [0, " + std::to_string(slots) + "]: a corrupt state");
    }
}

// The relaxed fusion's region of landmark j of map `row` over the window slots `slots`
// (int64, k of them), with the bases if use_base: (n, q), the region in out[:n]
// (bearing_env.slam.geometry.relaxed_intersection's kernel; not the per-step path).
nb::tuple relaxed_region_binding(const PyMapState& s, int64_t row, int64_t j, nb::handle slots,
                                 bool use_base, int64_t max_outliers, nb::handle out) {
    auto k_slots = bearing::bindings::view_of<const int64_t, 1>(slots, "slots");
    auto o = bearing::bindings::view_of<cplx, 1>(out, "out");
    require(0 <= row && row < s.maps,
            "row must be a map index in [0, " + std::to_string(s.maps) + ")");
    require(0 <= j && j < s.mapped,
            "j must be a landmark slot in [0, " + std::to_string(s.mapped) + ")");
    require(1 <= k_slots.shape[0] && k_slots.shape[0] <= s.sizes.at("w"),
            "slots must hold 1.." + std::to_string(s.sizes.at("w")) + " window slots");
    for (int64_t i = 0; i < k_slots.shape[0]; ++i) {
        require(0 <= k_slots(i) && k_slots(i) < s.sizes.at("w"), "slots must index the window");
    }
    require(0 <= max_outliers && max_outliers < slam::MAX_WINDOW, "max_outliers out of range");
    require(o.shape[0] >= slam::SCRATCH, "out must hold SCRATCH points");
    for (int64_t i = 0; i < k_slots.shape[0]; ++i) {
        check_region_count(s.views.window_counts(row, k_slots(i), j),
                           s.views.window_vertices.shape[3], "window_counts");
    }
    if (use_base) {
        check_region_count(s.views.base_counts(row, j), s.views.base_vertices.shape[2],
                           "base_counts");
    }
    slam::Scratch& scratch = slam::thread_buffers().scratch;  // reused, not zeroed per call
    for (int64_t i = 0; i < k_slots.shape[0]; ++i) scratch.slots[i] = k_slots(i);
    auto [n, q] =
        slam::relaxed_region(s.views, row, j, k_slots.shape[0], use_base, max_outliers, scratch);
    for (int64_t v = 0; v < n; ++v) o(v) = scratch.acc[v];
    return nb::make_tuple(n, q);
}

// Fuse the region `fresh` (complex128, 3..CAPACITY vertices) into landmark j's robust
// levels of map `row` (bearing_env.slam.geometry.robust_levels' kernel).
void update_levels_binding(const PyMapState& s, int64_t row, int64_t j, nb::handle fresh) {
    auto f = bearing::bindings::view_of<const cplx, 1>(fresh, "fresh");
    require(0 <= row && row < s.maps,
            "row must be a map index in [0, " + std::to_string(s.maps) + ")");
    require(0 <= j && j < s.mapped,
            "j must be a landmark slot in [0, " + std::to_string(s.mapped) + ")");
    require(s.sizes.at("levels") > 0, "the state has no robust levels (fusion must be 'robust')");
    require(3 <= f.shape[0] && f.shape[0] <= slam::CAPACITY,
            "fresh must have 3.." + std::to_string(slam::CAPACITY) + " vertices");
    require(s.views.n_regions(row, j) >= 0, "state.n_regions is negative: a corrupt state");
    for (int64_t k = 0; k < s.sizes.at("levels"); ++k) {
        check_region_count(s.views.level_counts(row, j, k), s.views.level_vertices.shape[3],
                           "level_counts");
    }
    slam::Scratch& scratch = slam::thread_buffers().scratch;  // reused, not zeroed per call
    for (int64_t v = 0; v < f.shape[0]; ++v) scratch.fresh[v] = f(v);
    slam::update_levels(s.views, row, j, f.shape[0], scratch);
}

}  // namespace

#define BEARING_BINDINGS_ENUM_VALUE(member, number) .value(#member, member)
#define BEARING_BINDINGS_PARAM(T, name, value, doc) , T name
#define BEARING_BINDINGS_PARAM_SET(T, name, value, doc) p.name = name;
#define BEARING_BINDINGS_PARAM_ARG(T, name, value, doc) , nb::arg(#name) = slam::Params{}.name
#define BEARING_BINDINGS_PARAM_READ(T, name, value, doc) .def_ro(#name, &slam::Params::name, doc)

void bind_slam_update(nb::module_& m) {
    using namespace bearing::slam;
    nb::enum_<FrStatus>(m, "FrStatus", nb::is_arithmetic())
        BEARING_CORE_FR_STATUS(BEARING_BINDINGS_ENUM_VALUE)
            .export_values();
    nb::enum_<FrameStatus>(m, "FrameStatus", nb::is_arithmetic())
        BEARING_CORE_FRAME_STATUS(BEARING_BINDINGS_ENUM_VALUE)
            .export_values();
    nb::enum_<LandmarkStatus>(m, "LandmarkStatus", nb::is_arithmetic())
        BEARING_CORE_LANDMARK_STATUS(BEARING_BINDINGS_ENUM_VALUE)
            .export_values();
    nb::enum_<Transfer>(m, "Transfer", nb::is_arithmetic())
        BEARING_CORE_TRANSFER(BEARING_BINDINGS_ENUM_VALUE)
            .export_values();
    nb::enum_<Inconsistency>(m, "Inconsistency", nb::is_arithmetic())
        BEARING_CORE_INCONSISTENCY(BEARING_BINDINGS_ENUM_VALUE)
            .export_values();
    nb::enum_<Fusion>(m, "Fusion", nb::is_arithmetic())
        BEARING_CORE_FUSION(BEARING_BINDINGS_ENUM_VALUE)
            .export_values();
    nb::enum_<IndexCheck>(m, "IndexCheck", nb::is_arithmetic())
        BEARING_CORE_INDEX_CHECK(BEARING_BINDINGS_ENUM_VALUE)
            .export_values();

    nb::class_<PyMapState>(m, "MapState",
                           "A batch's state (a State) as the native update takes it: every "
                           "array checked once, kept alive.")
        .def(nb::init<nb::handle>(), "state"_a)
        .def_prop_ro("state", [](const PyMapState& s) { return s.state; })
        .def_prop_ro("num_maps", [](const PyMapState& s) { return s.maps; })
        .def_prop_ro("n_mapped", [](const PyMapState& s) { return s.mapped; })
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

    m.def("update_maps", &update_maps_binding, "bearings_start"_a, "bearings_end"_a, "rows"_a,
          "params"_a, "state"_a, "out"_a, "threads"_a = 1,
          "Fuse one movement into each map rows[i] (bearings row i), in place, reporting to "
          "out (an Outputs); threads > 1 splits the rows into that many blocks.");
    m.def("copy_maps", &copy_maps_binding, "from_state"_a, "rows"_a, "to_state"_a,
          "Map i of to_state becomes a copy of map rows[i] of from_state (rows may repeat; "
          "same landmarks and fusion arrays).");
    m.def("check_indices", &check_indices_binding, "indices"_a, "size"_a, "distinct"_a,
          "INDEX_OK, INDEX_OUT_OF_RANGE or INDEX_REPEATED for int64 indices into [0, size).");
    m.def("none_infinite", &none_infinite_binding, "values"_a,
          "Whether no element of a float64 array is +-inf (NaN allowed).");
    m.def("contains_points", &contains_points_binding, "vertices"_a, "counts"_a, "rows"_a,
          "points"_a, "relative"_a, "out"_a,
          "out[i, j]: region j of map rows[i] contains points[i, j].");
    m.def("relaxed_region", &relaxed_region_binding, "state"_a, "row"_a, "j"_a, "slots"_a,
          "use_base"_a, "max_outliers"_a, "out"_a,
          "(n, q): landmark j's q-relaxed region over the window slots, into out[:n].");
    m.def("update_levels", &update_levels_binding, "state"_a, "row"_a, "j"_a, "fresh"_a,
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
    BEARING_BINDINGS_CONSTANT(CAPACITY)
    BEARING_BINDINGS_CONSTANT(MAX_EDGE_SAMPLES)
    BEARING_BINDINGS_CONSTANT(FR_VERTICES)
    BEARING_BINDINGS_CONSTANT(MAX_SAMPLES)
    BEARING_BINDINGS_CONSTANT(MAX_PAIRS)
    BEARING_BINDINGS_CONSTANT(SCRATCH)
    BEARING_BINDINGS_CONSTANT(MAX_CLOUD)
    BEARING_BINDINGS_CONSTANT(MAX_FR_EXTENT)
    BEARING_BINDINGS_CONSTANT(RELATIVE_TOLERANCE)
    BEARING_BINDINGS_CONSTANT(MAX_WINDOW)
    BEARING_BINDINGS_CONSTANT(PARALLEL_MIN_MAPS)
    BEARING_BINDINGS_CONSTANT(MAX_LANDMARKS)
    BEARING_BINDINGS_CONSTANT(ROBUST_LEVELS)
    BEARING_BINDINGS_CONSTANT(HISTORY)
    BEARING_BINDINGS_CONSTANT(PROBE_SHRINK)
    BEARING_BINDINGS_CONSTANT(BOUND_GROWTH)
    BEARING_BINDINGS_CONSTANT(MAX_NOISE_SCALE)
    BEARING_BINDINGS_CONSTANT(MAX_BOUND)
    BEARING_BINDINGS_CONSTANT(PRIOR_CONTRADICTIONS)
    BEARING_BINDINGS_CONSTANT(PRIOR_REGIONS)
    BEARING_BINDINGS_CONSTANT(UNSEEN_FACTOR)
#undef BEARING_BINDINGS_CONSTANT
}
