// Normals of point sets: PCA planes oriented by propagation, a viewpoint or facing
// directions; given normals with missing rows filled.
#include "geometry.h"
#include "normals.h"

#include <gtest/gtest.h>

#include <limits>
#include <numeric>

using namespace ib;

namespace {
/// Smallest dot product of the unit normals N with the sphere's outward directions.
double LeastOutward(const Points& P, const Points& N)
{
    return (N.array() * P.rowwise().normalized().array()).rowwise().sum().minCoeff();
}
} // namespace

TEST(PointNormals, SphereNormalsPointOutwardAfterPropagation)
{
    Points P, exact;
    test::SpherePoints(2000, 1.0, P, exact);
    const SampleIndex samples(P);
    PointNormals::Report report;
    const Points N = PointNormals::Compute(samples, PointNormals::Param(), &report);
    ASSERT_EQ(N.rows(), P.rows());
    EXPECT_NEAR((N.rowwise().norm().array() - 1).abs().maxCoeff(), 0, 1e-9);
    EXPECT_GT(LeastOutward(P, N), 0.99);  // outward, and within 8 degrees of the exact normal
    EXPECT_EQ(report.turned, 0u);
}

TEST(PointNormals, AViewpointOrFacingDirectionsChooseTheSide)
{
    Points P, exact;
    test::SpherePoints(1500, 1.0, P, exact);
    const SampleIndex samples(P);
    PointNormals::Param p;
    p.viewpoint = Eigen::Vector3d::Zero();  // a scanner inside the sphere: normals face it
    EXPECT_GT(LeastOutward(P, -PointNormals::Compute(samples, p)), 0.99);

    PointNormals::Param q;  // facing inward, with a patch of unknown directions
    q.facing = -exact;
    for (Eigen::Index i = 0; i < 40; ++i)
        q.facing.row(i).setZero();
    EXPECT_GT(LeastOutward(P, -PointNormals::Compute(samples, q)), 0.99);
}

TEST(PointNormals, GivenNormalsAreScaledAndMissingOnesFilled)
{
    Points P, exact;
    test::SpherePoints(1000, 1.0, P, exact);
    const SampleIndex samples(P);
    Points N = -3.0 * exact;  // inward, not unit
    N.row(10).setZero();
    N(500, 1) = std::numeric_limits<double>::quiet_NaN();
    N.row(900) << std::numeric_limits<double>::infinity(), 0, 0;
    size_t filled = 0;
    const Points given = PointNormals::Given(samples, N, 15, filled);
    EXPECT_EQ(filled, 3u);
    EXPECT_NEAR((given.rowwise().norm().array() - 1).abs().maxCoeff(), 0, 1e-9);
    EXPECT_NEAR((given.topRows(10) + exact.topRows(10)).cwiseAbs().maxCoeff(), 0, 1e-12);  // kept
    EXPECT_GT(LeastOutward(P, -given), 0.98);  // the filled ones face inward too

    Points none = Points::Zero(P.rows(), 3);  // nothing given: a seed faces away from the centroid
    std::vector<Eigen::Index> all(size_t(P.rows()));
    std::iota(all.begin(), all.end(), Eigen::Index(0));
    PointNormals::FillMissing(samples, none, all, 15);
    EXPECT_GT(LeastOutward(P, none), 0.98);
}

TEST(PointNormals, FlatScanNormalsAreItsPlanes)
{
    Points P, N;
    test::FlatScan(0.02, P, N);
    PointNormals::Param p;
    p.threads = 2;
    const Points estimated = PointNormals::Compute(SampleIndex(P), p);
    EXPECT_GT(estimated.col(2).cwiseAbs().minCoeff(), 1 - 1e-9);
    // One piece: all on one side.
    EXPECT_TRUE((estimated.col(2).array() > 0).all() || (estimated.col(2).array() < 0).all());
}
