// Mesh helpers: vertex positions, and the lean face-face adjacency against VCGlib's.
#include "gated_mc.h"
#include "geometry.h"
#include "mesh.h"

#include <vcg/complex/algorithms/create/platonic.h>

#include <gtest/gtest.h>

#include <array>

using namespace ib;

namespace {
/// UpdateFaceFace's adjacency equals vcg::tri::UpdateTopology::FaceFace's on m; returns the
/// number of border edges (an edge whose face across is its own).
int SameAdjacencyAsVcg(CoreMesh& m)
{
    UpdateFaceFace(m);
    std::vector<std::array<const CoreFace*, 3>> lean;
    std::vector<std::array<int, 3>> leanIndex;
    for (const auto& f : m.face) {
        lean.push_back({f.cFFp(0), f.cFFp(1), f.cFFp(2)});
        leanIndex.push_back({f.cFFi(0), f.cFFi(1), f.cFFi(2)});
    }
    vcg::tri::UpdateTopology<CoreMesh>::FaceFace(m);
    int borders = 0;
    for (size_t i = 0; i < m.face.size(); ++i)
        for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(lean[i][size_t(k)], m.face[i].cFFp(k)) << i << " " << k;
            EXPECT_EQ(leanIndex[i][size_t(k)], m.face[i].cFFi(k)) << i << " " << k;
            borders += m.face[i].cFFp(k) == &m.face[i];
        }
    return borders;
}
} // namespace

TEST(Mesh, PositionOfAndMoveVertexRoundTrip)
{
    CoreMesh m;
    vcg::tri::Allocator<CoreMesh>::AddVertices(m, 3);
    MoveVertex(m, 1, Eigen::Vector3d(0.25, -4, 1e-3));
    EXPECT_EQ(PositionOf(m, 1), Eigen::Vector3d(0.25, -4, 1e-3));
    EXPECT_EQ(m.vert[1].cP(), vcg::Point3d(0.25, -4, 1e-3));
    m.vert[2].P() = vcg::Point3d(7, 8, 9);
    EXPECT_EQ(PositionOf(m, 2), Eigen::Vector3d(7, 8, 9));
}

TEST(Mesh, LeanFaceFaceAdjacencyOnHandMadeMeshes)
{
    CoreMesh grid;  // open: 4 × 3 border edges
    test::Grid(3, 1.0, grid);
    EXPECT_EQ(SameAdjacencyAsVcg(grid), 12);
    CoreMesh closed;
    vcg::tri::Octahedron(closed);
    EXPECT_EQ(SameAdjacencyAsVcg(closed), 0);
    CoreMesh two;  // two triangles sharing an edge in opposite orientations (a flip)
    test::AddTriangle(two, vcg::Point3d(0, 0, 0), vcg::Point3d(1, 0, 0), vcg::Point3d(0, 1, 0));
    test::AddTriangle(two, vcg::Point3d(0, 0, 0), vcg::Point3d(1, 0, 0), vcg::Point3d(1, 1, 0));
    test::Weld(two);
    EXPECT_EQ(SameAdjacencyAsVcg(two), 4);
    UpdateFaceFace(two);
    EXPECT_EQ(two.face[0].cFFp(0), &two.face[1]);
}

TEST(Mesh, LeanFaceFaceAdjacencyOnAMarchingCubesCap)
{
    // An open cap (border edges) extracted by gated marching cubes, as the pipeline makes them.
    const Lattice l = Lattice::Fit(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1), 18, 2);
    Sods upper(l.cells);
    test::AllCells(l).ForEach([&](const Index3& c) {
        if (l.Corner(c[0], c[1], c[2])[2] > -0.2)
            upper.Insert(c);
    });
    CoreMesh m;
    GatedMarchingCubes::Param noHoles;
    noHoles.holes = false;
    GatedMarchingCubes::Compute(l, upper, test::SphereDistance(0.8), m, noHoles);
    EXPECT_GT(SameAdjacencyAsVcg(m), 20);
}
