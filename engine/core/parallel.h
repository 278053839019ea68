// Independent tasks on every core: body(i) for i in [0, count), each task
// writing only its own results, so the results do not depend on the order.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
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

}  // namespace bb
