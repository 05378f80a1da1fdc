// The edges of merged scans: samples on a scan's rim or around a hole in it are its edge, and
// an edge sample is covered when another scan's samples, off their own edge, lie over it.
#include "geometry.h"
#include "scan_edges.h"

#include <gtest/gtest.h>

#include <algorithm>

using namespace ib;
using test::FlatScan;

TEST(ScanEdges, TheRimOfAScanAndOfAHoleInItAreItsEdge)
{
    const double s = 0.02;
    Points grid, N0;
    FlatScan(s, grid, N0);
    // A round hole of radius 0.1 in the middle.
    std::vector<Eigen::Index> keep;
    for (Eigen::Index i = 0; i < grid.rows(); ++i)
        if ((grid.row(i) - Eigen::RowVector3d(0.5, 0.5, 0)).norm() > 0.1)
            keep.push_back(i);
    const Points P = grid(keep, Eigen::all), N = N0(keep, Eigen::all);
    const SampleIndex samples(P);
    const std::vector<char> edge = ScanEdges::Edges(samples, N, std::vector<int>(size_t(P.rows()), 0), 1);
    size_t rim = 0, hole = 0, inner = 0;
    for (Eigen::Index i = 0; i < P.rows(); ++i) {
        const double x = P(i, 0), y = P(i, 1), r = (P.row(i) - Eigen::RowVector3d(0.5, 0.5, 0)).norm();
        const bool onRim = std::min({x, y, 1 - x, 1 - y}) < 0.5 * s, byHole = r < 0.1 + 0.6 * s;
        if (onRim)
            rim += !edge[size_t(i)];
        else if (byHole)
            hole += !edge[size_t(i)];
        else if (std::min({x, y, 1 - x, 1 - y}) > 2 * s && r > 0.1 + 2 * s)
            inner += edge[size_t(i)];
    }
    EXPECT_EQ(rim, 0u);    // every sample on the square's rim is an edge sample
    EXPECT_EQ(hole, 0u);   // and every sample on the hole's rim
    EXPECT_EQ(inner, 0u);  // none two spacings inside
}

TEST(ScanEdges, AnEdgeIsCoveredWhereAnotherScanLiesOverIt)
{
    // Scan 0: [0, 1]^2; scan 1: [0.25, 0.75] x [-0.25, 0.25], as dense, half a spacing above
    // (registration error): it straddles scan 0's bottom edge. Scan 0's bottom edge is covered
    // where scan 1 lies over it and not elsewhere; scan 1's top edge lies over scan 0's inside
    // and is covered, its bottom edge lies over nothing.
    const double s = 0.02;
    Points a, Na, b, Nb;
    FlatScan(s, a, Na);
    FlatScan(2 * s, b, Nb);
    b = (0.5 * b).rowwise() + Eigen::RowVector3d(0.25, -0.25, 0.5 * s);
    Points P(a.rows() + b.rows(), 3), N(a.rows() + b.rows(), 3);
    P << a, b;
    N << Na, Nb;
    std::vector<int> scan(size_t(P.rows()), 0);
    std::fill(scan.begin() + a.rows(), scan.end(), 1);
    const SampleIndex samples(P);
    const std::vector<char> edge = ScanEdges::Edges(samples, N, scan, 1);
    const std::vector<char> covered = ScanEdges::Covered(samples, edge, scan, Eigen::VectorXd::Constant(P.rows(), s), 1);
    struct Count { size_t samples = 0, covered = 0; };
    Count over, beside, top, bottom;  // scan 0's bottom edge over / beside scan 1; scan 1's top and bottom edges
    for (Eigen::Index i = 0; i < P.rows(); ++i) {
        EXPECT_TRUE(edge[size_t(i)] || !covered[size_t(i)]) << i;  // only edge samples are covered
        const double x = P(i, 0), y = P(i, 1);
        const bool inside = x > 0.25 + 2 * s && x < 0.75 - 2 * s, outside = x < 0.25 - 2 * s || x > 0.75 + 2 * s;
        Count* c = nullptr;
        if (scan[size_t(i)] == 0 && y < 0.5 * s)
            c = inside ? &over : outside ? &beside : nullptr;
        else if (scan[size_t(i)] == 1 && inside && y > 0.25 - 0.5 * s)
            c = &top;
        else if (scan[size_t(i)] == 1 && inside && y < -0.25 + 0.5 * s)
            c = &bottom;
        if (c) {
            EXPECT_TRUE(edge[size_t(i)]) << P.row(i);
            ++c->samples;
            c->covered += covered[size_t(i)];
        }
    }
    EXPECT_GT(over.samples, 15u);
    EXPECT_EQ(over.covered, over.samples);
    EXPECT_GT(beside.samples, 15u);
    EXPECT_EQ(beside.covered, 0u);
    EXPECT_GT(top.samples, 15u);
    EXPECT_EQ(top.covered, top.samples);
    EXPECT_GT(bottom.samples, 15u);
    EXPECT_EQ(bottom.covered, 0u);
}

TEST(ScanEdges, UncoveredListsEverySampleButTheCoveredEdges)
{
    // Scan 1, as dense, over scan 0's right half, a quarter spacing above: scan 0's right edge
    // and scan 1's left edge lie over the other scan's inside.
    const double s = 0.02;
    Points a, Na;
    FlatScan(s, a, Na);
    const Points b = a.rowwise() + Eigen::RowVector3d(0.5, 0, 0.25 * s);
    Points P(2 * a.rows(), 3), N(2 * a.rows(), 3);
    P << a, b;
    N << Na, Na;
    std::vector<int> scan(size_t(P.rows()), 0);
    std::fill(scan.begin() + a.rows(), scan.end(), 1);
    const SampleIndex samples(P);
    const Eigen::VectorXd spacing = Eigen::VectorXd::Constant(P.rows(), s);
    const std::vector<char> covered =
        ScanEdges::Covered(samples, ScanEdges::Edges(samples, N, scan, 1), scan, spacing, 1);
    const std::vector<Eigen::Index> rows = ScanEdges::Uncovered(samples, N, scan, spacing, 1);
    const size_t coveredCount = size_t(std::count(covered.begin(), covered.end(), 1));
    EXPECT_GT(coveredCount, 50u);  // the two edges that lie over the other scan, ~50 samples each
    ASSERT_EQ(rows.size(), size_t(P.rows()) - coveredCount);
    EXPECT_TRUE(std::is_sorted(rows.begin(), rows.end()));
    for (Eigen::Index i : rows)
        EXPECT_FALSE(covered[size_t(i)]) << P.row(i);
}
