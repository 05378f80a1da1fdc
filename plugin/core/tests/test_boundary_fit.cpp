// BoundaryFit on a flat scan: a grid mesh reaching past the samples' square has its boundary
// moved onto the square's border, by at most max_move spacings; what is not next to the
// boundary stays where it was.
#include "boundary_fit.h"
#include "geometry.h"

#include <gtest/gtest.h>

#include <algorithm>

using namespace ib;

namespace {

constexpr double kSpacing = 0.02;   // the flat scan's
constexpr double kOverhang = 0.028;  // how far the mesh reaches past the square on every side

/// A 20 × 20 grid over [-kOverhang, 1 + kOverhang]^2 at z = 0, faces towards +z.
void Overhanging(CoreMesh& m)
{
    test::Grid(20, (1 + 2 * kOverhang) / 20, m);
    for (auto& v : m.vert)
        v.P() -= vcg::Point3d(kOverhang, kOverhang, 0);
}

/// Distance from q to the border of the unit square, and off its plane.
double OffBorder(const vcg::Point3d& q)
{
    return std::max(std::abs(std::min({q[0], 1 - q[0], q[1], 1 - q[1]})), std::abs(q[2]));
}

struct Fitted
{
    CoreMesh mesh;
    std::vector<vcg::Point3d> before;
    std::vector<BoundaryLoop> loops;
    size_t count = 0;
};

void Fit(const BoundaryFit::Param& p, Fitted& out)
{
    Points P, N;
    test::FlatScan(kSpacing, P, N);
    const SampleIndex samples(P);
    Overhanging(out.mesh);
    for (const auto& v : out.mesh.vert)
        out.before.push_back(v.cP());
    const std::vector<char> inSurface(out.mesh.face.size(), 1);
    out.loops = BoundaryLoops::Compute(out.mesh, inSurface);
    out.count = BoundaryFit::Compute(out.mesh, out.loops, inSurface, samples,
                                     Eigen::VectorXd::Constant(P.rows(), kSpacing), nullptr, p);
}

} // namespace

TEST(BoundaryFit, TheBoundaryMovesOntoTheSamplesEdge)
{
    Fitted r;
    Fit(BoundaryFit::Param(), r);
    ASSERT_EQ(r.loops.size(), 1u);
    const std::vector<int>& loop = r.loops[0].vertices;
    ASSERT_EQ(loop.size(), 80u);
    double nearestBefore = 1e9, worstAfter = 0;
    size_t moved = 0;
    for (int v : loop) {
        nearestBefore = std::min(nearestBefore, OffBorder(r.before[size_t(v)]));
        worstAfter = std::max(worstAfter, OffBorder(r.mesh.vert[size_t(v)].cP()));
        moved += r.mesh.vert[size_t(v)].cP() != r.before[size_t(v)];
    }
    // Every boundary vertex starts 1.4 spacings off the border; fitted, within the staggered
    // grid's half spacing (its rows alternate between x = 0 and x = 0.01 on the left).
    EXPECT_NEAR(nearestBefore, kOverhang, 1e-12);
    EXPECT_LT(worstAfter, 0.75 * kSpacing);
    EXPECT_EQ(r.count, moved);
    EXPECT_EQ(moved, loop.size());
    // Vertices that share no face with a boundary vertex stay put; none leaves the plane.
    std::vector<char> nearLoop(r.mesh.vert.size(), 0);
    for (const CoreFace& f : r.mesh.face) {
        bool touches = false;
        for (int i = 0; i < 3; ++i)
            touches |= std::find(loop.begin(), loop.end(), int(vcg::tri::Index(r.mesh, f.cV(i)))) != loop.end();
        for (int i = 0; touches && i < 3; ++i)
            nearLoop[vcg::tri::Index(r.mesh, f.cV(i))] = 1;
    }
    size_t far = 0;
    for (size_t v = 0; v < r.mesh.vert.size(); ++v) {
        EXPECT_NEAR(r.mesh.vert[v].cP()[2], 0.0, 1e-12);
        if (!nearLoop[v]) {
            ++far;
            EXPECT_EQ(r.mesh.vert[v].cP(), r.before[v]) << v;
        }
    }
    EXPECT_EQ(far, 17u * 17u);
    const auto t = test::Check(r.mesh);
    EXPECT_TRUE(t.oriented);
    EXPECT_EQ(t.non_manifold_edges, 0);
}

