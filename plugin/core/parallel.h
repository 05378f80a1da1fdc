#pragma once
/// \file parallel.h
/// Static split of an index range over threads. Each thread gets one contiguous block, so
/// any per-index result is the same whatever the thread count (deterministic output).

#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

namespace ib {

/// Threads to use when the caller asks for 0 (= all cores).
inline int DefaultThreads()
{
    return std::max(1u, std::thread::hardware_concurrency());
}

/// Calls f(begin, end, thread) on `threads` contiguous blocks of [0, n); blocks below
/// `grain` items are not worth a thread and run inline.
template <class F>
void ParallelFor(size_t n, int threads, F&& f, size_t grain = 1024)
{
    if (threads <= 0)
        threads = DefaultThreads();
    threads = int(std::min<size_t>(threads, std::max<size_t>(1, n / grain)));
    if (threads <= 1) {
        f(size_t(0), n, 0);
        return;
    }
    std::vector<std::thread> pool;
    const size_t block = (n + threads - 1) / threads;
    for (int t = 1; t < threads; ++t)
        pool.emplace_back([&, t] { f(std::min(n, t * block), std::min(n, (t + 1) * block), t); });
    f(0, std::min(n, block), 0);
    for (auto& th : pool)
        th.join();
}

} // namespace ib
