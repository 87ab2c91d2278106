// A batch of maps that owns its state (map_batch.hpp): the arrays that
// bearing_env.slam.BatchedPolygonSLAM allocates, with the same shapes and first values,
// so that the same movements give the same bits.
#include <bearing_core/slam/map_batch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include <bearing_core/core/pymath.hpp>
#include <bearing_core/core/schema.hpp>
#include <bearing_core/slam/robust.hpp>
#include <bearing_core/slam/scratch.hpp>
#include <bearing_core/slam/update.hpp>

namespace bearing::slam {

namespace {

constexpr double INF = std::numeric_limits<double>::infinity();
constexpr double NAN_VALUE = std::numeric_limits<double>::quiet_NaN();
// The most maps one batch holds: far above any use, and low enough that no array's size
// overflows int64 (2^31 maps of MAX_WINDOW x MAX_LANDMARKS x CAPACITY vertices).
constexpr int64_t MAX_MAPS = int64_t{1} << 31;

// A number as a message names it: all its digits, so that the bad value is recognisable.
std::string describe(double value) {
    std::ostringstream out;
    out.precision(17);
    out << value;
    return out.str();
}

void require(bool ok, const std::string& message) {
    if (!ok) throw std::invalid_argument(message);
}

void require_code(bool ok, const char* name, const char* choices, int64_t value) {
    require(ok, std::string(name) + " must be " + choices + ", not " + std::to_string(value));
}

void require_transfer(int64_t transfer) {
    require_code(valid_transfer(transfer), "transfer",
                 "TRANSFER_CONSERVATIVE (0), TRANSFER_PAPER (1) or "
                 "TRANSFER_CONSERVATIVE_GLOBAL (2)",
                 transfer);
}

void require_policy_and_fusion(int64_t on_inconsistency, int64_t fusion) {
    require_code(
        on_inconsistency == INCONSISTENCY_RESTART || on_inconsistency == INCONSISTENCY_KEEP,
        "on_inconsistency", "INCONSISTENCY_RESTART (0) or INCONSISTENCY_KEEP (1)",
        on_inconsistency);
    require_code(fusion == FUSION_INTERSECT || fusion == FUSION_RELAXED || fusion == FUSION_ROBUST,
                 "fusion", "FUSION_INTERSECT (0), FUSION_RELAXED (1) or FUSION_ROBUST (2)", fusion);
}

void require_edge_samples(int64_t edge_samples) {
    require(edge_samples >= 1 && edge_samples <= MAX_EDGE_SAMPLES,
            "edge_samples must be in [1, " + std::to_string(MAX_EDGE_SAMPLES) + "], not " +
                std::to_string(edge_samples));
}

template <class T, int D>
void fill(View<T, D> view, T value) {
    std::fill_n(view.data, view.size(), value);
}

}  // namespace

void validate(const Params& p) {
    require(std::isfinite(p.epsilon) && p.epsilon > 0.0,
            "epsilon must be a positive finite number of radians, not " + describe(p.epsilon));
    require_transfer(p.transfer);
    require_edge_samples(p.edge_samples);
    require_policy_and_fusion(p.on_inconsistency, p.fusion);
    require(p.max_outliers >= 0 && p.max_outliers < MAX_WINDOW,
            "max_outliers must be in [0, " + std::to_string(MAX_WINDOW) + "), not " +
                std::to_string(p.max_outliers));
    require(std::isfinite(p.risk), "risk must be a finite number, not " + describe(p.risk));
}

void MapSettings::validate() const {
    require(epsilon > 0.0 && epsilon < PI / 2,
            "epsilon must be in (0, pi/2) radians, not " + describe(epsilon));
    require_transfer(transfer);
    require_edge_samples(edge_samples);
    require_policy_and_fusion(on_inconsistency, fusion);
    require(
        window >= 1 && window <= MAX_WINDOW,
        "window must be in [1, " + std::to_string(MAX_WINDOW) + "], not " + std::to_string(window));
    require(max_outliers >= 0 && max_outliers < window,
            "max_outliers must be in [0, window = " + std::to_string(window) + "), not " +
                std::to_string(max_outliers));
    require(risk > 0.0 && risk <= 0.5, "risk must be in (0, 0.5], not " + describe(risk));
}

Params MapSettings::params(bool with_robot) const {
    Params p;
#define BEARING_CORE_COPY_SETTING(T, name, value, doc) p.name = name;
    BEARING_CORE_UPDATE_SETTINGS(BEARING_CORE_COPY_SETTING)
#undef BEARING_CORE_COPY_SETTING
    p.with_robot = with_robot;
    slam::validate(p);
    return p;
}

// The state's arrays, each a block of its own, kept alive with the batch.
struct MapBatch::Storage {
    std::vector<std::shared_ptr<void>> blocks;

