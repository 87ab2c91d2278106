// A batch of polygon-SLAM maps that owns its state: the C++ counterpart of
// bearing_env.slam.BatchedPolygonSLAM (same settings, same state, same results bit for
// bit). Make one from validated settings, update it with each movement's bearings, and
// read the landmarks' regions, areas and estimates.
//
//     bearing::slam::MapSettings settings;
//     settings.epsilon = 0.035;  // radians
//     bearing::slam::MapBatch maps(1, 4, settings);  // 1 map, landmarks L1, L2, L3, L4
//     maps.update(start, end);   // bearings (maps x landmarks) at R1 and at R2
//     maps.region(0, 0);         // the region of L3 in map 0, in L1-L2 frame coordinates
//
// Every type validates itself: a bad value throws std::invalid_argument naming it.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <bearing_core/core/complex.hpp>
#include <bearing_core/core/views.hpp>
#include <bearing_core/slam/state.hpp>

namespace bearing::slam {

// A map's settings (bearing_env.slam.settings.MapSettings): the update's shared settings
// and the relaxed fusion's window.
struct MapSettings {
    BEARING_CORE_UPDATE_SETTINGS(BEARING_CORE_DECLARE_SETTING)
    int64_t window = 8;  // relaxed fusion: movements in the window, [1, MAX_WINDOW]

    // Throws std::invalid_argument naming the first bad value.
    void validate() const;
    // The update's Params for these settings.
    Params params(bool with_robot) const;
};

// What one update did to each map (bearing_env.slam.BatchUpdateResult).
struct UpdateResult {
    std::vector<int8_t> frame_status;     // (maps,) a FrameStatus
    std::vector<int8_t> landmark_status;  // (maps * mapped landmarks) a LandmarkStatus
    std::vector<int64_t> n_bad;           // (maps,) landmarks found inconsistent
};

class MapBatch {
public:
    // num_maps >= 1 empty maps of n_landmarks >= 3 landmarks (L1, L2 and the mapped ones,
    // at most MAX_LANDMARKS) with `settings`; throws std::invalid_argument on a bad value.
    MapBatch(int64_t num_maps, int64_t n_landmarks, const MapSettings& settings);
    MapBatch(MapBatch&&) noexcept;
    MapBatch& operator=(MapBatch&&) noexcept;
    MapBatch(const MapBatch&) = delete;
    MapBatch& operator=(const MapBatch&) = delete;
    ~MapBatch();

    // Fuse one movement into every map: bearings (num_maps x n_landmarks, map by map)
    // at R1 and at R2, radians counter-clockwise from the direction of motion, column 0
    // L1 and column 1 L2; NaN for a missed reading. with_robot: also transfer the robot.
    // threads > 1 splits the maps over that many threads (same results). Throws
    // std::invalid_argument on a wrong size or an infinite bearing (nothing updated).
    UpdateResult update(const std::vector<double>& bearings_start,
                        const std::vector<double>& bearings_end, bool with_robot = true,
                        int64_t threads = 1);
    // Forget everything in every map.
    void reset();

    int64_t num_maps() const { return num_maps_; }
    int64_t n_landmarks() const { return n_landmarks_; }
    const MapSettings& settings() const { return settings_; }

    // Mapped landmark `landmark` (0 is L3, the first landmark after L1 and L2) of map
    // `map`, in the landmark frame (L1 at 0, L2 at 1): its region's vertices (CCW; empty
    // before the landmark is initialised), area (inf before) and estimate (the region's
    // centroid; NaN before). Throws std::out_of_range on a bad index.
    std::vector<cplx> region(int64_t map, int64_t landmark) const;
    double area(int64_t map, int64_t landmark) const;
    cplx estimate(int64_t map, int64_t landmark) const;
    // The robot's region at the end of the last movement that changed frames (empty
    // before any).
    std::vector<cplx> robot_region(int64_t map) const;

    // The state's arrays, as the kernels take them (bearing_env.slam.kernels.State).
    const MapState& state() const { return state_; }

private:
    void check_index(int64_t map, int64_t landmark) const;

    struct Storage;
    int64_t num_maps_;
    int64_t n_landmarks_;
    MapSettings settings_;
    std::unique_ptr<Storage> storage_;
    MapState state_;
};

}  // namespace bearing::slam
