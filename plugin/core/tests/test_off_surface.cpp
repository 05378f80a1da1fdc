// Off-surface constraints: one spacing out on an open sheet, shortened or dropped where they
// would cross to the other side of a thin part, none for a sample without a normal.
#include "implicit/off_surface.h"

#include <gtest/gtest.h>

using namespace ib;

namespace {
/// An n×n grid of samples `h` apart in the plane z = `z`, normals (0, 0, `up`).
void Sheet(int n, double h, double z, double up, Points& P, Points& N)
{
    const Eigen::Index first = P.rows();
    P.conservativeResize(first + n * n, 3);
    N.conservativeResize(first + n * n, 3);
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            P.row(first + i * n + j) << i * h, j * h, z;
            N.row(first + i * n + j) << 0, 0, up;
        }
}
} // namespace

TEST(OffSurface, OneSpacingOutOnAnOpenSheet)
{
    Points P(0, 3), N(0, 3);
    Sheet(20, 0.1, 0, 1, P, N);
    const SampleIndex samples(P);
    const OffSurface::Result r = OffSurface::Compute(samples, N, Eigen::VectorXd(), 1.0, 2);
    EXPECT_NEAR(r.median_spacing, 0.1, 0.02);  // sqrt(pi r_8^2 / 8) on a grid: about its step
    EXPECT_EQ(r.kept, size_t(2 * P.rows()));
    EXPECT_EQ(r.dropped, 0u);
    EXPECT_NEAR(r.e.col(0).minCoeff(), r.median_spacing, 0.05);
    EXPECT_LT(r.e.col(1).maxCoeff(), 0);
}

TEST(OffSurface, InsidePointsOfAThinPartStayOnTheirSide)
{
    // A plate: its top (normals up) 0.12 above its bottom (normals down), samples 0.1 apart.
    // Inside points one spacing in would land nearer the other side: they are halved (0.05,
    // nearer their own sample), never left crossing; outside points keep their full length.
    Points P(0, 3), N(0, 3);
    Sheet(20, 0.1, 0.12, 1, P, N);
    Sheet(20, 0.1, 0, -1, P, N);
    const SampleIndex samples(P);
    const OffSurface::Result r = OffSurface::Compute(samples, N, Eigen::VectorXd::Constant(P.rows(), 0.1), 1.0, 2);
    for (Eigen::Index i = 0; i < P.rows(); ++i) {
        EXPECT_DOUBLE_EQ(r.e(i, 0), 0.1);
        EXPECT_GE(r.e(i, 1), -0.06) << i;  // inside: at most half way to the other side
    }
    EXPECT_LT(r.e.col(1).maxCoeff(), 0);  // halved, not dropped
}

TEST(OffSurface, SamplesWithoutNormalsGetNoPoints)
{
    Points P(0, 3), N(0, 3);
    Sheet(10, 0.1, 0, 1, P, N);
    N.row(7).setZero();
    const SampleIndex samples(P);
    const OffSurface::Result r = OffSurface::Compute(samples, N, Eigen::VectorXd(), 1.0, 1);
    EXPECT_EQ(r.e(7, 0), 0);
    EXPECT_EQ(r.e(7, 1), 0);
    EXPECT_EQ(r.kept, size_t(2 * P.rows() - 2));
    EXPECT_EQ(r.dropped, 0u);  // counted only for samples that have a normal
}
