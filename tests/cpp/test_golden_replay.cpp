// The golden map corpus, replayed bit for bit through the library's MapBatch.
//
// tests/golden/slam_replay.txt (written by tests/golden_replay.py, which documents its
// format) holds cases of the corpus: settings, every movement's bearings and the sha256
// the Python corpus recorded over every update's result and every state array after every
// movement (tests/golden_slam.py's _feed). Each case runs here on a thread of its own with
// a 256 KB stack (so the update must not need a large stack), is hashed over the same
// bytes, and must give the recorded hash.
//
// Usage: test_golden_replay REPLAY_FILE
#include <pthread.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <bearing_core/slam/map_batch.hpp>

#include "check.hpp"
#include "sha256.hpp"

namespace {

using bearing::cplx;
using bearing::testing::Sha256;
namespace slam = bearing::slam;

constexpr size_t THREAD_STACK = 256 * 1024;

struct ReplayCase {
    std::string name, sha256;
    slam::MapSettings settings;
    int64_t maps = 0, landmarks = 0, moves = 0;
    std::vector<std::vector<double>> bearings;  // start, end, start, end, ...
    std::string replayed;                       // the replay's hash
    std::string error;                          // what the replay threw, if anything
};

std::vector<double> numbers(std::istringstream& line) {
    std::vector<double> out;
    std::string word;
    while (line >> word) out.push_back(std::strtod(word.c_str(), nullptr));
    return out;
}

std::vector<ReplayCase> read_cases(const char* path) {
    std::ifstream file(path);
    if (!file) throw std::runtime_error(std::string("cannot read ") + path);
    std::vector<ReplayCase> cases;
    std::string text;
    while (std::getline(file, text)) {
        if (text.empty() || text[0] == '#') continue;
        std::istringstream line(text);
        std::string kind;
        line >> kind;
        if (kind == "case") {
            cases.emplace_back();
            line >> cases.back().name >> cases.back().sha256;
        } else if (kind == "settings") {
            slam::MapSettings& s = cases.back().settings;
            int64_t transfer = 0, on_inconsistency = 0, fusion = 0;
            line >> s.epsilon >> transfer >> s.edge_samples >> on_inconsistency >> fusion >>
                s.max_outliers >> s.window >> s.risk >> s.likely >> s.estimate_bound;
            s.transfer = static_cast<slam::Transfer>(transfer);
            s.on_inconsistency = static_cast<slam::Inconsistency>(on_inconsistency);
            s.fusion = static_cast<slam::Fusion>(fusion);
        } else if (kind == "shape") {
            line >> cases.back().maps >> cases.back().landmarks >> cases.back().moves;
        } else if (kind == "start" || kind == "end") {
            cases.back().bearings.push_back(numbers(line));
        } else {
            throw std::runtime_error("unknown record " + kind);
        }
    }
    return cases;
}

// Python's repr of a shape tuple: (4,) or (4, 5, 128, 2).
template <size_t D>
std::string shape_text(const std::array<int64_t, D>& shape, bool complex_pairs) {
    std::string out = "(";
    for (size_t d = 0; d < D; ++d) out += (d ? ", " : "") + std::to_string(shape[d]);
    if (complex_pairs) out += ", 2";
    if (D == 1 && !complex_pairs) out += ",";
    return out + ")";
}

void feed_double(Sha256& digest, double value) {
    if (std::isnan(value)) value = std::numeric_limits<double>::quiet_NaN();  // numpy's nan
    digest.update(&value, sizeof value);
}

// One array as tests/golden_slam.py's _feed hashes it: "<dtype><shape>" then its bytes
// (complex as float64 pairs, every NaN as numpy's one NaN).
template <class T, int D>
void feed(Sha256& digest, const bearing::View<T, D>& view) {
    using Element = std::remove_const_t<T>;
    constexpr bool is_complex = std::is_same_v<Element, cplx>;
    const char* dtype = std::is_same_v<Element, bool>      ? "|b1"
                        : std::is_same_v<Element, int8_t>  ? "|i1"
                        : std::is_same_v<Element, int64_t> ? "<i8"
                                                           : "<f8";
    digest.update(dtype + shape_text(view.shape, is_complex));
    for (int64_t k = 0; k < view.size(); ++k) {
        if constexpr (is_complex) {
            feed_double(digest, view.data[k].re);
            feed_double(digest, view.data[k].im);
        } else if constexpr (std::is_same_v<Element, double>) {
            feed_double(digest, view.data[k]);
        } else {
            digest.update(&view.data[k], sizeof(Element));
        }
    }
}

// Whether state field k (State's order) is hashed for `fusion`: BatchedPolygonSLAM's
// state_names, the arrays of every fusion and those of the batch's own.
bool hashed(int k, int64_t fusion) {
    constexpr int WINDOW_VERTICES = 12, OUTLIERS = 21, LEVEL_VERTICES = 22;
    if (k < WINDOW_VERTICES) return true;
    if (fusion == slam::FUSION_RELAXED) return k <= OUTLIERS;
    if (fusion == slam::FUSION_ROBUST) return k == OUTLIERS || k >= LEVEL_VERTICES;
    return false;
}

void feed_state(Sha256& digest, const slam::MapState& state, int64_t fusion) {
    // The robust fusion's names put outliers first, then the levels and history.
    int k = 0;
    const bool robust = fusion == slam::FUSION_ROBUST;
    slam::for_each_field(state, [&](const char* name, const char*, const auto& view) {
        if (hashed(k, fusion) && !(robust && std::strcmp(name, "outliers") == 0)) {
            feed(digest, view);
        }
        if (robust && std::strcmp(name, "n_inconsistent") == 0) feed(digest, state.outliers);
        k += 1;
    });
}

void replay(ReplayCase& c) {
    slam::MapBatch maps(c.maps, c.landmarks, c.settings);
    Sha256 digest;
    const int64_t m = c.landmarks - 2;
    for (int64_t move = 0; move < c.moves; ++move) {
        const auto index = static_cast<size_t>(2 * move);
        const slam::UpdateResult r = maps.update(c.bearings[index], c.bearings[index + 1]);
        feed(digest, bearing::View<const int8_t, 1>{r.frame_status.data(), {c.maps}});
        feed(digest, bearing::View<const int8_t, 2>{r.landmark_status.data(), {c.maps, m}});
        feed(digest, bearing::View<const int64_t, 1>{r.n_bad.data(), {c.maps}});
        feed_state(digest, maps.state(), c.settings.fusion);
    }
    c.replayed = digest.hexdigest();
}

void* replay_thread(void* argument) {
    auto* c = static_cast<ReplayCase*>(argument);
    try {
        replay(*c);
    } catch (const std::exception& error) {
        c->error = error.what();
    }
    return nullptr;
}

// Replay `c` on a new thread with a THREAD_STACK-byte stack.
void replay_on_small_stack(ReplayCase& c) {
    pthread_attr_t attributes;
    pthread_attr_init(&attributes);
    CHECK(pthread_attr_setstacksize(&attributes, THREAD_STACK) == 0);
    pthread_t thread;
    CHECK(pthread_create(&thread, &attributes, replay_thread, &c) == 0);
    pthread_join(thread, nullptr);
    pthread_attr_destroy(&attributes);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s REPLAY_FILE\n", argv[0]);
        return 2;
    }
    std::vector<ReplayCase> cases = read_cases(argv[1]);
    CHECK(cases.size() >= 10);
    for (ReplayCase& c : cases) {
        CHECK(static_cast<int64_t>(c.bearings.size()) == 2 * c.moves);
        replay_on_small_stack(c);
        const bool same = c.error.empty() && c.replayed == c.sha256;
        std::printf("%s %s\n", same ? "same" : "DIFFERS", c.name.c_str());
        if (!c.error.empty()) std::printf("  threw: %s\n", c.error.c_str());
        CHECK(same);
    }
    std::printf("%zu cases replayed on %zu KB stacks\n", cases.size(), THREAD_STACK / 1024);
    return bearing::testing::report("golden replay");
}
