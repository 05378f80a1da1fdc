// Projection onto an implicit function's zero set: mesh vertices by capped Newton steps,
// samples along their normals.
#include "geometry.h"
#include "implicit_projection.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace ib;

namespace {
/// f = z: the plane z = 0.
class PlaneZ : public ImplicitFunction
{
public:
    void Eval(const Points& Q, Eigen::Ref<Eigen::VectorXd> values) const override { values = Q.col(2); }
};

/// NaN everywhere: nothing to project on.
class Nowhere : public ImplicitFunction
{
public:
    void Eval(const Points&, Eigen::Ref<Eigen::VectorXd> values) const override
    {
        values.setConstant(std::numeric_limits<double>::quiet_NaN());
    }
};

/// Loose vertices at the given positions, added to m.
void Vertices(CoreMesh& m, const std::vector<Eigen::Vector3d>& ps)
{
    vcg::tri::Allocator<CoreMesh>::AddVertices(m, ps.size());
    for (size_t i = 0; i < ps.size(); ++i)
        MoveVertex(m, int(i), ps[i]);
}
} // namespace

TEST(ImplicitProjection, VerticesOffASphereMoveOntoIt)
{
    const std::vector<Eigen::Vector3d> ps{{1.2, 0, 0}, {0, -0.7, 0.2}, {0.5, 0.5, 0.8}, {0.3, 0.1, 1.1}, {2, 2, 2}};
    CoreMesh m;
    Vertices(m, ps);
    const test::SphereDistance sphere(1.0);
    ImplicitProjection::Compute(m, {0, 1, 2, 3}, sphere, 2, 0.5);
    for (int v = 0; v < 4; ++v) {
        EXPECT_NEAR(PositionOf(m, v).norm(), 1.0, 1e-5) << v;
        // Along the gradient: the direction from the centre is kept (up to the central
        // differences' error).
        EXPECT_GT(PositionOf(m, v).normalized().dot(ps[size_t(v)].normalized()), 1 - 1e-6) << v;
    }
    EXPECT_EQ(PositionOf(m, 4), ps[4]);  // not in `moved`
}

TEST(ImplicitProjection, EachStepMovesAtMostACell)
{
    CoreMesh m;
    Vertices(m, {{3, 0, 0}, {0, 0, 0.3}});
    ImplicitProjection::Compute(m, {0, 1}, test::SphereDistance(1.0), 1, 0.5);
    EXPECT_NEAR(PositionOf(m, 0)[0], 2.5, 1e-9);  // 2 to go, capped at one cell
    ImplicitProjection::Compute(m, {0}, test::SphereDistance(1.0), 3, 0.5);
    EXPECT_NEAR(PositionOf(m, 0)[0], 1.0, 1e-9);  // 1.5 more in three capped steps
    CoreMesh flat;
    Vertices(flat, {{0.1, 0.2, 0.3}});
    ImplicitProjection::Compute(flat, {0}, PlaneZ(), 1, 1.0);
    EXPECT_NEAR((PositionOf(flat, 0) - Eigen::Vector3d(0.1, 0.2, 0)).norm(), 0, 1e-12);
    ImplicitProjection::Compute(flat, {0}, Nowhere(), 2, 1.0);  // no value, no gradient: no move
    EXPECT_NEAR((PositionOf(flat, 0) - Eigen::Vector3d(0.1, 0.2, 0)).norm(), 0, 1e-12);
}

TEST(ImplicitProjection, SamplesMoveAlongTheirNormalsOntoTheZeroSet)
{
    Points P(3, 3), N(3, 3);
    P << 0.1, 0.2, 0.05, -1, 3, -0.2, 5, 5, 0;
    N << 0, 0, 1, 0, 0, 1, 0, 0, -1;
    Points expected = P;
    expected.col(2).setZero();
    EXPECT_NEAR((ImplicitProjection::OntoZeroSet(P, N, PlaneZ()) - expected).cwiseAbs().maxCoeff(), 0, 1e-15);

    // On a sphere, with radial normals, off by up to 0.1 either way: exactly onto it.
    Points S, SN;
    test::SpherePoints(200, 1.0, S, SN);
    for (Eigen::Index i = 0; i < S.rows(); ++i)
        S.row(i) *= 1 + 0.1 * std::sin(double(i));
    const Points on = ImplicitProjection::OntoZeroSet(S, SN, test::SphereDistance(1.0));
    EXPECT_NEAR((on.rowwise().norm().array() - 1).abs().maxCoeff(), 0, 1e-12);
    EXPECT_GT((S.rowwise().norm().array() - 1).abs().maxCoeff(), 0.09);
}
