#include "geometry.h"
#include "reconstruct.h"

#include <gtest/gtest.h>

using namespace ib;

TEST(Reconstruction, ClosedSphereHasNoBoundary)
{
    Points P, N;
    test::SpherePoints(4000, 1.0, P, N);
    CoreMesh m;
    auto r = Reconstruction::Compute(P, N, {}, m);
    EXPECT_TRUE(r.resolution_automatic);
    EXPECT_TRUE(r.loops.empty());
    const auto t = test::Check(m);
    EXPECT_EQ(t.border_edges, 0);
    EXPECT_EQ(t.non_manifold_edges, 0);
    EXPECT_TRUE(t.oriented);
    double worst = 0;
    for (const auto& v : m.vert)
        worst = std::max(worst, std::abs(v.cP().Norm() - 1.0));
    EXPECT_LT(worst, 0.25 * r.cell_size);
    EXPECT_LT(double(r.evaluations), 0.5 * r.lattice_corners);
}

TEST(Reconstruction, HemisphereHasExactlyOneBoundaryLoopAtItsRim)
{
    Points P, N;
    test::SpherePoints(6000, 1.0, P, N, 0.0);
    Reconstruction::Param p;
    p.resolution = 40;
    CoreMesh m;
    auto r = Reconstruction::Compute(P, N, p, m);
    ASSERT_EQ(r.loops.size(), 1u);
    // Every boundary vertex within a cell and a half of the rim (the circle z = 0), on average
    // within one cell; the trim took off the SODS margin past the rim.
    double sum = 0;
    for (int v : r.loops[0].vertices) {
        const auto& q = m.vert[size_t(v)].cP();
        const double d = std::hypot(q[2], std::hypot(q[0], q[1]) - 1);
        EXPECT_LT(d, 1.5 * r.cell_size);
        sum += d;
    }
    EXPECT_LT(sum / r.loops[0].Edges(), r.cell_size);
    EXPECT_GT(r.faces_trimmed, 0u);
    EXPECT_NEAR(r.loops[0].length, 2 * M_PI, 0.15 * 2 * M_PI);  // smoothed: 1.8 times as long unsmoothed
    const auto t = test::Check(m);
    EXPECT_EQ(t.non_manifold_edges, 0);
    EXPECT_TRUE(t.oriented);
}

TEST(Reconstruction, EstimatesNormalsWhenThereAreNone)
{
    Points P, N;
    test::SpherePoints(3000, 1.0, P, N);
    CoreMesh m;
    auto r = Reconstruction::Compute(P, Points(), {}, m);
    EXPECT_TRUE(r.normals_estimated);
    EXPECT_TRUE(r.loops.empty());
    int outward = 0;
    for (auto& f : m.face)
        outward += vcg::TriangleNormal(f).dot(vcg::Barycenter(f)) > 0;
    EXPECT_GT(outward, 0.99 * m.fn);
}

TEST(Reconstruction, RejectsBadInputWithClearMessages)
{
    Points P, N;
    test::SpherePoints(100, 1.0, P, N);
    auto message = [](const Points& P, const Points& N, Reconstruction::Param p) {
        try {
            CoreMesh m;
            Reconstruction::Compute(P, N, p, m);
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(message(Points(0, 3), Points(), {}).find("no vertices"), std::string::npos);
    EXPECT_NE(message(P.topRows(3), N.topRows(3), {}).find("only 3 vertices"), std::string::npos);
    Points nan = P;
    nan(5, 1) = std::numeric_limits<double>::quiet_NaN();
    EXPECT_NE(message(nan, N, {}).find("NaN"), std::string::npos);
    Reconstruction::Param p;
    p.resolution = -4;
    EXPECT_NE(message(P, N, p).find("out of range"), std::string::npos);
    p.resolution = 100000;
    EXPECT_NE(message(P, N, p).find("out of range"), std::string::npos);
    Points same = Points::Ones(20, 3);
    EXPECT_NE(message(same, Points(), {}).find("same position"), std::string::npos);
    Points zeroSome = N;
    zeroSome.row(3).setZero();
    EXPECT_NE(message(P, zeroSome, {}).find("zero or NaN"), std::string::npos);
}
