// A one-line progress bar on stderr (only when it is a terminal).
#pragma once

#include <chrono>
#include <cstdio>

namespace bb::cli {

class ProgressBar {
public:
    explicit ProgressBar(bool enabled) : enabled_(enabled), start_(std::chrono::steady_clock::now()) {}
    void update(int done, int total) {
        if (!enabled_ || total <= 0) return;
        double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
        double eta = done > 0 ? elapsed * (total - done) / done : 0.0;
        int width = 40, filled = int(double(width) * done / total);
        std::fprintf(stderr, "\r[%.*s%*s] %d/%d directions, %.1f s, ETA %.1f s ", filled,
                     "########################################", width - filled, "", done, total, elapsed, eta);
        std::fflush(stderr);
    }
    void finish() {
        if (enabled_) std::fprintf(stderr, "\n");
    }

private:
    bool enabled_;
    std::chrono::steady_clock::time_point start_;
};

}  // namespace bb::cli
