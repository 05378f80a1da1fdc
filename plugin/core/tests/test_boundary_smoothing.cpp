// Boundary smoothing: a zig-zag rim becomes straighter; with an implicit function its
// vertices stay on the implicit surface.
#include "boundary_smoothing.h"
#include "geometry.h"

#include <gtest/gtest.h>

using namespace ib;

namespace {
/// A 10 × 10 grid over [-0.5, 0.5]^2 whose lower side zig-zags (every other vertex 0.04 up),
/// lifted onto the unit sphere (z = sqrt(1 - x^2 - y^2)) when `sphere`.
void ZigZagCap(CoreMesh& m, bool sphere)
{
    test::Grid(10, 0.1, m);
    for (int v = 0; v < int(m.vert.size()); ++v) {
        Eigen::Vector3d p = PositionOf(m, v) - Eigen::Vector3d(0.5, 0.5, 0);
        if (v < 11 && v % 2 == 1)
            p[1] += 0.04;
        if (sphere)
            p[2] = std::sqrt(1 - p[0] * p[0] - p[1] * p[1]);
        MoveVertex(m, v, p);
    }
}

/// Sum over the inner vertices of the lower side of |y[i-1] - 2 y[i] + y[i+1]|.
double Zig(const CoreMesh& m)
{
    double zig = 0;
    for (int v = 1; v < 10; ++v)
        zig += std::abs(PositionOf(m, v - 1)[1] - 2 * PositionOf(m, v)[1] + PositionOf(m, v + 1)[1]);
    return zig;
}

/// Largest distance of a loop vertex from the unit sphere, but for the grid's four corners:
/// cutting a corner flattens its face, and the fold guard, which runs after the projection,
/// pulls that move back halfway, along a chord (2.5e-3 off the sphere at vertex 0).
double OffSphere(const CoreMesh& m, const BoundaryLoop& loop)
{
    double worst = 0;
    for (int v : loop.vertices)
        if (v != 0 && v != 10 && v != 110 && v != 120)
            worst = std::max(worst, std::abs(PositionOf(m, v).norm() - 1));
    return worst;
}
} // namespace

TEST(BoundarySmoothing, AZigZagRimBecomesStraighter)
{
    CoreMesh m;
    ZigZagCap(m, false);
    const auto loops = BoundaryLoops::Compute(m);
    ASSERT_EQ(loops.size(), 1u);
    const double zig = Zig(m), length = BoundaryLoops::Length(m, loops[0]);
    ASSERT_NEAR(zig, 9 * 0.08, 1e-12);  // 9 inner vertices, each 0.04 off its neighbours' midpoint
    BoundarySmoothing::Param p;
    BoundarySmoothing::Compute(m, loops, nullptr, p);
    EXPECT_LT(Zig(m), 0.25 * zig);
    EXPECT_LT(BoundaryLoops::Length(m, loops[0]), length - 0.05);
    for (const auto& v : m.vert)
        EXPECT_EQ(v.cP()[2], 0.0);  // a flat mesh stays flat
    const auto t = test::Check(m);
    EXPECT_TRUE(t.oriented);
    EXPECT_EQ(t.non_manifold_edges, 0);

    CoreMesh still;  // no iteration: nothing moves
    ZigZagCap(still, false);
    p.iterations = 0;
    BoundarySmoothing::Compute(still, BoundaryLoops::Compute(still), nullptr, p);
    EXPECT_EQ(Zig(still), zig);
}

TEST(BoundarySmoothing, VerticesStayOnTheImplicitSurface)
{
    // On the unit sphere, straightening moves rim vertices along chords, inside the sphere;
    // with the sphere as the implicit function they are put back onto it.
    const test::SphereDistance sphere(1.0);
    CoreMesh loose, projected;
    ZigZagCap(loose, true);
    ZigZagCap(projected, true);
    const auto loops = BoundaryLoops::Compute(loose);
    ASSERT_EQ(loops.size(), 1u);
    const double zig = Zig(loose);
    BoundarySmoothing::Param p;
    p.cell_size = 0.1;
    p.newton_steps = 0;
    BoundarySmoothing::Compute(loose, loops, &sphere, p);
    EXPECT_GT(OffSphere(loose, loops[0]), 1e-3);
    p.newton_steps = 2;
    BoundarySmoothing::Compute(projected, loops, &sphere, p);
    EXPECT_LT(OffSphere(projected, loops[0]), 1e-5);
    EXPECT_LT(Zig(projected), 0.25 * zig);
}

TEST(BoundarySmoothing, TheResultDoesNotDependOnWhereTheLoopIsEntered)
{
    // A tile of a tiled run traces a loop from another vertex than one run does: the same loop
    // entered at each of its vertices is smoothed to the same positions.
    CoreMesh first;
    ZigZagCap(first, true);
    const auto loops = BoundaryLoops::Compute(first);
    ASSERT_EQ(loops.size(), 1u);
    BoundarySmoothing::Param p;
    p.cell_size = 0.1;
    p.newton_steps = 0;
    BoundarySmoothing::Compute(first, loops, nullptr, p);
    const size_t n = loops[0].vertices.size();
    for (size_t shift = 1; shift < n; ++shift) {
        CoreMesh other;
        ZigZagCap(other, true);
        std::vector<BoundaryLoop> entered = loops;
        std::rotate(entered[0].vertices.begin(), entered[0].vertices.begin() + long(shift), entered[0].vertices.end());
        BoundarySmoothing::Compute(other, entered, nullptr, p);
        double worst = 0;
        for (int v = 0; v < int(first.vert.size()); ++v)
            worst = std::max(worst, (PositionOf(first, v) - PositionOf(other, v)).norm());
        EXPECT_EQ(worst, 0.0) << "entered at loop vertex " << shift;
    }
}
