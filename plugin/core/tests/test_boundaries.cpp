// Boundary loops: counted, measured and oriented on hand-made meshes.
#include "boundaries.h"
#include "geometry.h"

#include <vcg/complex/algorithms/create/platonic.h>

#include <gtest/gtest.h>

#include <array>

using namespace ib;

namespace {
/// Per face of the n × n Grid: 0 in the squares [i0, i1) × [j0, j1) of each hole, else 1.
std::vector<char> WithHoles(int n, const std::vector<std::array<int, 4>>& holes)
{
    std::vector<char> in(size_t(2 * n * n), 1);
    for (const auto& h : holes)
        for (int j = h[2]; j < h[3]; ++j)
            for (int i = h[0]; i < h[1]; ++i)
                in[size_t(2 * (j * n + i))] = in[size_t(2 * (j * n + i) + 1)] = 0;
    return in;
}

/// Twice the signed area of the loop's projection on the plane z = 0.
double SignedArea(const CoreMesh& m, const BoundaryLoop& loop)
{
    double area = 0;
    for (size_t i = 0; i < loop.vertices.size(); ++i) {
        const Eigen::Vector3d a = PositionOf(m, loop.vertices[i]);
        const Eigen::Vector3d b = PositionOf(m, loop.vertices[(i + 1) % loop.vertices.size()]);
        area += a[0] * b[1] - a[1] * b[0];
    }
    return area;
}
} // namespace

TEST(BoundaryLoops, ADiskWithTwoHolesHasThreeLoops)
{
    // A 10 × 10 grid of squares of 0.1 with a 2 × 3 hole and a 1 × 1 hole.
    CoreMesh m;
    test::Grid(10, 0.1, m);
    const std::vector<char> surface = WithHoles(10, {{2, 4, 2, 5}, {7, 8, 7, 8}});
    const auto loops = BoundaryLoops::Compute(m, surface);
    ASSERT_EQ(loops.size(), 3u);
    EXPECT_EQ(loops[0].Edges(), 40);  // largest first
    EXPECT_EQ(loops[1].Edges(), 10);
    EXPECT_EQ(loops[2].Edges(), 4);
    EXPECT_NEAR(loops[0].length, 4.0, 1e-12);
    EXPECT_NEAR(loops[1].length, 1.0, 1e-12);
    EXPECT_NEAR(loops[2].length, 0.4, 1e-12);
    EXPECT_NEAR(BoundaryLoops::Length(m, loops[1]), loops[1].length, 1e-15);
    // Following the faces' orientation (counter-clockwise from +z): the rim runs
    // counter-clockwise, the holes clockwise.
    EXPECT_NEAR(SignedArea(m, loops[0]), 2 * 1.0, 1e-12);
    EXPECT_NEAR(SignedArea(m, loops[1]), -2 * 0.06, 1e-12);
    EXPECT_NEAR(SignedArea(m, loops[2]), -2 * 0.01, 1e-12);
    // Across the rim: the mesh's border (-1); across a hole's edge: a face out of the surface.
    for (int face : loops[0].across)
        EXPECT_EQ(face, -1);
    for (const auto& loop : {loops[1], loops[2]}) {
        ASSERT_EQ(loop.across.size(), loop.vertices.size());
        for (int face : loop.across) {
            ASSERT_GE(face, 0);
            EXPECT_EQ(surface[size_t(face)], 0);
        }
    }
    // Every vertex on a loop is used once; the others not at all.
    const std::vector<int> uses = BoundaryLoops::Uses(m, loops);
    EXPECT_EQ(std::count(uses.begin(), uses.end(), 1), 54);
    EXPECT_EQ(std::count(uses.begin(), uses.end(), 0), 121 - 54);
}

TEST(BoundaryLoops, HolesTouchingAtAVertexAreOneLoopThroughItTwice)
{
    CoreMesh m;
    test::Grid(4, 0.25, m);
    const auto loops = BoundaryLoops::Compute(m, WithHoles(4, {{1, 2, 1, 2}, {2, 3, 2, 3}}));
    ASSERT_EQ(loops.size(), 2u);
    EXPECT_EQ(loops[0].Edges(), 16);
    EXPECT_EQ(loops[1].Edges(), 8);
    const std::vector<int> uses = BoundaryLoops::Uses(m, loops);
    EXPECT_EQ(uses[size_t(2 * 5 + 2)], 2);  // vertex (2, 2), the corner both holes share
    EXPECT_EQ(std::count(uses.begin(), uses.end(), 2), 1);
}

TEST(BoundaryLoops, AllFacesByDefaultAndNoLoopOnAClosedMesh)
{
    CoreMesh grid;
    test::Grid(3, 1.0, grid);
    const auto loops = BoundaryLoops::Compute(grid);
    ASSERT_EQ(loops.size(), 1u);
    EXPECT_EQ(loops[0].Edges(), 12);
    EXPECT_NEAR(loops[0].length, 12.0, 1e-12);
    EXPECT_TRUE(BoundaryLoops::Compute(grid, std::vector<char>(grid.face.size(), 0)).empty());

    CoreMesh closed;
    vcg::tri::Octahedron(closed);
    vcg::tri::UpdateTopology<CoreMesh>::FaceFace(closed);
    EXPECT_TRUE(BoundaryLoops::Compute(closed).empty());
}
