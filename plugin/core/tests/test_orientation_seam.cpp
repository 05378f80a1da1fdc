// Orientation seams: found where the normals flip along a sheet, not across thin parts or at
// sharp folds, nor between scans; the surface is cut around them.
#include "geometry.h"
#include "orientation_seam.h"
#include "reconstruct.h"
#include "spacing.h"

#include <gtest/gtest.h>

using namespace ib;

namespace {
using test::FlatScan;
} // namespace

/// OrientationSeam::Find with the samples' own spacings and fold widths.
Points Seams(const SampleIndex& samples, const Points& N)
{
    const Eigen::VectorXd spacing = SampleSpacing::Local(samples);
    return OrientationSeam::Find(samples, N, spacing, OrientationSeam::FoldWidths(samples, N, spacing));
}

TEST(BoundarySteps, FlippedNormalsAreCutAlongTheFlip)
{
    // The flat scan with the normals of its half x > 0.5 turned down: the seam is the line
    // x = 0.5, and the surface is cut there into two pieces with one loop each.
    Points P, N;
    FlatScan(0.02, P, N);
    for (Eigen::Index i = 0; i < P.rows(); ++i)
        if (P(i, 0) > 0.5)
            N(i, 2) = -1;
    const SampleIndex samples(P);
    const Points seam = Seams(samples, N);
    ASSERT_GT(seam.rows(), 40);  // pairs across the line, all along it
    EXPECT_LT((seam.col(0).array() - 0.5).abs().maxCoeff(), 0.02);
    EXPECT_LT(seam.col(1).minCoeff(), 0.05);
    EXPECT_GT(seam.col(1).maxCoeff(), 0.95);
    CoreMesh m;
    const auto r = Reconstruction::Compute(P, N, Reconstruction::Param(), m);
    EXPECT_EQ(r.seam_points, size_t(seam.rows()));
    EXPECT_GT(r.boundary.faces_cut_at_seams, 0u);
    ASSERT_EQ(r.loops.size(), 2u);
    for (const auto& v : m.vert)  // nothing left within a spacing of the seam
        EXPECT_GT(std::abs(v.cP()[0] - 0.5), 0.02);
    const auto t = test::Check(m);
    EXPECT_EQ(t.non_manifold_edges, 0);
    EXPECT_TRUE(t.oriented);

    // Upside down but consistent, or the two sides of a thin plate: no seam.
    N.col(2).setConstant(-1);
    EXPECT_EQ(Seams(samples, N).rows(), 0);
    Points plate(2 * P.rows(), 3), sides(2 * P.rows(), 3);
    plate << P, P.rowwise() + Eigen::RowVector3d(0.01, 0, -0.01);
    sides << Points::Zero(P.rows(), 3).rowwise() + Eigen::RowVector3d(0, 0, 1),
        Points::Zero(P.rows(), 3).rowwise() + Eigen::RowVector3d(0, 0, -1);
    const SampleIndex plateSamples(plate);
    EXPECT_EQ(Seams(plateSamples, sides).rows(), 0);
}

TEST(BoundarySteps, SharpFoldsAreNoSeam)
{
    // Opposite-facing samples meet at a sharp fold with no flip: the crease of a 30-degree
    // V-groove (normals into the groove) and the rim of a plate 1.5 spacings thick (outward).
    // Right at the fold, pairs lie in each other's tangent planes; their neighbours along the
    // other side do not.
    const double s = 0.02, half = 15 * EIGEN_PI / 180;
    std::vector<Eigen::RowVector3d> groove, grooveNormals, plate, plateNormals;
    for (double u = -1 + s / 2; u < 1; u += s)
        for (double y = 0; y <= 1; y += s) {
            const double side = u > 0 ? 1 : -1;
            groove.emplace_back(std::abs(u) * std::sin(half) * side, y, std::abs(u) * std::cos(half));
            grooveNormals.emplace_back(-side * std::cos(half), 0, std::sin(half));
        }
    const double c = 0.75 * s;  // half the thickness: the plate z = +-c sqrt(1 - x^2 - y^2)
    for (double x = -1; x <= 1; x += s)
        for (double y = -1; y <= 1; y += s) {
            const double r2 = x * x + y * y;
            if (r2 >= 1)
                continue;
            for (double side : {1.0, -1.0}) {
                const Eigen::RowVector3d p(x, y, side * c * std::sqrt(1 - r2));
                plate.push_back(p);
                plateNormals.push_back(Eigen::RowVector3d(p[0], p[1], p[2] / (c * c)).normalized());
            }
        }
    for (auto [points, normals] : {std::pair{&groove, &grooveNormals}, std::pair{&plate, &plateNormals}}) {
        Points P(Eigen::Index(points->size()), 3), N(P.rows(), 3);
        for (Eigen::Index i = 0; i < P.rows(); ++i) {
            P.row(i) = (*points)[size_t(i)];
            N.row(i) = (*normals)[size_t(i)];
        }
        const SampleIndex samples(P);
        EXPECT_EQ(Seams(samples, N).rows(), 0) << P.rows();
    }
}