TEST(BoundaryFit, MovesAtMostMaxMoveSpacings)
{
    BoundaryFit::Param p;
    p.max_move = 0.5;
    Fitted r;
    Fit(p, r);
    ASSERT_EQ(r.loops.size(), 1u);
    double longest = 0;
    for (int v : r.loops[0].vertices)
        longest = std::max(longest, double((r.mesh.vert[size_t(v)].cP() - r.before[size_t(v)]).Norm()));
    // The edge is 1.4 spacings away: every move is cut to half a spacing.
    EXPECT_LE(longest, 0.5 * kSpacing + 1e-12);
    EXPECT_GT(longest, 0.49 * kSpacing);
    EXPECT_EQ(r.count, r.loops[0].vertices.size());
}

TEST(BoundaryFit, ANotchedBoundaryReachesADenseRowOfEdgeSamples)
{
    // A plane cut's edge: the flat scan's samples plus a row 4 times denser along x = 1. The
    // trimmed surface reaches it in teeth: notches up to 1.2 spacings deep, 0.1 apart. The
    // dense row pulls the samples' centroid past a notch's vertex (its side is then told by
    // the loop over a few vertices). Left where it was before (a spacing off the edge); now
    // moved towards it as far as the tooth's faces beside it let it go without folding.
    Points flat, N;
    test::FlatScan(kSpacing, flat, N);
    const int row = 201;
    Points P(flat.rows() + row, 3);
    P.topRows(flat.rows()) = flat;
    for (int k = 0; k < row; ++k)
        P.row(flat.rows() + k) << 1.0, k * 0.005, 0.0;
    const SampleIndex samples(P);
    CoreMesh m;
    test::Grid(50, 0.02, m);
    for (CoreFace& f : m.face) {
        const vcg::Point3d c = vcg::Barycenter(f);
        const double tooth = std::abs(std::fmod(c[1], 0.1) / 0.05 - 1);  // 1 at a notch, 0 at a tip
        if (c[0] > 1 - 1.2 * kSpacing * tooth)
            vcg::tri::Allocator<CoreMesh>::DeleteFace(m, f);
    }
    vcg::tri::Clean<CoreMesh>::RemoveUnreferencedVertex(m);
    vcg::tri::Allocator<CoreMesh>::CompactEveryVector(m);
    vcg::tri::UpdateTopology<CoreMesh>::FaceFace(m);
    const std::vector<char> inSurface(m.face.size(), 1);
    const std::vector<BoundaryLoop> loops = BoundaryLoops::Compute(m, inSurface);
    ASSERT_EQ(loops.size(), 1u);
    auto deepest = [&] {  // the right side's loop vertex farthest from x = 1, corners left out
        double d = 0;
        for (int v : loops[0].vertices)
            if (const vcg::Point3d& q = m.vert[size_t(v)].cP(); q[0] > 0.9 && q[1] > 0.1 && q[1] < 0.9)
                d = std::max(d, 1 - q[0]);
        return d;
    };
    ASSERT_GT(deepest(), 1.0 * kSpacing);
    BoundaryFit::Compute(m, loops, inSurface, samples, Eigen::VectorXd::Constant(P.rows(), kSpacing), nullptr,
                         BoundaryFit::Param());
    EXPECT_LT(deepest(), 0.6 * kSpacing);
    const auto t = test::Check(m);
    EXPECT_TRUE(t.oriented);
    EXPECT_EQ(t.non_manifold_edges, 0);
}
