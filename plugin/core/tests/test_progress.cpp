// Progress ranges and cancellation through VCG's plain function-pointer callback; stage timing.
#include "progress.h"

#include <gtest/gtest.h>

#include <string>
#include <thread>
#include <vector>

using namespace ib;

namespace {
std::vector<int> g_positions;
std::string g_what;
bool g_answer = true;
bool Record(const int pos, const char* what)
{
    g_positions.push_back(pos);
    g_what = what;
    return g_answer;
}
} // namespace

TEST(Progress, RangeMapsZeroToHundredIntoItsSpan)
{
    EXPECT_EQ(ProgressRange::Into(nullptr, 10, 20), nullptr);
    g_positions.clear();
    g_answer = true;
    vcg::CallBackPos* cb = ProgressRange::Into(&Record, 40, 96);
    ASSERT_NE(cb, nullptr);
    for (int pos : {0, 25, 50, 100, 150, -5})
        EXPECT_TRUE(cb(pos, "fitting"));
    EXPECT_EQ(g_positions, (std::vector<int>{40, 54, 68, 96, 96, 40}));  // clamped outside 0..100
    EXPECT_EQ(g_what, "fitting");
    g_answer = false;  // the host's "stop" is passed back, not turned into an exception
    EXPECT_FALSE(cb(10, "x"));
    g_answer = true;
}

TEST(Progress, CancellationTurnsStopIntoAnException)
{
    EXPECT_EQ(Cancellation::Watch(nullptr), nullptr);
    g_positions.clear();
    g_answer = true;
    vcg::CallBackPos* cb = Cancellation::Watch(&Record);
    ASSERT_NE(cb, nullptr);
    EXPECT_TRUE(cb(33, "extracting"));
    EXPECT_EQ(g_positions, std::vector<int>{33});
    EXPECT_EQ(g_what, "extracting");
    g_answer = false;
    EXPECT_THROW(cb(34, "extracting"), Cancelled);
    // Through a range too: the stage's report reaches the watch, which throws.
    vcg::CallBackPos* stage = ProgressRange::Into(Cancellation::Watch(&Record), 0, 50);
    try {
        stage(100, "stage");
        FAIL() << "no exception";
    } catch (const Cancelled& e) {
        EXPECT_STREQ(e.what(), "cancelled");
    }
    EXPECT_EQ(g_positions.back(), 50);
    g_answer = true;
}

TEST(Progress, StopwatchLapsAreTheStagesOwnTimes)
{
    Stopwatch watch;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const double first = watch.Lap();  // includes the 20 ms
    const double second = watch.Lap(); // only the time since the first lap, no sleep in it
    EXPECT_GE(first, 0.02);
    EXPECT_GE(second, 0.0);
    EXPECT_LT(second, first);
}
