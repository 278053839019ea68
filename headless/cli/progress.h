// Progress on stderr: a one-line bar with the ETA on a terminal; otherwise
// (logs, CI) an info line every 5 % of the directions.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "core/log.h"

namespace bb::cli {

class ProgressBar {
public:
    ProgressBar(bool enabled, bool terminal)
        : enabled_(enabled), terminal_(terminal), start_(std::chrono::steady_clock::now()) {}
    void update(int done, int total) {
        if (!enabled_ || total <= 0) return;
        double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
        double eta = done > 0 ? elapsed * (total - done) / done : 0.0;
        if (!terminal_) {
            int step = std::max(1, total / 20);
            if (done / step == lastLine_ / step && done != total) return;
            lastLine_ = done;
            char line[96];
            std::snprintf(line, sizeof line, "%d/%d directions, %.1f s, ETA %.1f s", done, total, elapsed, eta);
            logInfo(line);
            return;
        }
        int width = 40, filled = int(double(width) * done / total);
        std::fprintf(stderr, "\r[%.*s%*s] %d/%d directions, %.1f s, ETA %.1f s ", filled,
                     "########################################", width - filled, "", done, total, elapsed, eta);
        std::fflush(stderr);
    }
    void finish() {
        if (enabled_ && terminal_) std::fprintf(stderr, "\n");
    }

private:
    bool enabled_, terminal_;
    int lastLine_ = 0;
    std::chrono::steady_clock::time_point start_;
};

}  // namespace bb::cli
