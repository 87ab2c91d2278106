// The library's owning types: MapSettings, Params and MapBatch validate themselves
// (std::invalid_argument naming the bad value), a batch updates from bearings and gives
// its regions, areas and estimates, and the update refuses what would overflow.
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include <bearing_core/slam/map_batch.hpp>
#include <bearing_core/slam/robust.hpp>

#include "check.hpp"

namespace {

using bearing::cplx;
using bearing::testing::throws;
namespace slam = bearing::slam;

constexpr double DEG = 3.141592653589793 / 180.0;
constexpr int64_t INT64_END = std::numeric_limits<int64_t>::max();

slam::MapSettings settings_with(void (*change)(slam::MapSettings&)) {
    slam::MapSettings s;
    s.epsilon = 2.0 * DEG;
    change(s);
    return s;
}

template <class Change>
bool refused(Change change, const char* fragment) {
    slam::MapSettings s;
    s.epsilon = 2.0 * DEG;
    change(s);
    return throws<std::invalid_argument>([&] { slam::MapBatch maps(1, 4, s); }, fragment);
}

void settings_are_validated() {
    CHECK(refused([](auto& s) { s.epsilon = 0.0; }, "epsilon must be in (0, pi/2) radians, not 0"));
    CHECK(refused([](auto& s) { s.epsilon = std::nan(""); }, "epsilon must be in (0, pi/2)"));
    CHECK(refused([](auto& s) { s.epsilon = 2.0; }, "not 2"));
    CHECK(
        refused([](auto& s) { s.transfer = static_cast<slam::Transfer>(3); }, "transfer must be"));
    CHECK(refused([](auto& s) { s.edge_samples = 0; }, "edge_samples must be in [1, 8], not 0"));
    CHECK(refused([](auto& s) { s.on_inconsistency = static_cast<slam::Inconsistency>(-1); },
                  "on_inconsistency must be"));
    CHECK(refused([](auto& s) { s.fusion = static_cast<slam::Fusion>(7); },
                  "fusion must be FUSION_INTERSECT (0)"));
    CHECK(refused([](auto& s) { s.window = 33; }, "window must be in [1, 32], not 33"));
    CHECK(refused([](auto& s) { s.max_outliers = 8; }, "max_outliers must be in [0, window = 8)"));
    CHECK(refused([](auto& s) { s.risk = 0.0; }, "risk must be in (0, 0.5], not 0"));
    CHECK(refused([](auto& s) { s.risk = 0.75; }, "not 0.75"));
    slam::Params p = settings_with([](auto&) {}).params(true);
    p.epsilon = -1.0;
    CHECK(throws<std::invalid_argument>([&] { slam::validate(p); }, "epsilon must be a positive"));
    const slam::MapSettings good = settings_with([](auto&) {});
    CHECK(throws<std::invalid_argument>([&] { slam::MapBatch maps(0, 4, good); },
                                        "num_maps must be in [1, "));
    CHECK(throws<std::invalid_argument>([&] { slam::MapBatch maps(1, 2, good); },
                                        "n_landmarks must be in [3, 256] (L1, L2 and one more), "
                                        "not 2"));
}

// L1 at 0, L2 at 1 and L3, L4 above them; a robot moving right below them.
struct World {
    std::vector<cplx> landmarks = {{0.0, 0.0}, {1.0, 0.0}, {0.3, 0.8}, {0.7, 0.5}};

