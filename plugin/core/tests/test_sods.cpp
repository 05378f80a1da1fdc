#include "geometry.h"
#include "sods.h"

#include <Eigen/Geometry>

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
    const Sods s = Sods::FromSamples(UnitLattice(10), P);
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
    const Sods s = Sods::FromSamples(UnitLattice(10), P).Dilated();
    EXPECT_EQ(s.Count(), 27u);
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx)
                EXPECT_TRUE(s.Contains(Index3(4 + dx, 4 + dy, 4 + dz)));
    EXPECT_FALSE(s.Contains(Index3(6, 4, 4)));
    EXPECT_EQ(Sods::FromSamples(UnitLattice(10), P).Dilated().Dilated().Count(), 125u);
}

TEST(Sods, DilationIsClippedToTheLatticeAndCrossesBrickBorders)
{
    Points P(2, 3);
    P << 0.5, 0.5, 0.5,   // corner of the lattice: 8 cells after one ring
         7.5, 7.5, 7.5;   // last cell of brick (0,0,0): its neighbours lie in 8 bricks
    const Sods s = Sods::FromSamples(UnitLattice(20), P).Dilated();
    EXPECT_EQ(s.Count(), 8u + 27u);
    EXPECT_TRUE(s.Contains(Index3(8, 8, 8)));
    EXPECT_TRUE(s.Contains(Index3(6, 8, 7)));
}

TEST(Sods, CellsAreSortedAndUnique)
{
    Points P(4, 3);
    P << 9.5, 0.5, 0.5, 0.5, 9.5, 0.5, 0.5, 0.5, 9.5, 0.5, 0.5, 0.5;
    const auto cells = Sods::FromSamples(UnitLattice(16), P).Cells();
    ASSERT_EQ(cells.size(), 4u);
    EXPECT_EQ(cells[0], Index3(0, 0, 0));
    EXPECT_EQ(cells[1], Index3(9, 0, 0));
    EXPECT_EQ(cells[2], Index3(0, 9, 0));
    EXPECT_EQ(cells[3], Index3(0, 0, 9));
}

TEST(Sods, TangentDiskCoversItsPlaneOnly)
{
    // A disk of radius 2.2 around (5.5, 5.5, 5.5) in the plane z = 5.5: cells of the slab z = 5
    // whose centre is within 2.2 + half a cell diagonal; nothing above or below.
    Points P(1, 3), N(1, 3);
    P << 5.5, 5.5, 5.5;
    N << 0, 0, 1;
    const Sods s = Sods::FromDisks(UnitLattice(12), P, N, Eigen::VectorXd::Constant(1, 2.2), 0.0);
    EXPECT_TRUE(s.Contains(Index3(5, 5, 5)));
    EXPECT_TRUE(s.Contains(Index3(7, 5, 5)));
    EXPECT_TRUE(s.Contains(Index3(3, 6, 5)));
    EXPECT_FALSE(s.Contains(Index3(5, 5, 4)));
    EXPECT_FALSE(s.Contains(Index3(5, 5, 6)));
    EXPECT_FALSE(s.Contains(Index3(9, 5, 5)));
    s.ForEach([](const Index3& c) { EXPECT_EQ(c[2], 5); });
}

TEST(Sods, AnOpenDiskStopsAtItsSample)
{
    // The disk of TangentDiskCoversItsPlaneOnly, open towards +x: ahead it reaches half a cell
    // diagonal (cell centres up to x = 6.37), behind and sideways its full radius.
    Points P(1, 3), N(1, 3), open(1, 3);
    P << 5.5, 5.5, 5.5;
    N << 0, 0, 1;
    open << 1, 0, 0;
    const Eigen::VectorXd r = Eigen::VectorXd::Constant(1, 2.2);
    const Sods s = Sods::FromDisks(UnitLattice(12), P, N, r, 0.0, 1, Eigen::VectorXd(), Eigen::VectorXd(), 0, open);
    const Sods full = Sods::FromDisks(UnitLattice(12), P, N, r, 0.0, 1);
    EXPECT_TRUE(s.Contains(Index3(5, 5, 5)));
    EXPECT_FALSE(s.Contains(Index3(6, 5, 5)));
    EXPECT_TRUE(full.Contains(Index3(6, 5, 5)));
    EXPECT_TRUE(s.Contains(Index3(3, 5, 5)));
    EXPECT_TRUE(s.Contains(Index3(5, 7, 5)));
    s.ForEach([&](const Index3& c) { EXPECT_TRUE(full.Contains(c)); });
    EXPECT_LT(s.Count(), full.Count());
}

