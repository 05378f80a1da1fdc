// BoundaryStage on real gated extractions of the unit sphere: SmallHoles fills a small closed
// hole, keeps a large one and a balloon; RegionDepths in spacings and the merged scans'
// coverage rule; KeepSurface, Split and SplitHoles; Compute's filling end to end.
#include "boundary_stage.h"
#include "geometry.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

using namespace ib;

namespace {

/// Gated extraction (surface faces, then hole faces) of the unit sphere, the SODS being the
/// cells whose centre is above z = zc and farther than `radial` from the z axis.
GatedMarchingCubes::Result Extract(double zc, double radial, CoreMesh& all)
{
    const Lattice l = Lattice::Fit(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1), 20, 2);
    Sods gated(l.cells);
    test::AllCells(l).ForEach([&](const Index3& c) {
        const Eigen::Vector3d centre = l.Corner(c[0], c[1], c[2]) + Eigen::Vector3d::Constant(0.5 * l.cell_size);
        if (centre[2] > zc && centre.head<2>().norm() > radial)
            gated.Insert(c);
    });
    const auto mc = GatedMarchingCubes::Compute(l, gated, test::SphereDistance(1.0), all);
    UpdateFaceFace(all);
    return mc;
}

/// The cap above z = 0.3 with a small hole at its top: region `top` (the small hole, around
/// the north pole) and `bottom` (the rest of the sphere).
struct TwoHoles
{
    CoreMesh all;
    GatedMarchingCubes::Result mc;
    std::vector<char> inSurface;
    size_t top = 0, bottom = 1;
    std::vector<double> faces;  ///< per region

    TwoHoles() : mc(Extract(0.3, 0.25, all))
    {
        inSurface.assign(all.face.size(), 0);
        std::fill(inSurface.begin(), inSurface.begin() + long(mc.surface_faces), 1);
        faces.assign(mc.region_closed.size(), 0);
        for (size_t i = 0; i < mc.face_region.size(); ++i) {
            ++faces[size_t(mc.face_region[i])];
            if (vcg::Barycenter(all.face[mc.surface_faces + i])[2] > 0.9)
                top = size_t(mc.face_region[i]);
        }
        bottom = 1 - top;
    }
};

/// Distinct vertices of the faces f of m with inSurface[f] == which.
size_t VerticesOf(const CoreMesh& m, const std::vector<char>& inSurface, char which)
{
    std::set<size_t> used;
    for (size_t f = 0; f < m.face.size(); ++f)
        for (int i = 0; inSurface[f] == which && i < 3; ++i)
            used.insert(vcg::tri::Index(m, m.face[f].cV(i)));
    return used.size();
}

const Eigen::VectorXd kNoSpacing;

/// Samples where TwoHoles' SODS is: the unit sphere above z = 0.3, outside the cylinder of
/// radius 0.25 around the z axis.
Points SamplesOfTheCap()
{
    Points all, allNormals;
    test::SpherePoints(20000, 1.0, all, allNormals, 0.3);
    std::vector<Eigen::Index> kept;
    for (Eigen::Index i = 0; i < all.rows(); ++i)
        if (all.row(i).head<2>().norm() > 0.25)
            kept.push_back(i);
    return all(kept, Eigen::all);
}

} // namespace

TEST(BoundaryStage, SmallHolesFillsTheSmallClosedHoleAndKeepsTheLargeOne)
{
    TwoHoles h;
    ASSERT_EQ(h.mc.region_closed.size(), 2u);
    ASSERT_TRUE(h.mc.region_closed[0] && h.mc.region_closed[1]);
    ASSERT_NE(h.top, h.bottom);
    std::vector<int> edges;
    BoundaryStage::SmallHoles(h.all, h.inSurface, h.mc, 1000, nullptr, kNoSpacing, 1, edges);
    ASSERT_EQ(edges.size(), 2u);
    const int small = *std::min_element(edges.begin(), edges.end());
    const int large = *std::max_element(edges.begin(), edges.end());
    ASSERT_LT(small, large);
    // Small: fewer edges than min_edges; the large loop has more.
    std::vector<int> unused;
    std::vector<int> fill = BoundaryStage::SmallHoles(h.all, h.inSurface, h.mc, small + 1, nullptr, kNoSpacing, 1, unused);
    EXPECT_EQ(fill[h.top], 1);
    EXPECT_EQ(fill[h.bottom], 0);
    // Fewer than: a loop of exactly min_edges edges is not small.
    fill = BoundaryStage::SmallHoles(h.all, h.inSurface, h.mc, small, nullptr, kNoSpacing, 1, unused);
    EXPECT_EQ(fill[h.top], 0);
    EXPECT_EQ(fill[h.bottom], 0);
    // An open region (reaching the lattice border) is never filled.
    GatedMarchingCubes::Result open = h.mc;
    open.region_closed[h.top] = 0;
    fill = BoundaryStage::SmallHoles(h.all, h.inSurface, open, small + 1, nullptr, kNoSpacing, 1, unused);
    EXPECT_EQ(fill[h.top], 0);
}

