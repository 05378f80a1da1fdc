// The lattice: Fit pads and centres, corners and cells round-trip, packed keys.
#include "lattice.h"

#include <gtest/gtest.h>

#include <algorithm>

using namespace ib;

TEST(Lattice, FitPadsEverySideAndCentresTheBox)
{
    // Extents 4, 2 and 0.75 at 8 cells along the longest: cells of 0.5 (exact in binary).
    const Eigen::Vector3d lo(1, -2, 0.5), hi(5, 0, 1.25);
    const Lattice l = Lattice::Fit(lo, hi, 8, 2);
    EXPECT_EQ(l.cell_size, 0.5);
    EXPECT_EQ(l.cells, Index3(8 + 4, 4 + 4, 2 + 4));
    EXPECT_EQ(l.origin, Eigen::Vector3d(0, -3, -0.625));
    const Eigen::Vector3d centre = l.origin + 0.5 * l.cell_size * l.cells.cast<double>();
    EXPECT_EQ(centre, 0.5 * (lo + hi));
    EXPECT_EQ(l.CornerCount(), 13.0 * 9.0 * 7.0);

    // A flat box still gets one cell across, plus the padding.
    const Lattice flat = Lattice::Fit(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 1, 0), 4, 1);
    EXPECT_EQ(flat.cells, Index3(4 + 2, 2 + 2, 1 + 2));
    EXPECT_EQ(flat.origin[2], -0.75);
}

TEST(Lattice, CornersAndCellsRoundTrip)
{
    const Lattice l = Lattice::Fit(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 2, 3), 10, 1);
    for (int z = 0; z < l.cells[2]; ++z)
        for (int y = 0; y < l.cells[1]; ++y)
            for (int x = 0; x < l.cells[0]; ++x) {
                const Index3 c(x, y, z);
                ASSERT_TRUE(l.ContainsCell(c));
                const Eigen::Vector3d corner = l.Corner(x, y, z);
                EXPECT_NEAR((corner - (l.origin + l.cell_size * c.cast<double>())).norm(), 0, 1e-12);
                EXPECT_EQ(l.CellOf(corner + Eigen::Vector3d::Constant(0.5 * l.cell_size)), c);
                EXPECT_EQ(l.CellOf(l.Corner(x + 1, y + 1, z + 1) - Eigen::Vector3d::Constant(1e-9)), c);
            }
    // Points outside are clamped into the lattice; cells outside are not contained.
    EXPECT_EQ(l.CellOf(Eigen::Vector3d(-100, 0.1, 100)), Index3(0, l.CellOf(Eigen::Vector3d(0, 0.1, 0))[1], l.cells[2] - 1));
    EXPECT_FALSE(l.ContainsCell(Index3(-1, 0, 0)));
    EXPECT_FALSE(l.ContainsCell(Index3(0, l.cells[1], 0)));
    EXPECT_TRUE(l.ContainsCell(l.cells - Index3::Ones()));
}

TEST(Lattice, PackedKeysRoundTripAndSortByZYX)
{
    const int top = (1 << 20) - 1;
    for (const Index3& c : {Index3(0, 0, 0), Index3(1, 2, 3), Index3(top, 0, top), Index3(top, top, top),
                            Index3(Lattice::kMaxCells, 7, 0)})
        EXPECT_EQ(UnpackIndex(PackIndex(c[0], c[1], c[2])), c);
    EXPECT_LT(PackIndex(top, 0, 0), PackIndex(0, 1, 0));
    EXPECT_LT(PackIndex(top, top, 0), PackIndex(0, 0, 1));
    EXPECT_LT(PackIndex(5, 3, 2), PackIndex(6, 3, 2));
    EXPECT_EQ(PackIndex(top, top, top) >> 60, 0u);  // 4 bits left for edge keys
}

TEST(Lattice, LatticesOnOneGridShareTheirCornersBitForBit)
{
    // Two overlapping boxes on one grid (two tiles of a scan): each covers its box, with the
    // padding, and a grid corner both hold has the same coordinates, to the last bit, in both.
    const Eigen::Vector3d origin(-1.3, 0.7, 2.1);
    const double cell = 0.0371;
    const Lattice a = Lattice::OnGrid(origin, cell, Eigen::Vector3d(-1, 1, 2.5), Eigen::Vector3d(0.2, 1.4, 2.9), 2);
    const Lattice b = Lattice::OnGrid(origin, cell, Eigen::Vector3d(-0.1, 0.9, 2.6), Eigen::Vector3d(0.8, 1.9, 3.3), 2);
    for (const Lattice* l : {&a, &b}) {
        EXPECT_TRUE((l->Corner(2, 2, 2).array() <= Eigen::Array3d(l == &a ? -1 : -0.1, l == &a ? 1 : 0.9, l == &a ? 2.5 : 2.6)).all());
        EXPECT_EQ(l->CellOf(l->Corner(3, 4, 5) + Eigen::Vector3d::Constant(0.5 * cell)), Index3(3, 4, 5));
    }
    EXPECT_TRUE((a.Corner(a.cells[0] - 2, a.cells[1] - 2, a.cells[2] - 2).array() >= Eigen::Array3d(0.2, 1.4, 2.9)).all());
    int shared = 0;
    for (int z = 0; z <= a.cells[2]; ++z)
        for (int y = 0; y <= a.cells[1]; ++y)
            for (int x = 0; x <= a.cells[0]; ++x) {
                const Index3 g = a.first + Index3(x, y, z), inB = g - b.first;
                if ((inB.array() < 0).any() || (inB.array() > b.cells.array()).any())
                    continue;
                const Eigen::Vector3d pa = a.Corner(x, y, z), pb = b.Corner(inB[0], inB[1], inB[2]);
                ASSERT_TRUE(pa == pb) << "grid corner " << g.transpose();
                ++shared;
            }
    EXPECT_GT(shared, 1000);
    // A lattice fitted to its samples is the grid from its own origin on.
    const Lattice fit = Lattice::Fit(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 2, 3), 10, 1);
    EXPECT_EQ(fit.first, Index3::Zero());
}