    std::vector<double> bearings(cplx robot) const {
        std::vector<double> out;
        for (cplx l : landmarks) out.push_back(std::atan2(l.im - robot.im, l.re - robot.re));
        return out;
    }
};

// Whether the convex CCW polygon `region` contains `point` (boundary included).
bool contains(const std::vector<cplx>& region, cplx point) {
    for (size_t k = 0; k < region.size(); ++k) {
        const cplx a = region[k], b = region[(k + 1) % region.size()];
        if (bearing::cross(b - a, point - a) < -1e-12) return false;
    }
    return true;
}

void a_batch_maps_the_landmarks() {
    slam::MapBatch maps(1, 4, settings_with([](auto&) {}));
    CHECK(maps.region(0, 0).empty() && std::isinf(maps.area(0, 0)));
    CHECK(std::isnan(maps.estimate(0, 1).re));
    const World world;
    const slam::UpdateResult result =
        maps.update(world.bearings({0.2, -0.6}), world.bearings({0.8, -0.6}));
    CHECK(result.frame_status[0] == slam::FRAME_OK);
    CHECK(result.landmark_status[0] == slam::LANDMARK_UPDATED);
    CHECK(result.landmark_status[1] == slam::LANDMARK_UPDATED);
    for (int64_t j = 0; j < 2; ++j) {
        // The region (in the L1-L2 frame, which is the world frame here) holds the true
        // landmark and its estimate; its area is one movement's (finite, under 0.5).
        const std::vector<cplx> region = maps.region(0, j);
        CHECK(region.size() >= 3);
        CHECK(contains(region, world.landmarks[static_cast<size_t>(j + 2)]));
        CHECK(contains(region, maps.estimate(0, j)));
        CHECK(std::isfinite(maps.area(0, j)) && maps.area(0, j) > 0.0 && maps.area(0, j) < 0.5);
    }
    CHECK(maps.robot_region(0).size() >= 3);
    maps.reset();
    CHECK(maps.region(0, 0).empty() && maps.state().n_updates(0) == 0);
    CHECK(throws<std::out_of_range>([&] { maps.region(1, 0); }, "map must be in [0, 1), not 1"));
    CHECK(throws<std::out_of_range>([&] { maps.area(0, 2); }, "landmark must be in [0, 2)"));
}

void bad_bearings_are_refused_and_change_nothing() {
    slam::MapBatch maps(2, 4, settings_with([](auto&) {}));
    const std::vector<double> good(8, 0.5);
    std::vector<double> infinite = good;
    infinite[5] = std::numeric_limits<double>::infinity();
    CHECK(throws<std::invalid_argument>([&] { maps.update(good, infinite); },
                                        "bearings_end[5] is inf: bearings must be finite or NaN"));
    CHECK(throws<std::invalid_argument>([&] { maps.update(good, std::vector<double>(7)); },
                                        "bearings_end must hold num_maps x n_landmarks = 8 "
                                        "bearings, not 7"));
    CHECK(throws<std::invalid_argument>([&] { maps.update(good, good, true, 0); },
                                        "threads must be at least 1, not 0"));
    CHECK(maps.state().n_updates(0) == 0 && maps.state().n_updates(1) == 0);
    // A missed reading (NaN) is not an error.
    std::vector<double> missed = good;
    missed[0] = std::nan("");
    maps.update(missed, good);
    CHECK(maps.state().n_updates(0) == 1);
}

void counters_that_would_overflow_are_refused() {
    slam::MapBatch maps(1, 4, settings_with([](auto&) {}));
    const World world;
    maps.state().n_updates(0) = INT64_END;
    CHECK(throws<std::invalid_argument>(
        [&] { maps.update(world.bearings({0.2, -0.6}), world.bearings({0.8, -0.6})); },
        "map 0 has a corrupt state: n_updates out of range"));
    CHECK(maps.state().n_updates(0) == INT64_END);
}

void binomial_q_is_bounded() {
    // A risk that is never met (<= 0) gives q_cap at once, however large.
    CHECK(slam::binomial_q(10, 0.5, 0.0, INT64_END) == INT64_END);
    CHECK(slam::binomial_q(INT64_END, 0.5, -1.0, INT64_END) == INT64_END);
    CHECK(slam::binomial_q(10, 0.5, 0.05, INT64_END) == slam::binomial_q(10, 0.5, 0.05, 10));
    CHECK(slam::binomial_q(10, 0.5, 0.05, 10) == 8);  // P(Bin(10, 1/2) > 8) = 11/1024 < 0.05
}

}  // namespace

int main() {
    settings_are_validated();
    a_batch_maps_the_landmarks();
    bad_bearings_are_refused_and_change_nothing();
    counters_that_would_overflow_are_refused();
    binomial_q_is_bounded();
    return bearing::testing::report("map batch");
}