TEST(Sods, TangentDiskKeepsItsShapeOnFinerCells)
{
    // The disk of TangentDiskCoversItsPlaneOnly on cells 4 times finer (0.25), at least 0.5
    // thick and with the reach of unit cells: it reaches and is as thick as it is on unit
    // cells, in world units; without, only a quarter as thick.
    Points P(1, 3), N(1, 3);
    P << 5.5, 5.5, 5.5;
    N << 0, 0, 1;
    Lattice fine;
    fine.cell_size = 0.25;
    fine.cells = Index3(48, 48, 48);
    const Eigen::VectorXd r = Eigen::VectorXd::Constant(1, 2.2);
    const Sods shaped = Sods::FromDisks(fine, P, N, r, 0.0, 1, Eigen::VectorXd(), Eigen::VectorXd::Constant(1, 0.5), 1.0);
    const Sods flat = Sods::FromDisks(fine, P, N, r, 0.0, 1);
    // The cell centred 0.375 above the plane: within the unit-cell slab of 0.5, not within 0.125.
    EXPECT_TRUE(shaped.Contains(Index3(22, 22, 23)));
    EXPECT_FALSE(flat.Contains(Index3(22, 22, 23)));
    EXPECT_FALSE(shaped.Contains(Index3(22, 22, 24)));  // 0.625 above
    // Along the plane, the reach is 2.2 + the unit cell's half diagonal (0.87): the cell centred
    // 2.875 away is in, 3.125 is not; flat disks reach 2.2 + 0.22.
    EXPECT_TRUE(shaped.Contains(Index3(33, 22, 22)));
    EXPECT_FALSE(shaped.Contains(Index3(34, 22, 22)));
    EXPECT_FALSE(flat.Contains(Index3(32, 22, 22)));
    EXPECT_GT(shaped.Count(), 2 * flat.Count());
}

TEST(Sods, TangentDisksOfUniformSamplesLeaveNoGapAtFineCells)
{
    // Samples on a 1-spaced grid in a tilted plane, cells of 0.3: every cell the plane crosses
    // near the middle of the patch is covered by disks of radius 0.8 (more than the 0.71
    // covering radius of a unit square grid).
    const Eigen::Vector3d n = Eigen::Vector3d(0.2, 0.3, 1).normalized();
    const Eigen::Vector3d u = n.cross(Eigen::Vector3d::UnitX()).normalized(), v = n.cross(u);
    Points P(21 * 21, 3), N(21 * 21, 3);
    for (int i = 0; i < 21; ++i)
        for (int j = 0; j < 21; ++j) {
            P.row(i * 21 + j) = (Eigen::Vector3d::Constant(10) + (i - 10) * u + (j - 10) * v).transpose();
            N.row(i * 21 + j) = n.transpose();
        }
    Lattice l;
    l.cell_size = 0.3;
    l.cells = Index3(67, 67, 67);
    const Sods s = Sods::FromDisks(l, P, N, Eigen::VectorXd::Constant(P.rows(), 0.8), 0.0);
    int crossed = 0;
    for (int z = 0; z < 67; ++z)
        for (int y = 0; y < 67; ++y)
            for (int x = 0; x < 67; ++x) {
                const Eigen::Vector3d c = l.Corner(x, y, z) + Eigen::Vector3d::Constant(0.15) - Eigen::Vector3d::Constant(10);
                const double h = n.dot(c);
                const bool planeCrosses = std::abs(h) < 0.15 * n.cwiseAbs().sum() - 1e-9;  // not just touching
                const Eigen::Vector3d inPlane = c - h * n;
                if (planeCrosses && std::abs(inPlane.dot(u)) < 8 && std::abs(inPlane.dot(v)) < 8) {
                    ++crossed;
                    EXPECT_TRUE(s.Contains(Index3(x, y, z))) << x << " " << y << " " << z;
                }
            }
    EXPECT_GT(crossed, 2000);
}

TEST(Sods, TangentDisksAreTheSameOnOneAndTwoThreads)
{
    Points P, N;
    test::SpherePoints(20000, 1.0, P, N);
    const Lattice l = Lattice::Fit(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1), 80, 3);
    const Eigen::VectorXd r = Eigen::VectorXd::Constant(P.rows(), 0.03);
    const Sods one = Sods::FromDisks(l, P, N, r, 0.01, 1), two = Sods::FromDisks(l, P, N, r, 0.01, 2);
    EXPECT_GT(one.Count(), 10000u);
    EXPECT_EQ(one.Count(), two.Count());
    EXPECT_EQ(one.Cells(), two.Cells());
}
