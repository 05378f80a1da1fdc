#pragma once
/// \file parallel.h
/// Static split of an index range over threads. Each thread gets one contiguous block, so
/// any per-index result is the same whatever the thread count (deterministic output).

#include <algorithm>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace ib {

/// Threads to use when the caller asks for 0 (= all cores).
inline int DefaultThreads()
{
    return std::max(1u, std::thread::hardware_concurrency());
}

/// Calls f(begin, end, thread) on `threads` contiguous blocks of [0, n); blocks below
/// `grain` items are not worth a thread and run inline. Block 0 runs on the calling thread.
/// An exception thrown by f (a cancelled progress callback, out of memory) is rethrown here
/// once every thread has finished its block; the first one, by thread number, wins.
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
    std::vector<std::exception_ptr> failed(static_cast<size_t>(threads));
    auto run = [&](int t, size_t begin, size_t end) {
        try {
            f(begin, end, t);
        } catch (...) {
            failed[size_t(t)] = std::current_exception();
        }
    };
    std::vector<std::thread> pool;
    const size_t block = (n + threads - 1) / threads;
    for (int t = 1; t < threads; ++t)
        pool.emplace_back(run, t, std::min(n, t * block), std::min(n, (t + 1) * block));
    run(0, 0, std::min(n, block));
    for (auto& th : pool)
        th.join();
    for (const auto& e : failed)
        if (e)
            std::rethrow_exception(e);
}

} // namespace ib
