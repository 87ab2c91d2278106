// The C++ tests' few checks (no test framework needed): a failed check prints where and
// what, and the test's exit code counts the failures, which ctest reports.
#pragma once

#include <cstdio>
#include <exception>
#include <string>

namespace bearing::testing {

inline int failures = 0;

inline void check(bool ok, const char* what, const char* file, int line) {
    if (ok) return;
    std::fprintf(stderr, "%s:%d: check failed: %s\n", file, line, what);
    failures += 1;
}

// Whether calling f throws an E whose message contains `fragment` (printed if not).
template <class E, class F>
bool throws(F&& f, const std::string& fragment) {
    try {
        f();
    } catch (const E& error) {
        if (std::string(error.what()).find(fragment) != std::string::npos) return true;
        std::fprintf(stderr, "  message \"%s\" lacks \"%s\"\n", error.what(), fragment.c_str());
        return false;
    } catch (const std::exception& error) {
        std::fprintf(stderr, "  threw another exception: %s\n", error.what());
        return false;
    }
    std::fprintf(stderr, "  threw nothing (expected \"%s\")\n", fragment.c_str());
    return false;
}

inline int report(const char* name) {
    std::printf("%s: %s\n", name, failures == 0 ? "all checks passed" : "FAILED");
    return failures == 0 ? 0 : 1;
}

}  // namespace bearing::testing

#define CHECK(condition) ::bearing::testing::check((condition), #condition, __FILE__, __LINE__)
