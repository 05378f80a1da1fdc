// Outliers::Kept on generated point sets: strays alone or in small groups are found, surface
// samples are not, however uneven their density.

#include "outliers.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

using namespace ib;

namespace {

/// A flat square scan, z = 0: a coarse grid (spacing 0.1) on x < 0, a grid 10 times denser on
/// x >= 0 (the abrupt density change of a scan at a grazing angle next to a frontal one).
std::vector<Eigen::RowVector3d> UnevenPlane()
{
    std::vector<Eigen::RowVector3d> ps;
    for (double x = -2; x < 0; x += 0.1)
        for (double y = -2; y <= 2; y += 0.1)
            ps.emplace_back(x, y, 0);
    for (double x = 0; x <= 0.5; x += 0.01)
        for (double y = -0.5; y <= 0.5; y += 0.01)
            ps.emplace_back(x, y, 0);
    return ps;
}

Points Stack(const std::vector<Eigen::RowVector3d>& ps)
{
    Points P(Eigen::Index(ps.size()), 3);
    for (size_t i = 0; i < ps.size(); ++i)
        P.row(Eigen::Index(i)) = ps[i];
    return P;
}

} // namespace

TEST(Outliers, KeepsEverySampleOfAnUnevenScan)
{
    const Points P = Stack(UnevenPlane());
    EXPECT_EQ(Outliers::Kept(SampleIndex(P)).size(), size_t(P.rows()));
}

TEST(Outliers, FindsStraysAloneAndInSmallGroups)
{
    std::vector<Eigen::RowVector3d> ps = UnevenPlane();
    const size_t surface = ps.size();
    ps.emplace_back(0, 0, 100);  // far away
    ps.emplace_back(-1, 1, 0.7);  // above the coarse part, 7 spacings off
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(-2, 2);
    for (int i = 0; i < 3; ++i)   // a group of three, each the others' nearest
        ps.emplace_back(1.5 + 0.05 * i, 1.5, 1 + 0.05 * u(rng));
    const Points P = Stack(ps);
    const std::vector<Eigen::Index> kept = Outliers::Kept(SampleIndex(P));
    ASSERT_EQ(kept.size(), surface);
    for (size_t i = 0; i < surface; ++i)
        EXPECT_EQ(kept[i], Eigen::Index(i));
}

TEST(Outliers, FindsAScatterOfStraysThatClaimEachOther)
{
    // Twelve strays scattered a unit apart in the empty space beside the scan: each is among
    // the nearest of the others, so each is claimed, but as a group they are too few and too
    // sparse to be a surface.
    std::vector<Eigen::RowVector3d> ps = UnevenPlane();
    const size_t surface = ps.size();
    std::mt19937 rng(2);
    std::uniform_real_distribution<double> u(-0.3, 0.3);
    for (int i = 0; i < 12; ++i)
        ps.emplace_back(4 + (i % 3) + u(rng), 4 + (i / 3 % 2) + u(rng), 2 + (i / 6) + u(rng));
    const Points P = Stack(ps);
    const std::vector<Eigen::Index> kept = Outliers::Kept(SampleIndex(P));
    ASSERT_EQ(kept.size(), surface);
    EXPECT_EQ(kept.back(), Eigen::Index(surface - 1));
}

TEST(Outliers, FindsAScatterOfStraysLargerThanAGroupInTheBoxOfASheet)
{
    // A range scan is a sheet that leaves most of its bounding box empty: 0.1-0.5% of strays
    // drawn in that box are each other's nearest in groups larger than kMinGroup. They fill a
    // volume, as no surface does, however sparse.
    std::vector<Eigen::RowVector3d> ps;
    for (double x = -1; x <= 1; x += 0.02)
        for (double y = -1; y <= 1; y += 0.02)
            ps.emplace_back(x, y, 0);
    const size_t surface = ps.size();
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1, 1), w(0.5, 2);
    for (int i = 0; i < 50; ++i)
        ps.emplace_back(u(rng), u(rng), w(rng));
    const Points P = Stack(ps);
    const std::vector<Eigen::Index> kept = Outliers::Kept(SampleIndex(P));
    ASSERT_EQ(kept.size(), surface);
    EXPECT_EQ(kept.back(), Eigen::Index(surface - 1));
}

TEST(Outliers, KeepsASampleAloneInAGapOfTheSampling)
{
    // A gap 5 spacings wide in a curved sheet (z = x² / 2, grid spacing 0.1) with one sample at
    // its centre: the samples around the gap have their nearest on their own side, so nobody
    // claims it, but it lies on their sheet. One just as alone a spacing above it is a stray.
    std::vector<Eigen::RowVector3d> ps;
    for (double x = -1; x <= 1.001; x += 0.1)
        for (double y = -1; y <= 1.001; y += 0.1)
            if (x * x + y * y > 0.25 * 0.25)
                ps.emplace_back(x, y, 0.5 * x * x);
    ps.emplace_back(0, 0, 0);
    const Points sheet = Stack(ps);
    EXPECT_EQ(Outliers::Kept(SampleIndex(sheet)).size(), size_t(sheet.rows()));
    ps.back() = Eigen::RowVector3d(0, 0, 0.1);
    const Points above = Stack(ps);
    EXPECT_EQ(Outliers::Kept(SampleIndex(above)).size(), size_t(above.rows() - 1));
}

TEST(Outliers, FindsAStrayFarAwayInTheSheetsOwnPlane)
{
    // A flat scan and one sample about ten times its size away in its own plane: on the plane
    // its neighbours span, but nowhere among them.
    std::vector<Eigen::RowVector3d> ps = UnevenPlane();
    const size_t surface = ps.size();
    ps.emplace_back(40, 40, 0);
    const Points P = Stack(ps);
    EXPECT_EQ(Outliers::Kept(SampleIndex(P)).size(), surface);
}

TEST(Outliers, KeepsEveryOneOfFewSamples)
{
    const Points P = Stack({{0, 0, 0}, {1, 0, 0}, {100, 0, 0}});
    EXPECT_EQ(Outliers::Kept(SampleIndex(P)).size(), 3u);
}

TEST(Outliers, KeptRowsMapsASubsetsOutliersBackToItsRows)
{
    // The surface and two strays, of which only every second surface sample and the strays are
    // given as rows: the strays' own rows come out as outliers, after the ones already listed.
    std::vector<Eigen::RowVector3d> ps = UnevenPlane();
    const Eigen::Index surface = Eigen::Index(ps.size());
    ps.emplace_back(0, 0, 100);
    ps.emplace_back(-1, 1, 0.7);
    const Points P = Stack(ps);
    std::vector<Eigen::Index> rows;
    for (Eigen::Index i = 0; i < surface; i += 2)
        rows.push_back(i);
    rows.push_back(surface);
    rows.push_back(surface + 1);
    std::vector<Eigen::Index> outliers{7};
    const std::vector<Eigen::Index> kept = Outliers::KeptRows(P, rows, outliers, 1);
    EXPECT_EQ(outliers, (std::vector<Eigen::Index>{7, surface, surface + 1}));
    ASSERT_EQ(kept.size(), rows.size() - 2);
    EXPECT_TRUE(std::equal(kept.begin(), kept.end(), rows.begin()));
}
