// The boundary steps through the whole pipeline on a flat scan: trim, fit and smoothing
// bring the boundary onto the scan's edge; a small gap is filled by a patch, not a balloon.
// Each step alone is tested in the file of its header (test_boundary_trim.cpp, ...).
#include "geometry.h"
#include "reconstruct.h"

#include <gtest/gtest.h>

using namespace ib;

namespace {
using test::FlatScan;

/// Largest distance from a loop vertex to the square's border, and the loop's length.
std::pair<double, double> RimError(const CoreMesh& m, const BoundaryLoop& loop)
{
    double worst = 0;
    for (int v : loop.vertices) {
        const auto& q = m.vert[size_t(v)].cP();
        const double inside = std::min({q[0], 1 - q[0], q[1], 1 - q[1]});  // negative outside
        worst = std::max({worst, std::abs(inside), std::abs(q[2])});
    }
    return {worst, loop.length};
}
} // namespace

TEST(BoundarySteps, FlatScanIsTrimmedToItsBorderAndSmoothed)
{
    Points P, N;
    FlatScan(0.02, P, N);
    Reconstruction::Param raw;
    raw.boundary_trim = 0;
    raw.boundary_smoothing = 0;
    CoreMesh m0, m1;
    const auto r0 = Reconstruction::Compute(P, N, raw, m0);
    const auto r1 = Reconstruction::Compute(P, N, Reconstruction::Param(), m1);
    ASSERT_EQ(r0.loops.size(), 1u);
    ASSERT_EQ(r1.loops.size(), 1u);
    const auto [error0, length0] = RimError(m0, r0.loops[0]);
    const auto [error1, length1] = RimError(m1, r1.loops[0]);
    // Untrimmed, the SODS margin (a tangent disk, 1.25 spacings) shows; trimmed and fitted, the
    // boundary is within a cell of the square's border and, smoothed, about as long as it (4).
    EXPECT_GT(error0, 1.5 * r0.cell_size);
    EXPECT_LT(error1, r1.cell_size);
    EXPECT_GT(r1.boundary.faces_trimmed, 0u);
    EXPECT_NEAR(length1, 4.0, 0.4);
    EXPECT_GT(length0, length1);
    const auto t = test::Check(m1);
    EXPECT_EQ(t.non_manifold_edges, 0);
    EXPECT_EQ(t.non_manifold_vertices, 0);
    EXPECT_TRUE(t.oriented);
}

/// The plane z = 0 (signed distance z) and, when `balloon`, a tube of radius 0.04 rising from it
/// at (0.5, 0.5) into a ball of radius 0.15 at height 0.35: an implicit surface that closes a
/// gap in a flat scan by a detour far from every sample.
class PlaneWithBalloon : public ImplicitFunction
{
public:
    explicit PlaneWithBalloon(bool balloon) : balloon_(balloon) {}
    void Eval(const Points& Q, Eigen::Ref<Eigen::VectorXd> values) const override
    {
        for (Eigen::Index i = 0; i < Q.rows(); ++i) {
            const Eigen::Vector3d q = Q.row(i).transpose();
            const double radial = std::hypot(q[0] - 0.5, q[1] - 0.5);
            const double tube = std::max(radial - 0.04, std::abs(q[2] - 0.1) - 0.2);
            const double ball = (q - Eigen::Vector3d(0.5, 0.5, 0.35)).norm() - 0.15;
            values[i] = balloon_ ? std::min(q[2], std::min(tube, ball)) : q[2];
        }
    }

private:
    bool balloon_;
};

TEST(BoundarySteps, AGapIsFilledByAPatchNotByABalloon)
{
    // A flat scan with a round gap of radius 0.1 (5 spacings), small by the edge count given.
    Points all, allNormals;
    FlatScan(0.02, all, allNormals);
    std::vector<Eigen::Index> kept;
    for (Eigen::Index i = 0; i < all.rows(); ++i)
        if (std::hypot(all(i, 0) - 0.5, all(i, 1) - 0.5) > 0.1)
            kept.push_back(i);
    // And a small patch high above in a corner, where f has no zero: it only makes the lattice
    // tall enough to hold the ball.
    Points P(Eigen::Index(kept.size()) + 100, 3), N(P.rows(), 3);
    P.topRows(Eigen::Index(kept.size())) = all(kept, Eigen::all);
    N.topRows(Eigen::Index(kept.size())) = allNormals(kept, Eigen::all);
    for (int i = 0; i < 100; ++i) {
        P.row(Eigen::Index(kept.size()) + i) << 0.05 + 0.02 * (i % 10), 0.05 + 0.02 * (i / 10), 0.6;
        N.row(Eigen::Index(kept.size()) + i) << 0, 0, 1;
    }
    Reconstruction::Param p;
    p.implicit = Reconstruction::Implicit::Given;
    p.resolution = 84;
    p.min_boundary_edges = 80;
    for (const bool balloon : {false, true}) {
        const PlaneWithBalloon f(balloon);
        p.given = &f;
        CoreMesh m;
        const auto r = Reconstruction::Compute(P, N, p, m);
        double highest = 0;
        for (const auto& v : m.vert)
            highest = std::max(highest, v.cP()[2]);
        // Flat: the gap is closed by the plane across it. Ballooned: the implicit surface
        // across the gap is the tube and the ball (up to 0.5 high); the gap stays a hole.
        EXPECT_EQ(r.loops.size(), balloon ? 2u : 1u) << (balloon ? "ballooned" : "flat");
        EXPECT_EQ(r.boundary.holes_filled, balloon ? 0 : 1);
        EXPECT_LT(highest, 2 * r.cell_size) << (balloon ? "ballooned" : "flat");
        const auto t = test::Check(m);
        EXPECT_EQ(t.non_manifold_edges, 0);
        EXPECT_TRUE(t.oriented);
    }
}
