// Bindings of the batched map update (csrc/include/bearing_core/slam/update.hpp): MapState, Params,
// update_maps, the batch helpers (check_indices, none_infinite, contains_points),
// binomial_q, and the constants the Python side reads.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <bearing_core/core/errors.hpp>
#include <bearing_core/slam/fusion.hpp>
#include <bearing_core/slam/map_batch.hpp>
#include <bearing_core/slam/robust.hpp>
#include <bearing_core/slam/scratch.hpp>
#include <bearing_core/slam/state.hpp>
#include <bearing_core/slam/update.hpp>
#include "bindings/arrays.hpp"
#include "bindings/state_args.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace {

using bearing::cplx;
using bearing::bindings::value_error;
using bearing::bindings::view_of;
namespace slam = bearing::slam;

using bearing::bindings::N_STATE_FIELDS;
using bearing::bindings::STATE_FIELDS;

// A batch's state as the native update takes it: checked views of the 34 arrays of a
// bearing_env.slam.kernels.State, and a reference to the tuple (the arrays stay alive).
struct PyMapState {
    nb::object tuple;
    slam::MapState views;
    int64_t maps = 0;
    int64_t mapped = 0;  // m: landmarks mapped per map (L1 and L2 excluded)
    int64_t window = 0;  // w
    int64_t levels = 0;
    int64_t history = 0;  // h
};

void require(bool ok, const std::string& message) {
    if (!ok) value_error(message);
}

void init_map_state(PyMapState* self, nb::handle state) {
    if (!nb::isinstance<nb::tuple>(state)) {
        bearing::bindings::type_error(std::string("state must be a bearing_env.slam.kernels.State "
                                                  "tuple, not ") +
                                      nb::type_name(state.type()).c_str());
    }
    const size_t size = nb::len(state);
    if (size != N_STATE_FIELDS) {
        value_error("state must have the " + std::to_string(N_STATE_FIELDS) +
                    " fields of bearing_env.slam.kernels.State, not " + std::to_string(size));
    }
    // Field names, when the tuple has them (a State namedtuple): in State's order.
    if (nb::hasattr(state, "_fields")) {
        nb::tuple names = nb::cast<nb::tuple>(state.attr("_fields"));
        for (size_t k = 0; k < N_STATE_FIELDS; ++k) {
            if (nb::cast<std::string>(names[k]) != STATE_FIELDS[k]) {
                value_error(std::string("state field ") + std::to_string(k) + " must be " +
                            STATE_FIELDS[k] + ", not " + nb::cast<std::string>(names[k]));
            }
        }
    }
    bearing::bindings::Kept kept;  // (the tuple keeps its arrays alive)
    const auto parsed = bearing::bindings::parse_map_state(state, true, "state", kept);
    new (self) PyMapState{nb::borrow<nb::object>(state),
                          parsed.views,
                          parsed.maps,
                          parsed.mapped,
                          parsed.window,
                          parsed.levels,
                          parsed.history};
}

// One update call's settings (bearing_env.slam.kernels.Params), validated by the
// library (slam::validate: std::invalid_argument, a ValueError in Python).
slam::Params make_params(double epsilon, int64_t transfer, int64_t edge_samples,
                         int64_t on_inconsistency, int64_t fusion, int64_t max_outliers,
                         bool with_robot, double risk, bool likely, bool estimate_bound) {
    slam::Params p;
    p.epsilon = epsilon;
    p.transfer = transfer;
    p.edge_samples = edge_samples;
    p.on_inconsistency = on_inconsistency;
    p.fusion = fusion;
    p.max_outliers = max_outliers;
    p.with_robot = with_robot;
    p.risk = risk;
    p.likely = likely;
    p.estimate_bound = estimate_bound;
    slam::validate(p);
    return p;
}

