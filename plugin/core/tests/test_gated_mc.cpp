#include "gated_mc.h"
#include "geometry.h"

#include <gtest/gtest.h>

using namespace ib;

namespace {
// A SODS covering every cell: gated extraction then equals plain marching cubes.
Sods AllCells(const Lattice& l)
{
    Sods s(l.cells);
    for (int z = 0; z < l.cells[2]; ++z)
        for (int y = 0; y < l.cells[1]; ++y)
            for (int x = 0; x < l.cells[0]; ++x)
                s.Insert(Index3(x, y, z));
    return s;
}
} // namespace

TEST(GatedMarchingCubes, SphereIsAClosedOrientedManifoldOnTheSphere)
{
    const Lattice l = Lattice::Fit(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1), 24, 2);
    CoreMesh m;
    const auto stats = GatedMarchingCubes::Compute(l, AllCells(l), test::SphereDistance(1.0), m);
    EXPECT_EQ(stats.evaluations, size_t(l.CornerCount()));
    ASSERT_GT(m.fn, 1000);

    double worst = 0;
    for (const auto& v : m.vert)
        worst = std::max(worst, std::abs(v.cP().Norm() - 1.0));
    EXPECT_LT(worst, 0.05 * l.cell_size);  // linear interpolation of an exact distance

    const auto t = test::Check(m);
    EXPECT_EQ(t.non_manifold_edges, 0);
    EXPECT_EQ(t.non_manifold_vertices, 0);
    EXPECT_EQ(t.border_edges, 0);
    EXPECT_TRUE(t.oriented);
    EXPECT_EQ(m.vn - (t.border_edges + 3 * m.fn) / 2 + m.fn, 2);  // Euler characteristic of a sphere

    // Normals point outwards (to positive values). The sphere passes exactly through some
    // lattice corners here, where marching cubes makes zero-area triangles with no direction.
    int inward = 0;
    for (auto& f : m.face)
        inward += vcg::TriangleNormal(f).dot(vcg::Barycenter(f)) < -1e-15;
    EXPECT_EQ(inward, 0);
}

TEST(GatedMarchingCubes, EmitsTrianglesOnlyInSodsCells)
{
    const Lattice l = Lattice::Fit(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1), 16, 2);
    Sods upper(l.cells);  // cells whose centre is above z = 0.3
    AllCells(l).ForEach([&](const Index3& c) {
        if (l.Corner(c[0], c[1], c[2])[2] + 0.5 * l.cell_size > 0.3)
            upper.Insert(c);
    });
    CoreMesh m;
    GatedMarchingCubes::Compute(l, upper, test::SphereDistance(1.0), m);
    ASSERT_GT(m.fn, 0);
    for (const auto& f : m.face)
        EXPECT_GT(vcg::Barycenter(f)[2], 0.3 - l.cell_size);
    const auto t = test::Check(m);
    EXPECT_EQ(t.non_manifold_edges, 0);
    EXPECT_GT(t.border_edges, 0);  // a spherical cap: open
}
