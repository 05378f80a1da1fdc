// Sample spacing: exact on regular grids, the median, per scan of merged scans and their overlap.
#include "spacing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

using namespace ib;

namespace {
/// m × m samples of a square grid of spacing h at height z, from `corner`.
std::vector<Eigen::RowVector3d> Grid(int m, double h, double z, double corner = 0)
{
    std::vector<Eigen::RowVector3d> ps;
    for (int j = 0; j < m; ++j)
        for (int i = 0; i < m; ++i)
            ps.emplace_back(corner + i * h, corner + j * h, z);
    return ps;
}

Points Stack(const std::vector<Eigen::RowVector3d>& ps)
{
    Points P(Eigen::Index(ps.size()), 3);
    for (size_t i = 0; i < ps.size(); ++i)
        P.row(Eigen::Index(i)) = ps[i];
    return P;
}

/// On a square grid of spacing h, an inner sample's 8 nearest neighbours reach h sqrt 2:
/// sqrt(pi 2 h^2 / 8) = h sqrt(pi) / 2 (area per sample h^2 to within 11%).
double InnerSpacing(double h)
{
    return h * std::sqrt(M_PI) / 2;
}

/// Rows of the m × m grid at least two samples away from its sides.
bool Inner(int row, int m)
{
    const int i = row % m, j = row / m;
    return i >= 2 && j >= 2 && i < m - 2 && j < m - 2;
}
} // namespace

TEST(SampleSpacing, RegularGridGivesItsSpacing)
{
    const double h = 0.01;
    const Points P = Stack(Grid(30, h, 0));
    const SampleIndex samples(P);
    const Eigen::VectorXd spacing = SampleSpacing::Local(samples);
    ASSERT_EQ(spacing.size(), P.rows());
    for (Eigen::Index i = 0; i < P.rows(); ++i) {
        if (Inner(int(i), 30)) {
            EXPECT_NEAR(spacing[i], InnerSpacing(h), 1e-12) << i;
        }
        EXPECT_GE(spacing[i], InnerSpacing(h) - 1e-12) << i;  // fewer neighbours at the sides
        EXPECT_LT(spacing[i], 2 * h) << i;
    }
    EXPECT_NEAR(SampleSpacing::Median(spacing), InnerSpacing(h), 1e-12);
    // Every third sample; the same on two threads.
    const Eigen::VectorXd third = SampleSpacing::Local(samples, 3, 2);
    ASSERT_EQ(third.size(), 300);
    for (Eigen::Index i = 0; i < third.size(); ++i)
        EXPECT_EQ(third[i], spacing[3 * i]);
    // Scaling the samples scales the spacing.
    const Points Q = 3.0 * P;
    EXPECT_NEAR(SampleSpacing::Median(SampleSpacing::Local(SampleIndex(Q))), 3 * InnerSpacing(h), 1e-12);
}

TEST(SampleSpacing, NoiseAcrossTheSurfaceIsNotSpacingAlongIt)
{
    // The grid of spacing h with every sample moved up to 0.3 h off its plane: the 8 nearest
    // are still the inner ring's (their squared distances stay within h^2 + 0.36 h^2 and
    // 2 h^2 + 0.36 h^2, below the next ring's 4 h^2).
    const double h = 0.01;
    Points P = Stack(Grid(30, h, 0));
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> off(-0.15 * h, 0.15 * h);
    for (Eigen::Index i = 0; i < P.rows(); ++i)
        P(i, 2) = off(rng);
    const SampleIndex samples(P);
    Points N = Points::Zero(P.rows(), 3);
    N.col(2).setOnes();
    const Eigen::VectorXd along = SampleSpacing::Local(samples, 1, 1, &N), inSpace = SampleSpacing::Local(samples);
    for (Eigen::Index i = 0; i < P.rows(); ++i)
        if (Inner(int(i), 30)) {
            EXPECT_NEAR(along[i], InnerSpacing(h), 1e-12) << i;
        }
    EXPECT_GT(SampleSpacing::Median(inSpace), 1.002 * InnerSpacing(h));  // the offsets count there
    // A sample without a normal (a zero row) is measured in space.
    N.row(100).setZero();
    EXPECT_EQ(SampleSpacing::Local(samples, 1, 1, &N)[100], inSpace[100]);
}

TEST(SampleSpacing, MedianIsTheMiddleValue)
{
    EXPECT_EQ(SampleSpacing::Median((Eigen::VectorXd(3) << 3, 1, 2).finished()), 2);
    EXPECT_EQ(SampleSpacing::Median((Eigen::VectorXd(4) << 4, 1, 3, 2).finished()), 3);  // the upper middle
    EXPECT_EQ(SampleSpacing::Median((Eigen::VectorXd(5) << 1, 100, 1, 1, 1e9).finished()), 1);  // robust
}

TEST(SampleSpacing, PerScanMeasuresEachScanAmongItsOwnSamples)
{
    // Two scans of the same square, one twice as dense, interleaved; and a third scan of 5
    // samples, too few to measure alone.
    const double h = 0.02;
    std::vector<Eigen::RowVector3d> ps = Grid(40, h / 2, 0);
    const std::vector<Eigen::RowVector3d> coarse = Grid(20, h, 0, h / 4);
    ps.insert(ps.end(), coarse.begin(), coarse.end());
    for (int k = 0; k < 5; ++k)
        ps.emplace_back(0.1 + 0.003 * k, 0.1 + 0.001 * k, 0);
    const Points P = Stack(ps);
    std::vector<int> scan(ps.size(), 0);
    std::fill(scan.begin() + 1600, scan.end(), 1);
    std::fill(scan.end() - 5, scan.end(), 2);
    const SampleIndex samples(P);
    const Eigen::VectorXd own = SampleSpacing::PerScan(samples, scan, 2);
    const Eigen::VectorXd all = SampleSpacing::Local(samples);
    for (int i = 0; i < 1600; ++i)
        if (Inner(i, 40)) {
            EXPECT_NEAR(own[i], InnerSpacing(h / 2), 1e-12) << i;
        }
    for (int i = 0; i < 400; ++i)
        if (Inner(i, 20)) {
            EXPECT_NEAR(own[1600 + i], InnerSpacing(h), 1e-12) << i;
            EXPECT_LT(all[1600 + i], 0.7 * InnerSpacing(h)) << i;  // among the dense scan's samples
        }
    for (Eigen::Index i = 2000; i < 2005; ++i)
        EXPECT_EQ(own[i], all[i]);
    // One scan: the spacing among all samples.
    EXPECT_EQ(SampleSpacing::PerScan(samples, {}, 1), all);
}

TEST(SampleSpacing, OverlapCountsTheSheetsOfMergedScans)
{
    // Three scans of one unit square, 2,500 random samples each, lifted a registration error
    // apart: three sheets, three times the density.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<Eigen::RowVector3d> ps;
    std::vector<int> scan;
    for (int s = 0; s < 3; ++s)
        for (int i = 0; i < 2500; ++i) {
            ps.emplace_back(u(rng), u(rng), 0.002 * s);
            scan.push_back(s);
        }
    const Points P = Stack(ps);  // SampleIndex refers to it
    const SampleIndex samples(P);
    EXPECT_NEAR(SampleSpacing::Overlap(samples, SampleSpacing::PerScan(samples, scan, 2), 2), 3.0, 0.3);
    // One scan: no overlap, and never below 1.
    const Points single = Stack(Grid(30, 0.02, 0));
    const SampleIndex one(single);
    EXPECT_DOUBLE_EQ(SampleSpacing::Overlap(one, SampleSpacing::Local(one), 1), 1.0);
}
