// Trim, pinch resolution, scraps and smoothing, on hand-made meshes and a flat scan.
#include "boundary_trim.h"
#include "fold_guard.h"
#include "manifold_check.h"
#include "geometry.h"
#include "orientation_seam.h"
#include "pinches.h"
#include "reconstruct.h"

#include <gtest/gtest.h>

#include <array>

using namespace ib;

namespace {
void AddTriangle(CoreMesh& m, const vcg::Point3d& a, const vcg::Point3d& b, const vcg::Point3d& c)
{
    vcg::tri::Allocator<CoreMesh>::AddFace(m, a, b, c);
}

/// A flat square scan: samples on a staggered grid of spacing s over [0, 1]^2 at z = 0.
void FlatScan(double s, Points& P, Points& N)
{
    std::vector<Eigen::Vector3d> pts;
    const int n = int(std::round(1 / s));
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i)
            pts.emplace_back(std::min(1.0, (i + 0.5 * (j % 2)) * s), j * s, 0.0);
    P.resize(Eigen::Index(pts.size()), 3);
    N.resize(Eigen::Index(pts.size()), 3);
    for (size_t i = 0; i < pts.size(); ++i) {
        P.row(Eigen::Index(i)) = pts[i].transpose();
        N.row(Eigen::Index(i)) << 0, 0, 1;
    }
}

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

TEST(BoundarySteps, PinchKeepsTheLargerFan)
{
    // Three triangles around the origin on one side, one on the other: they meet only at (0,0,0).
    CoreMesh m;
    const vcg::Point3d o(0, 0, 0);
    AddTriangle(m, o, vcg::Point3d(1, 0, 0), vcg::Point3d(1, 1, 0));
    AddTriangle(m, o, vcg::Point3d(1, 1, 0), vcg::Point3d(0, 1, 0));
    AddTriangle(m, o, vcg::Point3d(0, 1, 0), vcg::Point3d(-0.2, 1, 0));
    AddTriangle(m, o, vcg::Point3d(-1, -1, 0), vcg::Point3d(0, -1, 0));
    vcg::tri::Clean<CoreMesh>::RemoveDuplicateVertex(m);
    vcg::tri::Allocator<CoreMesh>::CompactEveryVector(m);
    vcg::tri::UpdateTopology<CoreMesh>::FaceFace(m);
    std::vector<char> inSurface(4, 1);
    EXPECT_EQ(Pinches::Resolve(m, inSurface), 1u);
    EXPECT_EQ(inSurface, (std::vector<char>{1, 1, 1, 0}));
}

TEST(BoundarySteps, HoleFanTouchingTheSurfaceOnlyAtAVertexIsLeftOut)
{
    // Around the origin: a surface face (0), a hole face sharing its edge (1), and a larger
    // hole fan (2, 3) across an opening, touching both only at the origin.
    CoreMesh m;
    const vcg::Point3d o(0, 0, 0);
    AddTriangle(m, o, vcg::Point3d(1, 0, 0), vcg::Point3d(1, 1, 0));
    AddTriangle(m, o, vcg::Point3d(1, 1, 0), vcg::Point3d(0, 1, 0));
    AddTriangle(m, o, vcg::Point3d(-1, 0, 0), vcg::Point3d(-1, -1, 0));
    AddTriangle(m, o, vcg::Point3d(-1, -1, 0), vcg::Point3d(0, -1, 0));
    vcg::tri::Clean<CoreMesh>::RemoveDuplicateVertex(m);
    vcg::tri::Allocator<CoreMesh>::CompactEveryVector(m);
    vcg::tri::UpdateTopology<CoreMesh>::FaceFace(m);
    const std::vector<char> inSurface{1, 0, 0, 0};
    std::vector<char> inHoles{0, 1, 1, 1};
    // Alone, the holes layer would keep its larger fan and meet the surface in a bow-tie.
    std::vector<char> alone = inHoles;
    EXPECT_EQ(Pinches::Resolve(m, alone), 1u);
    EXPECT_EQ(alone, (std::vector<char>{0, 0, 1, 1}));
    EXPECT_EQ(Pinches::Resolve(m, inHoles, 8, &inSurface), 2u);
    EXPECT_EQ(inHoles, (std::vector<char>{0, 1, 0, 0}));
}

TEST(BoundarySteps, ScrapsBelowTheSizeAreRemoved)
{
    CoreMesh m;
    for (int i = 0; i < 6; ++i)  // a fan of 6 connected triangles
        AddTriangle(m, vcg::Point3d(0, 0, 0), vcg::Point3d(std::cos(i), std::sin(i), 0),
                    vcg::Point3d(std::cos(i + 1), std::sin(i + 1), 0));
    AddTriangle(m, vcg::Point3d(5, 0, 0), vcg::Point3d(6, 0, 0), vcg::Point3d(5, 1, 0));  // alone
    vcg::tri::Clean<CoreMesh>::RemoveDuplicateVertex(m);
    vcg::tri::Allocator<CoreMesh>::CompactEveryVector(m);
    vcg::tri::UpdateTopology<CoreMesh>::FaceFace(m);
    std::vector<char> inSurface(7, 1);
    EXPECT_EQ(BoundaryTrim::RemoveScraps(m, inSurface, 2), 1u);
    EXPECT_EQ(inSurface.back(), 0);
    EXPECT_EQ(std::count(inSurface.begin(), inSurface.end(), 1), 6);
}

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

TEST(BoundarySteps, ManifoldCheckRepairsFinsAndBowTies)
{
    // Vertices 0..6; a fin: faces 0-1-2, 1-0-3 and 0-1-4 share edge 0-1 (the third face is
    // removed); a bow tie: 2-5-6 touches the rest at vertex 2 only (split into its own vertex).
    auto build = [](CoreMesh& m, const std::vector<std::array<int, 3>>& faces) {
        auto v = vcg::tri::Allocator<CoreMesh>::AddVertices(m, 7);
        const double xyz[7][3] = {{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, -1, 0}, {0.5, 0, 1}, {0, 2, 0}, {1, 2, 0}};
        for (int i = 0; i < 7; ++i)
            v[i].P() = vcg::Point3d(xyz[i][0], xyz[i][1], xyz[i][2]);
        for (const auto& f : faces)
            vcg::tri::Allocator<CoreMesh>::AddFace(m, &m.vert[size_t(f[0])], &m.vert[size_t(f[1])], &m.vert[size_t(f[2])]);
    };
    CoreMesh fin;
    build(fin, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
    auto r = ManifoldCheck::Repair(fin);
    EXPECT_GE(r.faces_removed, 1u);
    EXPECT_TRUE(r.manifold);
    EXPECT_EQ(test::Check(fin).non_manifold_edges, 0);

    CoreMesh bowTie;
    build(bowTie, {{0, 1, 2}, {1, 0, 3}, {2, 6, 5}});
    r = ManifoldCheck::Repair(bowTie);
    EXPECT_EQ(r.faces_removed, 0u);
    EXPECT_EQ(r.vertices_split, 1u);
    EXPECT_TRUE(r.manifold && r.oriented);
    EXPECT_EQ(bowTie.face.size(), 3u);

    CoreMesh flipped;  // one face turned against its neighbour: reported, not hidden
    build(flipped, {{0, 1, 2}, {0, 1, 3}});
    r = ManifoldCheck::Repair(flipped);
    EXPECT_TRUE(r.manifold);
    EXPECT_FALSE(r.oriented);
}
