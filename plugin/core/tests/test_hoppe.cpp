// Hoppe's signed distance to the samples' tangent planes, blended over the k nearest.
#include "geometry.h"
#include "implicit/hoppe.h"

#include <gtest/gtest.h>

#include <limits>

using namespace ib;

TEST(HoppeDistance, IsTheSignedDistanceToAPlane)
{
    Points P, N;
    test::FlatScan(0.05, P, N);
    const SampleIndex samples(P);
    const HoppeDistance f(samples, N);
    Points Q(4, 3);
    Q << 0.5, 0.5, 0.1, 0.2, 0.7, -0.03, 0.9, 0.1, 0, 2, 2, 1;
    Eigen::VectorXd values(4);
    f.Eval(Q, values);
    EXPECT_NEAR((values - Q.col(2)).cwiseAbs().maxCoeff(), 0, 1e-12);  // every plane is z = 0
}

TEST(HoppeDistance, FollowsASphereWithItsSign)
{
    Points P, N;
    test::SpherePoints(2000, 1.0, P, N);
    const SampleIndex samples(P);
    const HoppeDistance f(samples, N, 8, 2);
    Points Q, dirs;
    test::SpherePoints(300, 1.0, Q, dirs);
    for (double r : {0.95, 1.0, 1.05}) {
        const Points at = r * Q;
        Eigen::VectorXd values(at.rows());
        f.Eval(at, values);
        EXPECT_LT((values.array() - (r - 1)).abs().maxCoeff(), 0.01) << r;
    }
    // Outward normals turned inward: the function changes sign.
    const Points inward = -N;
    const HoppeDistance g(samples, inward, 8, 1);
    Eigen::VectorXd a(Q.rows()), b(Q.rows());
    f.Eval(1.05 * Q, a);
    g.Eval(1.05 * Q, b);
    EXPECT_NEAR((a + b).cwiseAbs().maxCoeff(), 0, 1e-12);
}

TEST(HoppeDistance, OneNeighbourIsTheNearestSamplesPlane)
{
    Points P, N;
    test::SpherePoints(200, 1.0, P, N);
    const SampleIndex samples(P);
    const HoppeDistance f(samples, N, 0);  // k clamped to 1
    Points Q, dirs;
    test::SpherePoints(50, 1.2, Q, dirs);
    Eigen::VectorXd values(Q.rows());
    f.Eval(Q, values);
    for (Eigen::Index i = 0; i < Q.rows(); ++i) {
        Eigen::Index nearest = 0;
        double best = std::numeric_limits<double>::infinity();
        for (Eigen::Index j = 0; j < P.rows(); ++j)
            if (const double d = (P.row(j) - Q.row(i)).squaredNorm(); d < best) {
                best = d;
                nearest = j;
            }
        EXPECT_NEAR(values[i], (Q.row(i) - P.row(nearest)).dot(N.row(nearest)), 1e-12) << i;
    }
    const HoppeDistance all(samples, N, 100000);  // k clamped to the sample count: finite
    all.Eval(Q, values);
    EXPECT_TRUE(values.allFinite());
}
