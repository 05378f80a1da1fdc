// The fold guard: moves that flip or flatten an adjacent face are halved, then undone.
#include "fold_guard.h"
#include "geometry.h"

#include <gtest/gtest.h>

using namespace ib;

namespace {
using test::AddTriangle;
} // namespace

TEST(BoundarySteps, FoldGuardUndoesAMoveThatFoldsAFace)
{
    // A fan of 4 triangles around (0,0,0): moving the centre past the rim folds some of them.
    CoreMesh m;
    const vcg::Point3d o(0, 0, 0);
    for (int i = 0; i < 4; ++i)
        AddTriangle(m, o, vcg::Point3d(std::cos(i * M_PI / 2), std::sin(i * M_PI / 2), 0),
                    vcg::Point3d(std::cos((i + 1) * M_PI / 2), std::sin((i + 1) * M_PI / 2), 0));
    vcg::tri::Clean<CoreMesh>::RemoveDuplicateVertex(m);
    vcg::tri::Allocator<CoreMesh>::CompactEveryVector(m);
    int centre = 0;
    while (PositionOf(m, centre).norm() > 0)
        ++centre;
    const std::vector<int> moved{centre};
    const std::vector<Eigen::Vector3d> start{Eigen::Vector3d::Zero()};
    MoveVertex(m, centre, Eigen::Vector3d(0.2, 0.1, 0));  // inside the fan: fine
    EXPECT_EQ(FoldGuard::Restore(m, moved, start), 0u);
    EXPECT_EQ(PositionOf(m, centre), Eigen::Vector3d(0.2, 0.1, 0));
    MoveVertex(m, centre, Eigen::Vector3d(1.6, 0, 0));  // past the rim: halved to 0.8, inside again
    EXPECT_EQ(FoldGuard::Restore(m, moved, start), 1u);
    EXPECT_NEAR(PositionOf(m, centre)[0], 0.8, 1e-12);
    MoveVertex(m, centre, Eigen::Vector3d(30, 0, 0));  // 15, 7.5, 3.75 all fold: undone
    FoldGuard::Restore(m, moved, start);
    EXPECT_EQ(PositionOf(m, centre), Eigen::Vector3d::Zero());
    MoveVertex(m, centre, Eigen::Vector3d(1e-3, 0.9999, 0));  // flattens a face to a sliver
    FoldGuard::Restore(m, moved, start);
    EXPECT_LT(PositionOf(m, centre)[1], 0.5);
}

TEST(FoldGuard, CollapsedIsAFlipOrASliver)
{
    const vcg::Point3d up(0, 0, 2);
    EXPECT_FALSE(FoldGuard::Collapsed(up, up));
    EXPECT_FALSE(FoldGuard::Collapsed(vcg::Point3d(1, 0, 1), up));       // turned 45 degrees
    EXPECT_TRUE(FoldGuard::Collapsed(vcg::Point3d(1, 0, 0), up));        // turned 90 degrees
    EXPECT_TRUE(FoldGuard::Collapsed(vcg::Point3d(0, 0, -2), up));       // flipped
    EXPECT_TRUE(FoldGuard::Collapsed(vcg::Point3d(0, 0, 0.02), up));     // 1% of its area
    EXPECT_FALSE(FoldGuard::Collapsed(vcg::Point3d(0, 0, 0.021), up));   // just over 1%
    EXPECT_FALSE(FoldGuard::Collapsed(vcg::Point3d(0, 0, -1), vcg::Point3d(0, 0, 0)));  // had no area
}

TEST(FoldGuard, MovesThatFoldNothingStay)
{
    CoreMesh m;
    test::Grid(4, 0.25, m);
    const std::vector<int> moved{6, 12, 18};  // interior vertices (1, 1), (2, 2), (3, 3)
    std::vector<Eigen::Vector3d> start;
    for (int v : moved) {
        start.push_back(PositionOf(m, v));
        MoveVertex(m, v, PositionOf(m, v) + Eigen::Vector3d(0.05, -0.05, 0.1));
    }
    EXPECT_EQ(FoldGuard::Restore(m, moved, start), 0u);
    for (size_t i = 0; i < moved.size(); ++i)
        EXPECT_EQ(PositionOf(m, moved[i]), start[i] + Eigen::Vector3d(0.05, -0.05, 0.1));
    EXPECT_EQ(FoldGuard::Restore(m, {}, {}), 0u);
}