TEST(BoundaryStage, ABalloonIsKeptAPatchInsideTheSameLoopIsFilled)
{
    // The SODS above z = -0.8 leaves a cap-sized hole at the bottom (a patch); above z = 0.8, the
    // hole behind a loop of the same size is the rest of the sphere (a balloon).
    for (const double zc : {-0.8, 0.8}) {
        CoreMesh all;
        const auto mc = Extract(zc, -1, all);
        ASSERT_EQ(mc.region_closed.size(), 1u);
        ASSERT_TRUE(mc.region_closed[0]);
        std::vector<char> inSurface(all.face.size(), 0);
        std::fill(inSurface.begin(), inSurface.begin() + long(mc.surface_faces), 1);
        std::vector<int> edges;
        const std::vector<int> fill =
            BoundaryStage::SmallHoles(all, inSurface, mc, 1000, nullptr, kNoSpacing, 1, edges);
        ASSERT_EQ(edges.size(), 1u);
        const double faces = double(mc.face_region.size()), bound =
            BoundaryStage::kPatchFacesPerSquaredEdge * edges[0] * edges[0];
        const bool balloon = zc > 0;
        EXPECT_EQ(faces > bound, balloon) << faces << " faces, loop of " << edges[0];
        EXPECT_EQ(fill[0], balloon ? 0 : 1) << zc;
    }
}

TEST(BoundaryStage, RegionDepthsAndTheCoverageRule)
{
    TwoHoles h;
    const Points P = SamplesOfTheCap();
    const SampleIndex samples(P);
    const Eigen::VectorXd tenth = Eigen::VectorXd::Constant(P.rows(), 0.1);
    std::vector<char> both(2, 1), bottomOnly(2, 0);
    bottomOnly[h.bottom] = 1;
    const std::vector<double> depth = BoundaryStage::RegionDepths(h.all, h.mc, both, samples, tenth, 1);
    // The north pole is 0.25 from the nearest sample, the south pole sqrt(2.6) = 1.61.
    EXPECT_NEAR(depth[h.top], 2.5, 0.4);
    EXPECT_NEAR(depth[h.bottom], 16.1, 0.5);
    const std::vector<double> some = BoundaryStage::RegionDepths(h.all, h.mc, bottomOnly, samples, tenth, 2);
    EXPECT_EQ(some[h.top], 0.0);
    EXPECT_DOUBLE_EQ(some[h.bottom], depth[h.bottom]);
    // Every loop large (min_edges 3): only the coverage rule fills, and only the shallow gap
    // (1.25 spacings of 0.2 deep, the other 8).
    const Eigen::VectorXd fifth = Eigen::VectorXd::Constant(P.rows(), 0.2);
    std::vector<int> unused;
    std::vector<int> fill = BoundaryStage::SmallHoles(h.all, h.inSurface, h.mc, 3, nullptr, fifth, 1, unused);
    EXPECT_EQ(fill[h.top], 0);
    EXPECT_EQ(fill[h.bottom], 0);
    fill = BoundaryStage::SmallHoles(h.all, h.inSurface, h.mc, 3, &samples, fifth, 1, unused);
    EXPECT_EQ(fill[h.top], 1);
    EXPECT_EQ(fill[h.bottom], 0);
}

TEST(BoundaryStage, ALoopIsCountedInTheEdgesOfItsOwnSampling)
{
    TwoHoles h;
    std::vector<int> edges;
    BoundaryStage::SmallHoles(h.all, h.inSurface, h.mc, 1000, nullptr, kNoSpacing, 1, edges);
    const int small = *std::min_element(edges.begin(), edges.end());
    ASSERT_GE(small, 6);
    const Points P = SamplesOfTheCap();
    const SampleIndex samples(P);
    // The same loop, too long for min_edges where the samples around it are as dense as the
    // median (a rim's samples read up to kRimSpacing times wider), is short where they are three
    // times as far apart beyond that: about a third as many of their spacings.
    const int minEdges = small / 2 + 1;
    const double median = 0.1;
    Eigen::VectorXd rimWide = Eigen::VectorXd::Constant(P.rows(), median), sparseTop = rimWide;
    for (Eigen::Index i = 0; i < P.rows(); ++i)
        if (P(i, 2) > 0.9) {
            rimWide[i] = BoundaryStage::kRimSpacing * median;
            sparseTop[i] = 3 * BoundaryStage::kRimSpacing * median;
        }
    std::vector<int> unused;
    BoundaryStage::Result margins;
    std::vector<int> fill = BoundaryStage::SmallHoles(h.all, h.inSurface, h.mc, minEdges, nullptr, rimWide, 1, unused,
                                                      &margins, nullptr, 0, &samples, median);
    EXPECT_EQ(fill[h.top], 0);
    EXPECT_EQ(fill[h.bottom], 0);
    EXPECT_EQ(margins.smallest_hole_kept, small);
    margins = BoundaryStage::Result();
    fill = BoundaryStage::SmallHoles(h.all, h.inSurface, h.mc, minEdges, nullptr, sparseTop, 1, unused, &margins,
                                     nullptr, 0, &samples, median);
    EXPECT_EQ(fill[h.top], 1);
    EXPECT_EQ(fill[h.bottom], 0);
    // Reported in edges at the median spacing.
    EXPECT_EQ(margins.largest_hole_filled, small / 3);
}

