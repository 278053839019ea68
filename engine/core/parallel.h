// Independent tasks on every core: body(i) for i in [0, count), each task
// writing only its own results, so the results do not depend on the order.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <thread>
#include <vector>

namespace bb {

template <class Body>
void parallelFor(size_t count, Body&& body, size_t maxThreads = 16) {
    std::atomic<size_t> next{0};
    auto work = [&]() {
        for (size_t i; (i = next++) < count;) body(i);
    };
    const size_t threads = std::min<size_t>({std::max(1u, std::thread::hardware_concurrency()), count, maxThreads});
    std::vector<std::thread> pool;
    for (size_t k = 1; k < threads; ++k) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();
}

// How many tasks of `bytesPerTask` transient memory each may run at once
// within 2 GiB (at least one, at most a thread a core): one 8192^2 light-map
// page's owners, footprints and cells alone take ~4 GiB.
inline size_t threadsWithin(int64_t bytesPerTask) {
    const int64_t fit = (int64_t(2) << 30) / std::max<int64_t>(bytesPerTask, 1);
    return size_t(std::clamp<int64_t>(std::min<int64_t>(fit, std::max(1u, std::thread::hardware_concurrency())), 1, 16));
}

}  // namespace bb
