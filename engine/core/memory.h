// One tracker for every GPU allocation (pbrt's tracked memory resource idea):
// buffers and textures report their bytes on creation and release, stats
// print the peak, tests hold it against the memory predictor.
#pragma once

#include <atomic>
#include <cstdint>

namespace bb {

class MemoryTracker {
public:
    static MemoryTracker& gpu();
    void allocate(int64_t bytes);
    void release(int64_t bytes);
    int64_t current() const { return current_.load(); }
    int64_t peak() const { return peak_.load(); }
    void resetPeak() { peak_.store(current_.load()); }

private:
    std::atomic<int64_t> current_{0};
    std::atomic<int64_t> peak_{0};
};

}  // namespace bb