TEST(BoundaryStage, SplitAndKeepSurfaceCountFacesAndVertices)
{
    TwoHoles h;
    const size_t surfaceVertices = VerticesOf(h.all, h.inSurface, 1), holeVertices = VerticesOf(h.all, h.inSurface, 0);
    ASSERT_GT(surfaceVertices, 0u);
    CoreMesh surface, holes;
    BoundaryStage::Split(h.all, h.inSurface, 1, surface);
    BoundaryStage::Split(h.all, h.inSurface, 0, holes);
    EXPECT_EQ(size_t(surface.fn), h.mc.surface_faces);
    EXPECT_EQ(size_t(surface.vn), surfaceVertices);
    EXPECT_EQ(size_t(holes.fn), h.all.face.size() - h.mc.surface_faces);
    EXPECT_EQ(size_t(holes.vn), holeVertices);

    // KeepSurface: the surface in its order, its border edges (the loops) already known.
    std::vector<int> edges;
    BoundaryStage::SmallHoles(h.all, h.inSurface, h.mc, 0, nullptr, kNoSpacing, 1, edges);
    const vcg::Point3d first = h.all.face[0].cP(0), last = h.all.face[h.mc.surface_faces - 1].cP(2);
    BoundaryStage::KeepSurface(h.all, h.inSurface);
    ASSERT_EQ(h.all.face.size(), h.mc.surface_faces);
    EXPECT_EQ(h.all.vert.size(), surfaceVertices);
    EXPECT_EQ(h.all.face[0].cP(0), first);
    EXPECT_EQ(h.all.face.back().cP(2), last);
    int borders = 0;
    for (const CoreFace& f : h.all.face)
        for (int i = 0; i < 3; ++i)
            borders += f.cFFp(i) == &f;
    EXPECT_EQ(borders, edges[0] + edges[1]);
    EXPECT_EQ(test::Check(h.all).border_edges, borders);  // what VCG's own adjacency finds
}

TEST(BoundaryStage, SplitHolesGivesATwoManifold)
{
    TwoHoles h;
    CoreMesh holes;
    BoundaryStage::SplitHoles(h.all, h.inSurface, holes);
    ASSERT_GT(holes.fn, 0);
    EXPECT_LE(size_t(holes.fn), h.all.face.size() - h.mc.surface_faces);
    const auto t = test::Check(holes);
    EXPECT_EQ(t.non_manifold_edges, 0);
    EXPECT_EQ(t.non_manifold_vertices, 0);
    EXPECT_GT(t.border_edges, 0);
    EXPECT_TRUE(t.oriented);
}

TEST(BoundaryStage, ComputeFillsTheSmallHoleOnly)
{
    TwoHoles h;
    Points P, N;
    test::SpherePoints(4000, 1.0, P, N, 0.3);
    const SampleIndex samples(P);
    const Eigen::VectorXd spacing = Eigen::VectorXd::Constant(P.rows(), 0.05);
    BoundaryStage::Param p;
    p.boundary_trim = 0;
    p.boundary_smoothing = 0;
    p.boundary_fit = false;
    p.min_support = 0;
    p.sample_spacing = 0.05;
    p.threads = 1;
    std::vector<int> edges;
    BoundaryStage::SmallHoles(h.all, h.inSurface, h.mc, 0, nullptr, kNoSpacing, 1, edges);
    p.min_boundary_edges = std::min(edges[0], edges[1]) + 1;
    const test::SphereDistance f(1.0);
    std::vector<char> inSurface;
    p.reference = true;  // nothing filled
    BoundaryStage::Result r = BoundaryStage::Compute(h.all, h.mc, samples, spacing, Points(0, 3), f, p, inSurface);
    EXPECT_EQ(r.holes_filled, 0);
    EXPECT_TRUE(r.loops_before_filling.empty());
    EXPECT_EQ(size_t(std::count(inSurface.begin(), inSurface.end(), 1)), h.mc.surface_faces);
    p.reference = false;
    r = BoundaryStage::Compute(h.all, h.mc, samples, spacing, Points(0, 3), f, p, inSurface);
    EXPECT_EQ(r.loops_before_filling.size(), 2u);
    EXPECT_EQ(r.holes_filled, 1);
    EXPECT_EQ(r.faces_cut_at_seams, 0u);
    EXPECT_EQ(r.faces_trimmed, 0u);
    EXPECT_EQ(r.boundary_vertices_fitted, 0u);
    EXPECT_EQ(size_t(std::count(inSurface.begin(), inSurface.end(), 1)),
              h.mc.surface_faces + size_t(h.faces[h.top]) - r.faces_unpinched - r.faces_unsupported);
    for (size_t i = 0; i < h.mc.face_region.size(); ++i)
        if (size_t(h.mc.face_region[i]) == h.bottom) {
            ASSERT_EQ(inSurface[h.mc.surface_faces + i], 0) << i;
        }
}
