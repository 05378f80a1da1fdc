// The manifold check: fins lose their extra faces, bow ties are split, a flip is reported.
#include "geometry.h"
#include "manifold_check.h"

#include <vcg/complex/algorithms/create/platonic.h>

#include <gtest/gtest.h>

#include <array>

using namespace ib;

TEST(BoundarySteps, ManifoldCheckRepairsFinsAndBowTies)
{
    // Vertices 0..6; a fin: faces 0-1-2, 1-0-3 and 0-1-4 share edge 0-1 (the third face is
    // removed); a bow tie: 2-5-6 touches the rest at vertex 2 only (split into its own vertex).
    auto build = [](CoreMesh& m, const std::vector<std::array<int, 3>>& faces) {
        auto v = vcg::tri::Allocator<CoreMesh>::AddVertices(m, 7);
        const double xyz[7][3] = {{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, -1, 0}, {0.5, 0, 1}, {0, 2, 0}, {1, 2, 0}};
        for (int i = 0; i < 7; ++i)
            v[i].P() = vcg::Point3d(xyz[i][0], xyz[i][1], xyz[i][2]);
        for (const auto& f : faces)
            vcg::tri::Allocator<CoreMesh>::AddFace(m, &m.vert[size_t(f[0])], &m.vert[size_t(f[1])], &m.vert[size_t(f[2])]);
    };
    CoreMesh fin;
    build(fin, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
    auto r = ManifoldCheck::Repair(fin);
    EXPECT_GE(r.faces_removed, 1u);
    EXPECT_TRUE(r.manifold);
    EXPECT_EQ(test::Check(fin).non_manifold_edges, 0);

    CoreMesh bowTie;
    build(bowTie, {{0, 1, 2}, {1, 0, 3}, {2, 6, 5}});
    r = ManifoldCheck::Repair(bowTie);
    EXPECT_EQ(r.faces_removed, 0u);
    EXPECT_EQ(r.vertices_split, 1u);
    EXPECT_TRUE(r.manifold && r.oriented);
    EXPECT_EQ(bowTie.face.size(), 3u);

    CoreMesh flipped;  // one face turned against its neighbour: reported, not hidden
    build(flipped, {{0, 1, 2}, {0, 1, 3}});
    r = ManifoldCheck::Repair(flipped);
    EXPECT_TRUE(r.manifold);
    EXPECT_FALSE(r.oriented);
}

TEST(ManifoldCheck, LeavesAManifoldAlone)
{
    CoreMesh grid;
    test::Grid(3, 1.0, grid);
    auto r = ManifoldCheck::Repair(grid);
    EXPECT_EQ(r.faces_removed, 0u);
    EXPECT_EQ(r.vertices_split, 0u);
    EXPECT_TRUE(r.manifold && r.oriented);
    EXPECT_EQ(grid.face.size(), 18u);
    EXPECT_EQ(grid.vert.size(), 16u);

    CoreMesh closed;  // an octahedron: closed, no border
    vcg::tri::Octahedron(closed);
    r = ManifoldCheck::Repair(closed);
    EXPECT_EQ(r.faces_removed + r.vertices_split, 0u);
    EXPECT_TRUE(r.manifold && r.oriented);
    EXPECT_EQ(test::Check(closed).border_edges, 0);
}

TEST(ManifoldCheck, TwoSquaresMeetingAtACornerAreSplitApart)
{
    // Two grid squares touching at one vertex: that vertex is split in two, the 4 faces are
    // kept, and each square has its own 4 corners.
    CoreMesh m;
    test::Grid(2, 1.0, m);
    for (size_t f : {2u, 3u, 4u, 5u})  // squares (1, 0) and (0, 1) go: (0, 0) and (1, 1) stay
        vcg::tri::Allocator<CoreMesh>::DeleteFace(m, m.face[f]);
    vcg::tri::Clean<CoreMesh>::RemoveUnreferencedVertex(m);
    vcg::tri::Allocator<CoreMesh>::CompactEveryVector(m);
    ASSERT_EQ(m.vert.size(), 7u);
    const auto r = ManifoldCheck::Repair(m);
    EXPECT_EQ(r.faces_removed, 0u);
    EXPECT_EQ(r.vertices_split, 1u);
    EXPECT_TRUE(r.manifold && r.oriented);
    EXPECT_EQ(m.face.size(), 4u);
    EXPECT_EQ(m.vert.size(), 8u);
}
