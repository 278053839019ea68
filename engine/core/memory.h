// One tracker for every GPU allocation (pbrt's tracked memory resource idea):
// buffers and textures report their bytes on creation and release, under the
// category in scope when they were made (MemoryCategory); stats print the
// peaks, tests hold them against the memory predictor.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>

namespace bb {

class MemoryTracker {
public:
    struct Figures {
        int64_t current = 0;
        int64_t peak = 0;
    };
    static MemoryTracker& gpu();
    void allocate(int64_t bytes, const char* category);
    void release(int64_t bytes, const char* category);
    int64_t current() const { return current_.load(); }
    int64_t peak() const { return peak_.load(); }
    void resetPeak();
    // Per category (the names given to MemoryCategory), since the last resetPeak.
    std::map<std::string, Figures> categories() const;
    // The category allocations are filed under on this thread ("other" outside any scope).
    static const char* currentCategory();

private:
    std::atomic<int64_t> current_{0};
    std::atomic<int64_t> peak_{0};
    mutable std::mutex mutex_;
    std::map<std::string, Figures> categories_;
};

// The process's peak resident set (getrusage), bytes.
int64_t peakResidentBytes();

// GPU allocations made while it lives are filed under `name` (a string literal).
class MemoryCategory {
public:
    explicit MemoryCategory(const char* name);
    ~MemoryCategory();
    MemoryCategory(const MemoryCategory&) = delete;
    MemoryCategory& operator=(const MemoryCategory&) = delete;

private:
    const char* previous_;
};

}  // namespace bb
