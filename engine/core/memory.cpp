#include "core/memory.h"

#include <algorithm>

#include <sys/resource.h>

namespace bb {
namespace {
thread_local const char* tCategory = "other";
}

MemoryTracker& MemoryTracker::gpu() {
    static MemoryTracker tracker;
    return tracker;
}

const char* MemoryTracker::currentCategory() { return tCategory; }

void MemoryTracker::allocate(int64_t bytes, const char* category) {
    int64_t now = current_.fetch_add(bytes) + bytes;
    int64_t peak = peak_.load();
    while (now > peak && !peak_.compare_exchange_weak(peak, now)) {
    }
    std::lock_guard<std::mutex> lock(mutex_);
    Figures& f = categories_[category];
    f.current += bytes;
    f.peak = std::max(f.peak, f.current);
}

void MemoryTracker::release(int64_t bytes, const char* category) {
    current_.fetch_sub(bytes);
    std::lock_guard<std::mutex> lock(mutex_);
    categories_[category].current -= bytes;
}

void MemoryTracker::resetPeak() {
    peak_.store(current_.load());
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto& [name, f] : categories_) f.peak = f.current;
}

std::map<std::string, MemoryTracker::Figures> MemoryTracker::categories() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return categories_;
}

int64_t peakResidentBytes() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return int64_t(u.ru_maxrss) * 1024;  // KiB on Linux
}

MemoryCategory::MemoryCategory(const char* name) : previous_(tCategory) { tCategory = name; }
MemoryCategory::~MemoryCategory() { tCategory = previous_; }

}  // namespace bb
