// Replay a bearing log through one map and print the landmarks' regions.
//
//     replay LOG.csv EPSILON [TRANSFER [FUSION]]
//
// LOG.csv: a header line `movement,landmark,bearing_start,bearing_end`, then one row per
// movement and landmark (0 is L1, 1 is L2), every movement listing every landmark in
// order; bearings in radians counter-clockwise from the direction of motion, `nan` for a
// missed reading; `#` lines are comments. EPSILON: the bearing error bound, radians.
// TRANSFER: conservative (default), paper or conservative_global; FUSION: intersect
// (default), relaxed or robust.
//
// Output, per mapped landmark j (2 is L3): a comment line with its area and estimate,
// then its region's vertices (counter-clockwise, in the frame of L1 at (0, 0) and L2 at
// (1, 0)) as rows `j,x,y`, every number with all 17 digits.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <bearing_core/slam/map_batch.hpp>

namespace {

namespace slam = bearing::slam;

struct BearingLog {
    int64_t landmarks = 0;
    std::vector<std::vector<double>> start, end;  // per movement, per landmark
};

double bearing_of(const std::string& field, int line) {
    char* stop = nullptr;
    const double value = std::strtod(field.c_str(), &stop);
    if (field.empty() || *stop != '\0' || std::isinf(value)) {
        throw std::invalid_argument("line " + std::to_string(line) + ": bearing \"" + field +
                                    "\" is not a finite number or nan");
    }
    return value;
}

// One row's fields: movement, landmark, bearing at the start, bearing at the end.
void read_row(const std::string& text, int line, BearingLog& log) {
    std::vector<std::string> fields;
    std::stringstream row(text);
    for (std::string field; std::getline(row, field, ',');) fields.push_back(field);
    if (fields.size() != 4) {
        throw std::invalid_argument("line " + std::to_string(line) + " has " +
                                    std::to_string(fields.size()) + " fields, not 4");
    }
    const long movement = std::stol(fields[0]), landmark = std::stol(fields[1]);
    if (landmark == 0) {
        log.start.emplace_back();
        log.end.emplace_back();
    }
    const auto expected_movement = static_cast<long>(log.start.size()) - 1;
    const auto expected_landmark =
        static_cast<long>(log.start.empty() ? 0 : log.start.back().size());
    if (movement != expected_movement || landmark != expected_landmark) {
        throw std::invalid_argument("line " + std::to_string(line) + ": (movement, landmark) (" +
                                    fields[0] + ", " + fields[1] + ") out of order");
    }
    log.start.back().push_back(bearing_of(fields[2], line));
    log.end.back().push_back(bearing_of(fields[3], line));
}

BearingLog read_log(const char* path) {
    std::ifstream file(path);
    if (!file) throw std::invalid_argument(std::string("cannot read ") + path);
    BearingLog log;
    std::string text;
    int line = 0;
    bool header = false;
    while (std::getline(file, text)) {
        line += 1;
        if (text.empty() || text[0] == '#') continue;
        if (!header) {
            if (text != "movement,landmark,bearing_start,bearing_end") {
                throw std::invalid_argument("line " + std::to_string(line) +
                                            ": expected the header "
                                            "movement,landmark,bearing_start,bearing_end");
            }
            header = true;
            continue;
        }
        read_row(text, line, log);
    }
    log.landmarks = log.start.empty() ? 0 : static_cast<int64_t>(log.start[0].size());
    for (const auto& movement : log.start) {
        if (static_cast<int64_t>(movement.size()) != log.landmarks) {
            throw std::invalid_argument("every movement must list the same landmarks");
        }
    }
    return log;
}

int64_t code_of(const char* name, const std::vector<std::string>& names, const char* what) {
    for (size_t k = 0; k < names.size(); ++k) {
        if (names[k] == name) return static_cast<int64_t>(k);
    }
    throw std::invalid_argument(std::string("unknown ") + what + " \"" + name + "\"");
}

void print_regions(const slam::MapBatch& maps) {
    for (int64_t j = 0; j < maps.n_landmarks() - 2; ++j) {
        const std::vector<bearing::cplx> region = maps.region(0, j);
        const bearing::cplx estimate = maps.estimate(0, j);
        std::printf("# landmark %lld (L%lld): area %.17g, estimate %.17g %.17g, %zu vertices\n",
                    static_cast<long long>(j + 2), static_cast<long long>(j + 3), maps.area(0, j),
                    estimate.re, estimate.im, region.size());
        for (const bearing::cplx& v : region) {
            std::printf("%lld,%.17g,%.17g\n", static_cast<long long>(j + 2), v.re, v.im);
        }
    }
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 3 || argc > 5) {
        std::fprintf(stderr, "usage: %s LOG.csv EPSILON [TRANSFER [FUSION]]\n", argv[0]);
        return 2;
    }
    try {
        const BearingLog log = read_log(argv[1]);
        slam::MapSettings settings;
        settings.epsilon = std::strtod(argv[2], nullptr);
        // The names of the codes, in the order of their values (slam/state.hpp).
        if (argc > 3) {
            settings.transfer = static_cast<slam::Transfer>(
                code_of(argv[3], {"conservative", "paper", "conservative_global"}, "transfer"));
        }
        if (argc > 4)
            settings.fusion = static_cast<slam::Fusion>(
                code_of(argv[4], {"intersect", "relaxed", "robust"}, "fusion"));
        slam::MapBatch maps(1, log.landmarks, settings);
        for (size_t move = 0; move < log.start.size(); ++move) {
            maps.update(log.start[move], log.end[move]);
        }
        std::printf("# %zu movements, %lld landmarks\n", log.start.size(),
                    static_cast<long long>(log.landmarks));
        print_regions(maps);
    } catch (const std::exception& error) {
        std::fprintf(stderr, "replay: %s\n", error.what());
        return 1;
    }
    return 0;
}
