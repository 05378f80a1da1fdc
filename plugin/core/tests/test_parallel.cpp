// ParallelFor: every index once, in contiguous blocks, exceptions rethrown on the caller.
#include "parallel.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

using namespace ib;

TEST(ParallelFor, RethrowsOnceEveryThreadHasFinished)
{
    std::vector<int> done(4, 0);
    auto work = [&](size_t begin, size_t end, int thread) {
        for (size_t i = begin; i < end; ++i)
            done[size_t(thread)] += 1;
        if (thread == 0 || thread == 2)
            throw std::runtime_error("block " + std::to_string(thread));
    };
    try {
        ParallelFor(4000, 4, work, 1000);
        FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "block 0");
    }
    EXPECT_EQ(done, (std::vector<int>{1000, 1000, 1000, 1000}));
}

TEST(ParallelFor, CoversEveryIndexOnceInContiguousBlocks)
{
    for (int threads : {1, 2, 3, 7}) {
        std::vector<int> seen(10007, 0), owner(10007, -1);
        ParallelFor(seen.size(), threads, [&](size_t begin, size_t end, int thread) {
            for (size_t i = begin; i < end; ++i) {
                ++seen[i];
                owner[i] = thread;
            }
        }, 100);
        EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), 10007) << threads;
        // Block t holds the indices of thread t: owners never decrease along the range.
        EXPECT_TRUE(std::is_sorted(owner.begin(), owner.end())) << threads;
        EXPECT_EQ(owner.front(), 0);
        EXPECT_EQ(owner.back(), threads - 1);
    }
}

TEST(ParallelFor, SmallRangesRunInlineOnTheCallingThread)
{
    const std::thread::id caller = std::this_thread::get_id();
    int calls = 0;
    ParallelFor(500, 4, [&](size_t begin, size_t end, int thread) {
        ++calls;
        EXPECT_EQ(begin, 0u);
        EXPECT_EQ(end, 500u);
        EXPECT_EQ(thread, 0);
        EXPECT_EQ(std::this_thread::get_id(), caller);
    });  // grain 1024: not worth a thread
    EXPECT_EQ(calls, 1);
    std::thread::id ran;
    ParallelFor(0, 0, [&](size_t begin, size_t end, int) {
        ran = std::this_thread::get_id();
        EXPECT_EQ(begin, end);
    });
    EXPECT_EQ(ran, caller);
    EXPECT_GE(DefaultThreads(), 1);
}
