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
