// The memory budget: the peak model, and the refusal over the limit with what to change.
// lattice.h first: input_check.h uses its Points without including it.
#include "lattice.h"
#include "memory_budget.h"

#include <gtest/gtest.h>

#include <string>

using namespace ib;

namespace {
std::string Refusal(double samples, double cells, bool dense, double corners, double limit, int resolution)
{
    try {
        MemoryBudget::Check(samples, cells, dense, corners, limit, resolution);
    } catch (const InputError& e) {
        return e.what();
    }
    return "accepted";
}
} // namespace

TEST(MemoryBudget, PeakIsTheLinearModelAndGrowsWithEachTerm)
{
    EXPECT_EQ(MemoryBudget::PeakBytes(0, 0, 0), MemoryBudget::kBytesFixed);
    EXPECT_DOUBLE_EQ(MemoryBudget::PeakBytes(1000, 2000, 3000), 30e6 + 380e3 + 540e3 + 24e3);
    const double base = MemoryBudget::PeakBytes(1e6, 1e6, 1e6);
    EXPECT_GT(MemoryBudget::PeakBytes(2e6, 1e6, 1e6), base);
    EXPECT_GT(MemoryBudget::PeakBytes(1e6, 2e6, 1e6), base);
    EXPECT_GT(MemoryBudget::PeakBytes(1e6, 1e6, 2e6), base);
    EXPECT_GT(MemoryBudget::Default(), 0);
    MemoryBudget::ReleaseFreed();
}

TEST(MemoryBudget, CheckReturnsTheEstimateUnderTheLimit)
{
    EXPECT_EQ(MemoryBudget::Check(1e5, 1e6, false, 1e9, 1e9, 200), MemoryBudget::PeakBytes(1e5, 1e6, 0));
    EXPECT_EQ(MemoryBudget::Check(1e5, 1e6, true, 1e7, 1e9, 200), MemoryBudget::PeakBytes(1e5, 1e6, 1e7));
    const double exact = MemoryBudget::PeakBytes(1e5, 1e6, 0);
    EXPECT_EQ(MemoryBudget::Check(1e5, 1e6, false, 0, exact, 200), exact);  // at the limit: accepted
}

TEST(MemoryBudget, RefusalSaysHowMuchAndWhatToChange)
{
    // 2M samples and 10M cells: 30 MB + 760 MB + 2.7 GB = 3.49 GB, over a 2 GB limit.
    const std::string sods = Refusal(2e6, 1e7, false, 0, 2e9, 900);
    EXPECT_EQ(sods, "Resolution 900 would need about 3.49 GB of memory (2000000 samples, 10000000 occupied "
                    "cells), over the limit of 2.00 GB: lower the resolution (0 = automatic) or raise the "
                    "memory limit.");
    const std::string dense = Refusal(1e6, 1e5, true, 1e9, 2e9, 1000);
    EXPECT_NE(dense.find("1000000000 lattice corners"), std::string::npos) << dense;
    EXPECT_NE(dense.find("use the SODS-driven extraction"), std::string::npos) << dense;
    // The samples alone over the limit: no resolution helps.
    const std::string samples = Refusal(2e7, 1e3, false, 0, 1e9, 100);
    EXPECT_NE(samples.find("the samples alone need about 7.63 GB; thin them out"), std::string::npos) << samples;
    EXPECT_EQ(samples.find("lower the resolution"), std::string::npos) << samples;
}