    // view = a new zero-filled array of `shape` (the state's schema gives it).
    template <class T, int D>
    void allocate(View<T, D>& view, const std::vector<int64_t>& shape) {
        for (int d = 0; d < D; ++d) view.shape[d] = shape[static_cast<size_t>(d)];
        std::shared_ptr<T[]> block(new T[static_cast<size_t>(std::max<int64_t>(view.size(), 1))]);
        view.data = block.get();
        fill(view, T{});
        blocks.push_back(block);
    }
};

MapBatch::MapBatch(int64_t num_maps, int64_t n_landmarks, const MapSettings& settings)
    : num_maps_(num_maps),
      n_landmarks_(n_landmarks),
      settings_(settings),
      storage_(std::make_unique<Storage>()) {
    require(num_maps >= 1 && num_maps <= MAX_MAPS, "num_maps must be in [1, " +
                                                       std::to_string(MAX_MAPS) + "], not " +
                                                       std::to_string(num_maps));
    require(n_landmarks >= 3 && n_landmarks <= MAX_LANDMARKS,
            "n_landmarks must be in [3, " + std::to_string(MAX_LANDMARKS) +
                "] (L1, L2 and one more), not " + std::to_string(n_landmarks));
    settings.validate();
    // The lengths of the state's shape rules (state.hpp); the fusion's arrays not used
    // have an empty axis.
    const bool relaxed = settings.fusion == FUSION_RELAXED;
    const bool robust = settings.fusion == FUSION_ROBUST;
    const schema::Sizes sizes{{"maps", num_maps},
                              {"m", n_landmarks - 2},
                              {"CAPACITY", CAPACITY},
                              {"w", relaxed ? settings.window : 0},
                              {"base_capacity", relaxed ? CAPACITY : 0},
                              {"levels", robust ? ROBUST_LEVELS : 0},
                              {"probe_capacity", robust ? CAPACITY : 0},
                              {"h", robust ? HISTORY : 0}};
    for_each_field(state_, [&](const char*, const char* rule, auto& view) {
        storage_->allocate(view, schema::shape_of(rule, sizes));
    });
    reset();
}

MapBatch::MapBatch(MapBatch&&) noexcept = default;
MapBatch& MapBatch::operator=(MapBatch&&) noexcept = default;
MapBatch::~MapBatch() = default;

void MapBatch::reset() {
    // BatchedPolygonSLAM.reset: the counts, areas, estimates and counters (the vertices
    // past a count are never read).
    MapState& s = state_;
    const cplx nan_point(NAN_VALUE, NAN_VALUE);
    fill(s.counts, int64_t{0});
    fill(s.areas, INF);
    fill(s.centroids, nan_point);
    fill(s.robot_counts, int64_t{0});
    fill(s.robot_area, INF);
    fill(s.robot_centroid, nan_point);
    fill(s.robot_heading, NAN_VALUE);
    for (const auto& counter :
         {s.n_updates, s.n_frame_changes, s.n_inconsistent, s.window_length, s.window_next,
          s.robot_fixed_at, s.bound_events, s.history_length, s.history_next}) {
        fill(counter, int64_t{0});
    }
    for (const auto& per_landmark :
         {s.base_counts, s.n_dropped, s.outliers, s.n_regions, s.probe_counts}) {
        fill(per_landmark, int64_t{0});
    }
    fill(s.window_counts, int64_t{0});
    fill(s.level_counts, int64_t{0});
    fill(s.noise_scale, 1.0);
}

UpdateResult MapBatch::update(const std::vector<double>& bearings_start,
                              const std::vector<double>& bearings_end, bool with_robot,
                              int64_t threads) {
    const int64_t size = num_maps_ * n_landmarks_;
    const std::pair<const char*, const std::vector<double>*> inputs[] = {
        {"bearings_start", &bearings_start}, {"bearings_end", &bearings_end}};
    for (const auto& [name, bearings] : inputs) {
        require(static_cast<int64_t>(bearings->size()) == size,
                std::string(name) + " must hold num_maps x n_landmarks = " + std::to_string(size) +
                    " bearings, not " + std::to_string(bearings->size()));
        for (size_t k = 0; k < bearings->size(); ++k) {
            require(!std::isinf((*bearings)[k]), std::string(name) + "[" + std::to_string(k) +
                                                     "] is " + describe((*bearings)[k]) +
                                                     ": bearings must be finite or NaN (a missed "
                                                     "reading)");
        }
    }
    require(threads >= 1, "threads must be at least 1, not " + std::to_string(threads));
    const int64_t m = n_landmarks_ - 2;
    UpdateResult result{std::vector<int8_t>(static_cast<size_t>(num_maps_)),
                        std::vector<int8_t>(static_cast<size_t>(num_maps_ * m)),
                        std::vector<int64_t>(static_cast<size_t>(num_maps_))};
    std::vector<int64_t> rows(static_cast<size_t>(num_maps_));
    for (int64_t i = 0; i < num_maps_; ++i) rows[static_cast<size_t>(i)] = i;
    Outputs out;
    out.frame_status = {result.frame_status.data(), {num_maps_}};
    out.landmark_status = {result.landmark_status.data(), {num_maps_, m}};
    out.n_bad = {result.n_bad.data(), {num_maps_}};
    update_maps({bearings_start.data(), {num_maps_, n_landmarks_}},
                {bearings_end.data(), {num_maps_, n_landmarks_}}, {rows.data(), {num_maps_}},
                settings_.params(with_robot), state_, out, threads);
    return result;
}

void MapBatch::check_index(int64_t map, int64_t landmark) const {
    if (map < 0 || map >= num_maps_) {
        throw std::out_of_range("map must be in [0, " + std::to_string(num_maps_) + "), not " +
                                std::to_string(map));
    }
    if (landmark < 0 || landmark >= n_landmarks_ - 2) {
        throw std::out_of_range("landmark must be in [0, " + std::to_string(n_landmarks_ - 2) +
                                ") (0 is L3), not " + std::to_string(landmark));
    }
}

std::vector<cplx> MapBatch::region(int64_t map, int64_t landmark) const {
    check_index(map, landmark);
    const cplx* first = state_.vertices.row(map, landmark);
    return std::vector<cplx>(first, first + state_.counts(map, landmark));
}

double MapBatch::area(int64_t map, int64_t landmark) const {
    check_index(map, landmark);
    return state_.areas(map, landmark);
}

cplx MapBatch::estimate(int64_t map, int64_t landmark) const {
    check_index(map, landmark);
    return state_.centroids(map, landmark);
}

std::vector<cplx> MapBatch::robot_region(int64_t map) const {
    check_index(map, 0);
    const cplx* first = state_.robot_vertices.row(map);
    return std::vector<cplx>(first, first + state_.robot_counts(map));
}

}  // namespace bearing::slam
