// Wall-clock timing for the figures the bake reports (stats.json, benches).
#pragma once

#include <chrono>

namespace bb {

using Clock = std::chrono::steady_clock;

// Seconds from t0 to now.
inline double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace bb
