#include "sods.h"

#include <gtest/gtest.h>

using namespace ib;

namespace {
Lattice UnitLattice(int n)
{
    Lattice l;
    l.cell_size = 1;
    l.cells = Index3(n, n, n);
    return l;
}
} // namespace

TEST(Sods, OccupiesTheCellsHoldingSamples)
{
    Points P(3, 3);
    P << 0.5, 0.5, 0.5,   // cell (0,0,0)
         0.7, 0.2, 0.9,   // same cell again
         5.5, 2.1, 7.9;   // cell (5,2,7)
    const Sods s = Sods::FromSamples(UnitLattice(10), P, 0);
    EXPECT_EQ(s.Count(), 2u);
    EXPECT_TRUE(s.Contains(Index3(0, 0, 0)));
    EXPECT_TRUE(s.Contains(Index3(5, 2, 7)));
    EXPECT_FALSE(s.Contains(Index3(1, 0, 0)));
    EXPECT_FALSE(s.Contains(Index3(-1, 0, 0)));
}

TEST(Sods, DilationAddsThe26Neighbourhood)
{
    Points P(1, 3);
    P << 4.5, 4.5, 4.5;
    const Sods s = Sods::FromSamples(UnitLattice(10), P, 1);
    EXPECT_EQ(s.Count(), 27u);
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx)
                EXPECT_TRUE(s.Contains(Index3(4 + dx, 4 + dy, 4 + dz)));
    EXPECT_FALSE(s.Contains(Index3(6, 4, 4)));
    EXPECT_EQ(Sods::FromSamples(UnitLattice(10), P, 2).Count(), 125u);
}

TEST(Sods, DilationIsClippedToTheLatticeAndCrossesBrickBorders)
{
    Points P(2, 3);
    P << 0.5, 0.5, 0.5,   // corner of the lattice: 8 cells after one ring
         7.5, 7.5, 7.5;   // last cell of brick (0,0,0): its neighbours lie in 8 bricks
    const Sods s = Sods::FromSamples(UnitLattice(20), P, 1);
    EXPECT_EQ(s.Count(), 8u + 27u);
    EXPECT_TRUE(s.Contains(Index3(8, 8, 8)));
    EXPECT_TRUE(s.Contains(Index3(6, 8, 7)));
}

TEST(Sods, CellsAreSortedAndUnique)
{
    Points P(4, 3);
    P << 9.5, 0.5, 0.5, 0.5, 9.5, 0.5, 0.5, 0.5, 9.5, 0.5, 0.5, 0.5;
    const auto cells = Sods::FromSamples(UnitLattice(16), P, 0).Cells();
    ASSERT_EQ(cells.size(), 4u);
    EXPECT_EQ(cells[0], Index3(0, 0, 0));
    EXPECT_EQ(cells[1], Index3(9, 0, 0));
    EXPECT_EQ(cells[2], Index3(0, 9, 0));
    EXPECT_EQ(cells[3], Index3(0, 0, 9));
}
