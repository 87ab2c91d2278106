// Cones in the robot frame FR and the change of frames FR -> FL
// (bearing_env/slam/kernels/frames.py, ported function for function).
#pragma once

#include <cstdint>
#include <utility>

#include <bearing_core/slam/common.hpp>

namespace bearing::slam {

struct SubSquares;  // slam/local_bound.hpp

// One movement's change of frames, as transfer_region applies it (frames.py FrameChange).
struct FrameChange {
    const cplx* a1 = nullptr;  // the FR region of L1 (a1[:n1])
    int64_t n1 = 0;
    const cplx* a2 = nullptr;  // the FR region of L2
    int64_t n2 = 0;
    const cplx* h1 = nullptr;     // hypotheses h1 (h1[:n_pairs])
    const cplx* inv_d = nullptr;  // their 1 / (h2 - h1)
    int64_t n_pairs = 0;
    bool conservative = false;  // grow the hull by the bound (else the paper's hull)
    // With conservative: the movement's sub-squares, for the local bound (the growth is
    // the smaller of it and the global one); nullptr grows by the global bound alone.
    const SubSquares* local = nullptr;
    double distance = 0.0;  // distance between the regions of L1 and L2
    double delta1 = 0.0;    // sample spacing on L1's edges
    double delta2 = 0.0;
};

// The result of frame_plan: (status, per_edge, distance, delta1, delta2).
struct FramePlan {
    int64_t status = 0;
    int64_t per_edge = 0;
    double distance = 0.0;
    double delta1 = 0.0;
    double delta2 = 0.0;
};

// (n, status): out[:n] (n <= 4) and an FrStatus.
std::pair<int64_t, int64_t> cone_region(double a, double b, double epsilon, cplx* out);
int64_t boundary_samples(const cplx* poly, int64_t n, int64_t per_edge, cplx* out);
FramePlan frame_plan(const cplx* a1, int64_t n1, const cplx* a2, int64_t n2, bool conservative,
                     int64_t edge_samples);
// h1 and inv_d hold MAX_PAIRS; returns the pair count.
int64_t sample_hypotheses(const cplx* a1, int64_t n1, const cplx* a2, int64_t n2, int64_t per_edge,
                          cplx* h1, cplx* inv_d);
// cloud holds MAX_CLOUD, hull MAX_CLOUD + 1, out SCRATCH (frames.py's contract).
int64_t transfer_region(const cplx* target, int64_t n_target, const FrameChange& frame, cplx* cloud,
                        cplx* hull, cplx* out);

}  // namespace bearing::slam