void update_maps_binding(nb::handle bearings_start, nb::handle bearings_end, nb::handle rows,
                         const slam::Params& params, const PyMapState& state, nb::handle out,
                         int64_t threads) {
    const int64_t m = state.mapped;
    const int64_t n_landmarks = m + 2;
    auto rows_view = view_of<const int64_t, 1>(rows, "rows");
    const int64_t n_rows = rows_view.shape[0];
    auto start = view_of<const double, 2>(bearings_start, "bearings_start", {n_rows, n_landmarks});
    auto end = view_of<const double, 2>(bearings_end, "bearings_end", {n_rows, n_landmarks});
    if (!nb::isinstance<nb::tuple>(out) || nb::len(out) != 3) {
        bearing::bindings::type_error(
            "out must be a bearing_env.slam.kernels.Outputs tuple "
            "(frame_status, landmark_status, n_bad)");
    }
    slam::Outputs outputs;
    outputs.frame_status = view_of<int8_t, 1>(out[0], "out.frame_status", {n_rows});
    outputs.landmark_status = view_of<int8_t, 2>(out[1], "out.landmark_status", {n_rows, m});
    outputs.n_bad = view_of<int64_t, 1>(out[2], "out.n_bad", {n_rows});
    require(outputs.frame_status.shape[0] == n_rows && outputs.landmark_status.shape[0] == n_rows &&
                outputs.landmark_status.shape[1] == m && outputs.n_bad.shape[0] == n_rows,
            "out's arrays must have one row per entry of rows (" + std::to_string(n_rows) +
                ") and out.landmark_status one column per mapped landmark (" + std::to_string(m) +
                ")");
    require(threads >= 1, "threads must be at least 1, not " + std::to_string(threads));
    bearing::bindings::check_state_for(state.views, params);
    for (int64_t i = 0; i < n_rows; ++i) {
        const int64_t row = rows_view(i);
        if (row < 0 || row >= state.maps) {
            value_error("rows must be map indices in [0, " + std::to_string(state.maps) +
                        "), got " + std::to_string(row) + " at position " + std::to_string(i));
        }
    }
    if (threads > 1 && n_rows > 1) {
        // Threads write their maps concurrently: a map in two blocks would race.
        std::vector<bool> seen(static_cast<size_t>(state.maps), false);
        for (int64_t i = 0; i < n_rows; ++i) {
            const auto row = static_cast<size_t>(rows_view(i));
            if (seen[row]) {
                value_error("rows must not repeat a map when threads > 1, got map " +
                            std::to_string(row) + " twice");
            }
            seen[row] = true;
        }
    }
    nb::gil_scoped_release release;
    slam::update_maps(start, end, rows_view, params, state.views, outputs, threads);
}

void copy_maps_binding(const PyMapState& from, nb::handle rows, const PyMapState& to) {
    require(from.views.vertices.data != to.views.vertices.data,
            "copy_maps needs two different states (from_state and to_state)");
    require(from.mapped == to.mapped && from.window == to.window && from.levels == to.levels &&
                from.history == to.history &&
                from.views.base_vertices.shape[2] == to.views.base_vertices.shape[2] &&
                from.views.probe_vertices.shape[2] == to.views.probe_vertices.shape[2],
            "copy_maps needs states of the same landmarks and fusion arrays: from has " +
                std::to_string(from.mapped) + " mapped landmarks, to " + std::to_string(to.mapped));
    auto rows_view = view_of<const int64_t, 1>(rows, "rows");
    require(rows_view.shape[0] <= to.maps, "rows has " + std::to_string(rows_view.shape[0]) +
                                               " entries, more than to's " +
                                               std::to_string(to.maps) + " maps");
    for (int64_t i = 0; i < rows_view.shape[0]; ++i) {
        if (rows_view(i) < 0 || rows_view(i) >= from.maps) {
            value_error("rows must be map indices in [0, " + std::to_string(from.maps) + "), got " +
                        std::to_string(rows_view(i)) + " at position " + std::to_string(i));
        }
    }
    slam::copy_maps(from.views, rows_view, to.views);
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
    require(1 <= k_slots.shape[0] && k_slots.shape[0] <= s.window,
            "slots must hold 1.." + std::to_string(s.window) + " window slots");
    for (int64_t i = 0; i < k_slots.shape[0]; ++i) {
        require(0 <= k_slots(i) && k_slots(i) < s.window, "slots must index the window");
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
    require(s.levels > 0, "the state has no robust levels (fusion must be 'robust')");
    require(3 <= f.shape[0] && f.shape[0] <= slam::CAPACITY,
            "fresh must have 3.." + std::to_string(slam::CAPACITY) + " vertices");
    require(s.views.n_regions(row, j) >= 0, "state.n_regions is negative: a corrupt state");
    for (int64_t k = 0; k < s.levels; ++k) {
        check_region_count(s.views.level_counts(row, j, k), s.views.level_vertices.shape[3],
                           "level_counts");
    }
    slam::Scratch& scratch = slam::thread_buffers().scratch;  // reused, not zeroed per call
    for (int64_t v = 0; v < f.shape[0]; ++v) scratch.fresh[v] = f(v);
    slam::update_levels(s.views, row, j, f.shape[0], scratch);
}

}  // namespace

