#include "core/memory.h"

namespace bb {

MemoryTracker& MemoryTracker::gpu() {
    static MemoryTracker tracker;
    return tracker;
}

void MemoryTracker::allocate(int64_t bytes) {
    int64_t now = current_.fetch_add(bytes) + bytes;
    int64_t peak = peak_.load();
    while (now > peak && !peak_.compare_exchange_weak(peak, now)) {
    }
}

void MemoryTracker::release(int64_t bytes) { current_.fetch_sub(bytes); }

}  // namespace bb