TEST(OrientationSeam, FoldWidthIsTheDistanceToTheOppositeSide)
{
    // One sheet: nothing faces it. Two sheets 0.01 apart (half a spacing) facing away from
    // each other: every sample sees the other side at exactly that distance.
    Points P, N;
    FlatScan(0.02, P, N);
    const SampleIndex sheet(P);
    const Eigen::VectorXd sheetSpacing = SampleSpacing::Local(sheet);
    EXPECT_EQ(OrientationSeam::FoldWidths(sheet, N, sheetSpacing).cwiseAbs().maxCoeff(), 0.0);
    Points plate(2 * P.rows(), 3), sides(2 * P.rows(), 3);
    plate << P, P.rowwise() - Eigen::RowVector3d(0, 0, 0.01);
    sides << N, -N;
    const SampleIndex samples(plate);
    const Eigen::VectorXd width = OrientationSeam::FoldWidths(samples, sides, SampleSpacing::Local(samples), 2);
    EXPECT_NEAR(width.minCoeff(), 0.01, 1e-12);
    EXPECT_NEAR(width.maxCoeff(), 0.01, 1e-12);
    // Each side its own scan: pairs across scans are not compared.
    std::vector<int> scan(size_t(plate.rows()), 0);
    std::fill(scan.begin() + P.rows(), scan.end(), 1);
    EXPECT_EQ(OrientationSeam::FoldWidths(samples, sides, SampleSpacing::Local(samples), 1, scan).maxCoeff(), 0.0);
}

TEST(OrientationSeam, AFlipBetweenTwoScansIsNoSeam)
{
    Points P, N;
    FlatScan(0.02, P, N);
    std::vector<int> scan(size_t(P.rows()), 0);
    for (Eigen::Index i = 0; i < P.rows(); ++i)
        if (P(i, 0) > 0.5) {
            N(i, 2) = -1;
            scan[size_t(i)] = 1;
        }
    const SampleIndex samples(P);
    const Eigen::VectorXd spacing = SampleSpacing::Local(samples);
    const Eigen::VectorXd folds = OrientationSeam::FoldWidths(samples, N, spacing, 1, scan);
    EXPECT_EQ(OrientationSeam::Find(samples, N, spacing, folds, 1, scan).rows(), 0);
    const Points one = OrientationSeam::Find(samples, N, spacing, OrientationSeam::FoldWidths(samples, N, spacing, 2), 2);
    EXPECT_GT(one.rows(), 40);
    const Points two = OrientationSeam::Find(samples, N, spacing, OrientationSeam::FoldWidths(samples, N, spacing, 1), 1);
    ASSERT_EQ(two.rows(), one.rows());
    EXPECT_TRUE(two == one);  // the same points in the same order on one and two threads
}

TEST(OrientationSeam, CutRemovesTheSurfaceFacesNearTheSeam)
{
    CoreMesh m;
    test::Grid(10, 0.1, m);
    Points seam(2, 3);
    seam << 0.5, 0.5, 0, 0.5, 0.6, 0;
    std::vector<char> inSurface(m.face.size(), 1);
    inSurface[0] = 0;
    EXPECT_EQ(OrientationSeam::Cut(m, Points(0, 3), 0.15, inSurface), 0u);
    size_t near = 0;
    std::vector<char> expected = inSurface;
    for (size_t f = 0; f < m.face.size(); ++f) {
        const vcg::Point3d c = vcg::Barycenter(m.face[f]);
        const Eigen::Vector3d q(c[0], c[1], c[2]);
        const double d = std::min((seam.row(0).transpose() - q).norm(), (seam.row(1).transpose() - q).norm());
        if (d < 0.15 && expected[f]) {
            expected[f] = 0;
            ++near;
        }
    }
    ASSERT_GT(near, 8u);
    EXPECT_EQ(OrientationSeam::Cut(m, seam, 0.15, inSurface, 2), near);
    EXPECT_EQ(inSurface, expected);
}