void bind_slam_update(nb::module_& m) {
    nb::class_<PyMapState>(m, "MapState",
                           "A batch's state (a bearing_env.slam.kernels.State of 34 arrays) as "
                           "the native update takes it: every array checked once, kept alive.")
        .def("__init__", &init_map_state, "state"_a)
        .def_prop_ro("state", [](const PyMapState& s) { return s.tuple; })
        .def_prop_ro("num_maps", [](const PyMapState& s) { return s.maps; })
        .def_prop_ro("n_mapped", [](const PyMapState& s) { return s.mapped; })
        .def_prop_ro("window", [](const PyMapState& s) { return s.window; })
        .def_prop_ro("levels", [](const PyMapState& s) { return s.levels; })
        .def_prop_ro("history", [](const PyMapState& s) { return s.history; });

    nb::class_<slam::Params>(m, "Params", "One update call's settings, validated.")
        .def(
            "__init__",
            [](slam::Params* self, double epsilon, int64_t transfer, int64_t edge_samples,
               int64_t on_inconsistency, int64_t fusion, int64_t max_outliers, bool with_robot,
               double risk, bool likely, bool estimate_bound) {
                new (self) slam::Params(make_params(epsilon, transfer, edge_samples,
                                                    on_inconsistency, fusion, max_outliers,
                                                    with_robot, risk, likely, estimate_bound));
            },
            "epsilon"_a, "transfer"_a, "edge_samples"_a, "on_inconsistency"_a, "fusion"_a,
            "max_outliers"_a, "with_robot"_a, "risk"_a, "likely"_a, "estimate_bound"_a)
        .def_ro("epsilon", &slam::Params::epsilon)
        .def_ro("transfer", &slam::Params::transfer)
        .def_ro("edge_samples", &slam::Params::edge_samples)
        .def_ro("on_inconsistency", &slam::Params::on_inconsistency)
        .def_ro("fusion", &slam::Params::fusion)
        .def_ro("max_outliers", &slam::Params::max_outliers)
        .def_ro("with_robot", &slam::Params::with_robot)
        .def_ro("risk", &slam::Params::risk)
        .def_ro("likely", &slam::Params::likely)
        .def_ro("estimate_bound", &slam::Params::estimate_bound);

    m.def("update_maps", &update_maps_binding, "bearings_start"_a, "bearings_end"_a, "rows"_a,
          "params"_a, "state"_a, "out"_a, "threads"_a = 1,
          "Fuse one movement into each map rows[i] (bearings row i), in place, reporting to "
          "out (an Outputs tuple); threads > 1 splits the rows into that many blocks.");
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
    m.def("binomial_q", &slam::binomial_q, "n"_a, "p"_a, "risk"_a, "q_cap"_a,
          "The smallest q (at most q_cap) with P(Bin(n, p) > q) < risk.");

    // Constants the Python side reads.
    m.attr("CAPACITY") = slam::CAPACITY;
    m.attr("MAX_EDGE_SAMPLES") = slam::MAX_EDGE_SAMPLES;
    m.attr("FR_VERTICES") = slam::FR_VERTICES;
    m.attr("MAX_SAMPLES") = slam::MAX_SAMPLES;
    m.attr("MAX_PAIRS") = slam::MAX_PAIRS;
    m.attr("SCRATCH") = slam::SCRATCH;
    m.attr("MAX_CLOUD") = slam::MAX_CLOUD;
    m.attr("MAX_FR_EXTENT") = slam::MAX_FR_EXTENT;
    m.attr("RELATIVE_TOLERANCE") = slam::RELATIVE_TOLERANCE;
    m.attr("MAX_WINDOW") = slam::MAX_WINDOW;
    m.attr("PARALLEL_MIN_MAPS") = slam::PARALLEL_MIN_MAPS;
    m.attr("MAX_LANDMARKS") = slam::MAX_LANDMARKS;
    m.attr("ROBUST_LEVELS") = slam::ROBUST_LEVELS;
    m.attr("HISTORY") = slam::HISTORY;
    m.attr("PROBE_SHRINK") = slam::PROBE_SHRINK;
    m.attr("BOUND_GROWTH") = slam::BOUND_GROWTH;
    m.attr("MAX_NOISE_SCALE") = slam::MAX_NOISE_SCALE;
    m.attr("MAX_BOUND") = slam::MAX_BOUND;
    m.attr("PRIOR_CONTRADICTIONS") = slam::PRIOR_CONTRADICTIONS;
    m.attr("PRIOR_REGIONS") = slam::PRIOR_REGIONS;
    m.attr("UNSEEN_FACTOR") = slam::UNSEEN_FACTOR;
    m.attr("FR_BOUNDED") = static_cast<int64_t>(slam::FR_BOUNDED);
    m.attr("FR_UNBOUNDED") = static_cast<int64_t>(slam::FR_UNBOUNDED);
    m.attr("FR_EMPTY") = static_cast<int64_t>(slam::FR_EMPTY);
    m.attr("FR_MISSING") = static_cast<int64_t>(slam::FR_MISSING);
    m.attr("FRAME_OK") = static_cast<int64_t>(slam::FRAME_OK);
    m.attr("FRAME_L1_UNBOUNDED") = static_cast<int64_t>(slam::FRAME_L1_UNBOUNDED);
    m.attr("FRAME_L2_UNBOUNDED") = static_cast<int64_t>(slam::FRAME_L2_UNBOUNDED);
    m.attr("FRAME_L1_L2_OVERLAP") = static_cast<int64_t>(slam::FRAME_L1_L2_OVERLAP);
    m.attr("FRAME_L1_L2_TOO_CLOSE") = static_cast<int64_t>(slam::FRAME_L1_L2_TOO_CLOSE);
    m.attr("FRAME_L1_MISSING") = static_cast<int64_t>(slam::FRAME_L1_MISSING);
    m.attr("FRAME_L2_MISSING") = static_cast<int64_t>(slam::FRAME_L2_MISSING);
    m.attr("FRAME_REJECTED") = static_cast<int64_t>(slam::FRAME_REJECTED);
    m.attr("LANDMARK_UPDATED") = static_cast<int64_t>(slam::LANDMARK_UPDATED);
    m.attr("LANDMARK_UNBOUNDED") = static_cast<int64_t>(slam::LANDMARK_UNBOUNDED);
    m.attr("LANDMARK_INCONSISTENT") = static_cast<int64_t>(slam::LANDMARK_INCONSISTENT);
    m.attr("LANDMARK_SKIPPED") = static_cast<int64_t>(slam::LANDMARK_SKIPPED);
    m.attr("LANDMARK_MISSING") = static_cast<int64_t>(slam::LANDMARK_MISSING);
    m.attr("TRANSFER_CONSERVATIVE") = static_cast<int64_t>(slam::TRANSFER_CONSERVATIVE);
    m.attr("TRANSFER_PAPER") = static_cast<int64_t>(slam::TRANSFER_PAPER);
    m.attr("TRANSFER_CONSERVATIVE_GLOBAL") =
        static_cast<int64_t>(slam::TRANSFER_CONSERVATIVE_GLOBAL);
    m.attr("INCONSISTENCY_RESTART") = static_cast<int64_t>(slam::INCONSISTENCY_RESTART);
    m.attr("INCONSISTENCY_KEEP") = static_cast<int64_t>(slam::INCONSISTENCY_KEEP);
    m.attr("FUSION_INTERSECT") = static_cast<int64_t>(slam::FUSION_INTERSECT);
    m.attr("FUSION_RELAXED") = static_cast<int64_t>(slam::FUSION_RELAXED);
    m.attr("FUSION_ROBUST") = static_cast<int64_t>(slam::FUSION_ROBUST);
    m.attr("INDEX_OK") = static_cast<int64_t>(slam::INDEX_OK);
    m.attr("INDEX_OUT_OF_RANGE") = static_cast<int64_t>(slam::INDEX_OUT_OF_RANGE);
    m.attr("INDEX_REPEATED") = static_cast<int64_t>(slam::INDEX_REPEATED);
}
