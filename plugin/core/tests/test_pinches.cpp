// Pinch resolution: the smaller fans at a vertex where separate fans of surface meet.
#include "boundaries.h"
#include "geometry.h"
#include "pinches.h"

#include <gtest/gtest.h>

using namespace ib;

namespace {
using test::AddTriangle;

/// Per face of the n × n Grid: 1 when its square (i, j) is one of `squares`.
std::vector<char> Squares(int n, const std::vector<std::pair<int, int>>& squares)
{
    std::vector<char> in(size_t(2 * n * n), 0);
    for (auto [i, j] : squares)
        in[size_t(2 * (j * n + i))] = in[size_t(2 * (j * n + i) + 1)] = 1;
    return in;
}
} // namespace

TEST(BoundarySteps, PinchKeepsTheLargerFan)
{
    // Three triangles around the origin on one side, one on the other: they meet only at (0,0,0).
    CoreMesh m;
    const vcg::Point3d o(0, 0, 0);
    AddTriangle(m, o, vcg::Point3d(1, 0, 0), vcg::Point3d(1, 1, 0));
    AddTriangle(m, o, vcg::Point3d(1, 1, 0), vcg::Point3d(0, 1, 0));
    AddTriangle(m, o, vcg::Point3d(0, 1, 0), vcg::Point3d(-0.2, 1, 0));
    AddTriangle(m, o, vcg::Point3d(-1, -1, 0), vcg::Point3d(0, -1, 0));
    vcg::tri::Clean<CoreMesh>::RemoveDuplicateVertex(m);
    vcg::tri::Allocator<CoreMesh>::CompactEveryVector(m);
    vcg::tri::UpdateTopology<CoreMesh>::FaceFace(m);
    std::vector<char> inSurface(4, 1);
    EXPECT_EQ(Pinches::Resolve(m, inSurface), 1u);
    EXPECT_EQ(inSurface, (std::vector<char>{1, 1, 1, 0}));
}

TEST(BoundarySteps, HoleFanTouchingTheSurfaceOnlyAtAVertexIsLeftOut)
{
    // Around the origin: a surface face (0), a hole face sharing its edge (1), and a larger
    // hole fan (2, 3) across an opening, touching both only at the origin.
    CoreMesh m;
    const vcg::Point3d o(0, 0, 0);
    AddTriangle(m, o, vcg::Point3d(1, 0, 0), vcg::Point3d(1, 1, 0));
    AddTriangle(m, o, vcg::Point3d(1, 1, 0), vcg::Point3d(0, 1, 0));
    AddTriangle(m, o, vcg::Point3d(-1, 0, 0), vcg::Point3d(-1, -1, 0));
    AddTriangle(m, o, vcg::Point3d(-1, -1, 0), vcg::Point3d(0, -1, 0));
    vcg::tri::Clean<CoreMesh>::RemoveDuplicateVertex(m);
    vcg::tri::Allocator<CoreMesh>::CompactEveryVector(m);
    vcg::tri::UpdateTopology<CoreMesh>::FaceFace(m);
    const std::vector<char> inSurface{1, 0, 0, 0};
    std::vector<char> inHoles{0, 1, 1, 1};
    // Alone, the holes layer would keep its larger fan and meet the surface in a bow-tie.
    std::vector<char> alone = inHoles;
    EXPECT_EQ(Pinches::Resolve(m, alone), 1u);
    EXPECT_EQ(alone, (std::vector<char>{0, 0, 1, 1}));
    EXPECT_EQ(Pinches::Resolve(m, inHoles, 8, &inSurface), 2u);
    EXPECT_EQ(inHoles, (std::vector<char>{0, 1, 0, 0}));
}

TEST(Pinches, ADiskHasNoPinch)
{
    CoreMesh m;
    test::Grid(4, 0.25, m);
    std::vector<char> inSurface(m.face.size(), 1);
    EXPECT_EQ(Pinches::Resolve(m, inSurface), 0u);
    EXPECT_EQ(std::count(inSurface.begin(), inSurface.end(), 1), 32);
    std::vector<char> ring = Squares(4, {{0, 0}, {1, 0}, {2, 0}, {2, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}});
    const std::vector<char> before = ring;  // a ring of squares around (1, 1): no pinch either
    EXPECT_EQ(Pinches::Resolve(m, ring), 0u);
    EXPECT_EQ(ring, before);
}

TEST(Pinches, DiagonalSquaresKeepOneSquareAndOneLoop)
{
    // Squares (1, 1) and (2, 2) of a grid (the other faces are holes) touch at one vertex:
    // their boundary passes that vertex twice. One square's two faces go.
    CoreMesh m;
    test::Grid(4, 0.25, m);
    std::vector<char> inSurface = Squares(4, {{1, 1}, {2, 2}});
    ASSERT_EQ(BoundaryLoops::Uses(m, BoundaryLoops::Compute(m, inSurface))[size_t(2 * 5 + 2)], 2);
    EXPECT_EQ(Pinches::Resolve(m, inSurface), 2u);
    EXPECT_EQ(std::count(inSurface.begin(), inSurface.end(), 1), 2);
    const auto loops = BoundaryLoops::Compute(m, inSurface);
    ASSERT_EQ(loops.size(), 1u);
    EXPECT_EQ(loops[0].Edges(), 4);
    std::vector<char> none = Squares(4, {{1, 1}, {2, 2}});  // no pass: nothing is removed
    EXPECT_EQ(Pinches::Resolve(m, none, 0), 0u);
    EXPECT_EQ(std::count(none.begin(), none.end(), 1), 4);
}
