#include "reconstruction_param.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <utility>
#include <vector>

using namespace ib;

namespace {
/// What Check() says about p, or "" when it accepts it.
std::string CheckMessage(const ReconstructionParam& p)
{
    try {
        p.Check();
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}
} // namespace

TEST(ReconstructionParam, DefaultsAndRangeEndsAreAccepted)
{
    ReconstructionParam p;
    EXPECT_EQ(CheckMessage(p), "");
    p.resolution = ReconstructionParam::kMinResolution;
    p.sods_dilation = 8;
    p.sample_radius = 0.25;
    p.boundary_trim = 0;
    p.normal_neighbours = 256;
    EXPECT_EQ(CheckMessage(p), "");
    p.resolution = ReconstructionParam::kMaxResolution;
    EXPECT_EQ(CheckMessage(p), "");
}

TEST(ReconstructionParam, EachParameterOutOfRangeIsNamedInTheMessage)
{
    using Change = std::function<void(ReconstructionParam&)>;
    const std::vector<std::pair<Change, std::string>> cases = {
        {[](auto& p) { p.resolution = 7; }, "Resolution 7 is out of range"},
        {[](auto& p) { p.resolution = 4097; }, "Resolution 4097 is out of range"},
        {[](auto& p) { p.sods_dilation = 9; }, "SODS dilation"},
        {[](auto& p) { p.sample_radius = 0.2; }, "sample radius"},
        {[](auto& p) { p.sample_radius = std::nan(""); }, "sample radius"},
        {[](auto& p) { p.boundary_smoothing = -1; }, "Boundary smoothing"},
        {[](auto& p) { p.boundary_trim = 9; }, "boundary trim"},
        {[](auto& p) { p.implicit = ReconstructionParam::Implicit::Given; }, "No implicit function"},
        {[](auto& p) { p.rbf.min_samples = 3; }, "minimum samples per cell"},
        {[](auto& p) { p.rbf.max_samples = 6000; }, "maximum samples per cell"},
        {[](auto& p) { p.rbf.overlap = 0.5; }, "overlap"},
        {[](auto& p) { p.rbf.off_surface = 0; }, "off-surface distance"},
        {[](auto& p) { p.memory_limit = -1; }, "memory limit"},
        {[](auto& p) { p.min_boundary_edges = -1; }, "minimum number of boundary edges"},
        {[](auto& p) { p.normal_neighbours = 2; }, "Normal neighbours"},
    };
    for (const auto& [change, expected] : cases) {
        ReconstructionParam p;
        change(p);
        const std::string message = CheckMessage(p);
        EXPECT_NE(message.find(expected), std::string::npos) << "expected \"" << expected << "\", got \"" << message << "\"";
    }
}
