// Openings among samples closed: flat grids and a sphere with faces cut out, samples at their
// vertices (with or without the cut-out part's).
#include "covered_openings.h"
#include "geometry.h"

#include <gtest/gtest.h>

using namespace ib;

namespace {

/// The vertices of m as samples.
Points VerticesOf(const CoreMesh& m)
{
    Points P(Eigen::Index(m.vert.size()), 3);
    for (size_t i = 0; i < m.vert.size(); ++i)
        P.row(Eigen::Index(i)) = PositionOf(m, int(i)).transpose();
    return P;
}

/// Deletes the faces of m whose centre lies within `radius` of `centre`, and the vertices left
/// unused; rebuilds the face-face adjacency.
void CutOut(CoreMesh& m, const vcg::Point3d& centre, double radius)
{
    for (CoreFace& f : m.face)
        if (vcg::Distance(vcg::Barycenter(f), centre) < radius)
            vcg::tri::Allocator<CoreMesh>::DeleteFace(m, f);
    vcg::tri::Clean<CoreMesh>::RemoveUnreferencedVertex(m);
    vcg::tri::Allocator<CoreMesh>::CompactEveryVector(m);
    vcg::tri::UpdateTopology<CoreMesh>::FaceFace(m);
}

} // namespace

TEST(CoveredOpenings, AnOpeningAmongSamplesIsClosedAndTheRimKept)
{
    CoreMesh m;
    test::Grid(20, 1.0, m);
    const Points P = VerticesOf(m);  // with the samples where the faces are cut out
    CutOut(m, vcg::Point3d(10, 10, 0), 1.2);
    ASSERT_EQ(BoundaryLoops::Compute(m).size(), 2u);
    const SampleIndex samples(P);
    const CoveredOpenings::Result r = CoveredOpenings::Compute(m, samples, 1.0);
    EXPECT_EQ(r.closed, 1);
    const std::vector<BoundaryLoop> loops = BoundaryLoops::Compute(m);
    ASSERT_EQ(loops.size(), 1u);
    EXPECT_EQ(loops[0].Edges(), 80);  // the grid's rim, whose fan lies on the grid among samples
    const test::Topology t = test::Check(m);
    EXPECT_EQ(t.non_manifold_edges, 0);
    EXPECT_EQ(t.non_manifold_vertices, 0);
    EXPECT_TRUE(t.oriented);
    double area = 0;
    for (const CoreFace& f : m.face)
        area += 0.5 * vcg::DoubleArea(f);
    EXPECT_NEAR(area, 400.0, 1e-9);  // the patch lies in the plane, over the cut
}

TEST(CoveredOpenings, AHoleWithNoSampleInItIsKept)
{
    CoreMesh m;
    test::Grid(20, 1.0, m);
    CutOut(m, vcg::Point3d(10, 10, 0), 3.0);
    const Points P = VerticesOf(m);  // none inside the hole
    const SampleIndex samples(P);
    const std::vector<BoundaryLoop> before = BoundaryLoops::Compute(m);
    ASSERT_EQ(before.size(), 2u);
    EXPECT_GT(CoveredOpenings::Reach(m, before[1], samples, 1.0, 10.0), 2.0);  // about the hole's radius
    const size_t faces = m.face.size();
    const CoveredOpenings::Result r = CoveredOpenings::Compute(m, samples, 1.0);
    EXPECT_EQ(r.closed, 0);
    EXPECT_GT(r.closest_kept, 1.5);  // over the grid's own gap (0.7)
    EXPECT_EQ(BoundaryLoops::Compute(m).size(), 2u);
    EXPECT_EQ(m.face.size(), faces);
}

TEST(CoveredOpenings, AnOpeningInAClosedSurfaceIsClosed)
{
    CoreMesh m;
    vcg::tri::Sphere(m, 4);
    vcg::tri::UpdateTopology<CoreMesh>::FaceFace(m);
    const Points P = VerticesOf(m);
    const double spacing = vcg::Distance(m.face[0].cP(0), m.face[0].cP(1));
    CutOut(m, m.vert[0].cP(), 1.6 * spacing);
    ASSERT_EQ(BoundaryLoops::Compute(m).size(), 1u);
    const SampleIndex samples(P);
    EXPECT_EQ(CoveredOpenings::Compute(m, samples, spacing).closed, 1);
    EXPECT_TRUE(BoundaryLoops::Compute(m).empty());
    const test::Topology t = test::Check(m);
    EXPECT_EQ(t.non_manifold_edges + t.non_manifold_vertices + t.border_edges, 0);
    EXPECT_TRUE(t.oriented);
}

TEST(CoveredOpenings, AnOpeningNoFartherFromTheSamplesThanTheSurfaceAroundIsClosed)
{
    // The surface 1.1 spacings off its samples everywhere (a thin part's bulge): an opening in
    // it reaches 1.1-1.3 spacings from the samples, no farther than the surface around it.
    for (const double hole : {1.2, 3.0}) {
        CoreMesh m;
        test::Grid(20, 1.0, m);
        Points P = VerticesOf(m);
        P.col(2).array() -= 1.1;
        CutOut(m, vcg::Point3d(10, 10, 0), hole);
        if (hole > 2) {  // and no sample under the larger one: a real hole
            std::vector<Eigen::Index> kept;
            for (Eigen::Index i = 0; i < P.rows(); ++i)
                if (std::hypot(P(i, 0) - 10, P(i, 1) - 10) >= hole)
                    kept.push_back(i);
            P = Points(P(kept, Eigen::all));
        }
        const SampleIndex samples(P);
        const std::vector<BoundaryLoop> before = BoundaryLoops::Compute(m);
        ASSERT_EQ(before.size(), 2u);
        EXPECT_GT(CoveredOpenings::Reach(m, before[1], samples, 1.0, 10.0), 1.05);  // over kReach either way
        EXPECT_EQ(CoveredOpenings::Compute(m, samples, 1.0).closed, hole < 2 ? 1 : 0) << hole;
        EXPECT_EQ(BoundaryLoops::Compute(m).size(), hole < 2 ? 1u : 2u) << hole;
    }
}

TEST(CoveredOpenings, OverTheInputTrianglesAnOpeningIsClosedAndAHoleOfTheMeshKept)
{
    // The surface a grid with an opening of radius 3 cut out; the input mesh the same grid,
    // whole or with the same hole: the opening is closed only over whole triangles.
    for (const bool inputHoled : {false, true}) {
        CoreMesh input;
        test::Grid(20, 1.0, input);
        if (inputHoled)
            CutOut(input, vcg::Point3d(10, 10, 0), 3.0);
        Faces F(Eigen::Index(input.face.size()), 3);
        for (size_t f = 0; f < input.face.size(); ++f)
            for (int i = 0; i < 3; ++i)
                F(Eigen::Index(f), i) = int(vcg::tri::Index(input, input.face[f].cV(i)));
        const MeshDistance triangles(VerticesOf(input), F);
        CoreMesh m;
        test::Grid(20, 1.0, m);
        CutOut(m, vcg::Point3d(10, 10, 0), 3.0);
        const CoveredOpenings::Result r = CoveredOpenings::OverTriangles(m, triangles, 0.5);
        EXPECT_EQ(r.closed, inputHoled ? 0 : 1) << inputHoled;
        EXPECT_EQ(BoundaryLoops::Compute(m).size(), inputHoled ? 2u : 1u) << inputHoled;
        if (inputHoled) {
            EXPECT_GT(r.closest_kept, 4.0);  // the centroid ~6 cells past the input's border, 0.5 allowed
        }
    }
}
