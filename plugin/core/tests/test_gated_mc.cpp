#include "gated_mc.h"
#include "geometry.h"

#include <gtest/gtest.h>

using namespace ib;

TEST(GatedMarchingCubes, SphereIsAClosedOrientedManifoldOnTheSphere)
{
    const Lattice l = Lattice::Fit(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1), 24, 2);
    CoreMesh m;
    const auto stats = GatedMarchingCubes::Compute(l, test::AllCells(l), test::SphereDistance(1.0), m);
    EXPECT_EQ(stats.evaluations, size_t(l.CornerCount()));
    ASSERT_GT(m.fn, 1000);

    double worst = 0;
    for (const auto& v : m.vert)
        worst = std::max(worst, std::abs(v.cP().Norm() - 1.0));
    EXPECT_LT(worst, 0.05 * l.cell_size);  // linear interpolation of an exact distance

    const auto t = test::Check(m);
    EXPECT_EQ(t.non_manifold_edges, 0);
    EXPECT_EQ(t.non_manifold_vertices, 0);
    EXPECT_EQ(t.border_edges, 0);
    EXPECT_TRUE(t.oriented);
    EXPECT_EQ(m.vn - (t.border_edges + 3 * m.fn) / 2 + m.fn, 2);  // Euler characteristic of a sphere

    // Normals point outwards (to positive values). The sphere passes exactly through some
    // lattice corners here, where marching cubes makes zero-area triangles with no direction.
    int inward = 0;
    for (auto& f : m.face)
        inward += vcg::TriangleNormal(f).dot(vcg::Barycenter(f)) < -1e-15;
    EXPECT_EQ(inward, 0);
}

TEST(GatedMarchingCubes, EmitsTrianglesOnlyInSodsCells)
{
    const Lattice l = Lattice::Fit(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1), 16, 2);
    Sods upper(l.cells);  // cells whose centre is above z = 0.3
    test::AllCells(l).ForEach([&](const Index3& c) {
        if (l.Corner(c[0], c[1], c[2])[2] + 0.5 * l.cell_size > 0.3)
            upper.Insert(c);
    });
    CoreMesh m;
    GatedMarchingCubes::Param noHoles;
    noHoles.holes = false;
    GatedMarchingCubes::Compute(l, upper, test::SphereDistance(1.0), m, noHoles);
    ASSERT_GT(m.fn, 0);
    for (const auto& f : m.face)
        EXPECT_GT(vcg::Barycenter(f)[2], 0.3 - l.cell_size);
    const auto t = test::Check(m);
    EXPECT_EQ(t.non_manifold_edges, 0);
    EXPECT_GT(t.border_edges, 0);  // a spherical cap: open
}

TEST(GatedMarchingCubes, HoleTrianglesCloseTheSurfaceAndShareItsVertices)
{
    // SODS: cells whose centre is above z = 0.3 and outside a small cylinder around the z axis,
    // so the cap gets two holes: the big bottom opening and a small one at the top.
    const Lattice l = Lattice::Fit(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1), 20, 2);
    Sods gated(l.cells);
    test::AllCells(l).ForEach([&](const Index3& c) {
        const Eigen::Vector3d centre = l.Corner(c[0], c[1], c[2]) + Eigen::Vector3d::Constant(0.5 * l.cell_size);
        if (centre[2] > 0.3 && centre.head<2>().norm() > 0.25)
            gated.Insert(c);
    });
    CoreMesh m;
    const auto r = GatedMarchingCubes::Compute(l, gated, test::SphereDistance(1.0), m);
    ASSERT_GT(r.surface_faces, 0u);
    ASSERT_EQ(r.face_region.size(), m.face.size() - r.surface_faces);
    ASSERT_EQ(r.region_closed.size(), 2u);  // the two holes
    EXPECT_TRUE(r.region_closed[0] && r.region_closed[1]);
    EXPECT_FALSE(r.hole_search_capped);
    // Surface + holes: the closed sphere, one vertex per crossed lattice edge.
    const auto t = test::Check(m);
    EXPECT_EQ(t.border_edges, 0);
    EXPECT_EQ(t.non_manifold_edges, 0);
    EXPECT_TRUE(t.oriented);
    EXPECT_EQ(m.vn - (3 * m.fn) / 2 + m.fn, 2);
    // Hole cells are outside the SODS and only where the surface is.
    EXPECT_GT(r.hole_cells, 0u);
    EXPECT_LT(r.evaluations, size_t(l.CornerCount()));
}

TEST(GatedMarchingCubes, HoleRegionReachingTheLatticeBorderIsOpen)
{
    // A plane z = 0.1 through the whole lattice, SODS only in the middle: the hole region
    // around it runs to the lattice border.
    class Plane : public ImplicitFunction
    {
    public:
        void Eval(const Points& Q, Eigen::Ref<Eigen::VectorXd> v) const override { v = Q.col(2).array() - 0.1; }
    };
    const Lattice l = Lattice::Fit(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1), 12, 1);
    Sods middle(l.cells);
    test::AllCells(l).ForEach([&](const Index3& c) {
        if ((l.Corner(c[0], c[1], c[2]) + Eigen::Vector3d::Constant(0.5 * l.cell_size)).norm() < 0.5)
            middle.Insert(c);
    });
    CoreMesh m;
    const auto r = GatedMarchingCubes::Compute(l, middle, Plane(), m);
    ASSERT_EQ(r.region_closed.size(), 1u);
    EXPECT_FALSE(r.region_closed[0]);
}

namespace {
using Triangle = std::array<std::array<double, 3>, 3>;

// The faces of m as vertex position triples, rotated to start at the smallest vertex (same
// orientation), optionally only those whose centroid lies in a cell of `within`.
std::vector<Triangle> Triangles(const CoreMesh& m, const Lattice& l, const Sods* within = nullptr)
{
    std::vector<Triangle> out;
    for (const auto& f : m.face) {
        const vcg::Point3d centre = vcg::Barycenter(f);
        if (within && !within->Contains(l.CellOf(Eigen::Vector3d(centre[0], centre[1], centre[2]))))
            continue;
        Triangle t;
        for (int k = 0; k < 3; ++k)
            t[size_t(k)] = {f.cP(k)[0], f.cP(k)[1], f.cP(k)[2]};
        std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
        out.push_back(t);
    }
    std::sort(out.begin(), out.end());
    return out;
}
} // namespace

TEST(GatedMarchingCubes, TheThreeExtractionsAgreeInSodsCells)
{
    // A sphere gated by a tilted slab: open surface, two hole regions.
    const Lattice l = Lattice::Fit(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1), 22, 2);
    Sods slab(l.cells);
    test::AllCells(l).ForEach([&](const Index3& c) {
        const Eigen::Vector3d centre = l.Corner(c[0], c[1], c[2]) + Eigen::Vector3d::Constant(0.5 * l.cell_size);
        if (std::abs(centre[0] + 0.3 * centre[2]) < 0.6)
            slab.Insert(c);
    });
    const test::SphereDistance sphere(0.9);
    CoreMesh sparse, full, plain;
    GatedMarchingCubes::Param p;
    const auto rs = GatedMarchingCubes::Compute(l, slab, sphere, sparse, p);
    p.extraction = GatedMarchingCubes::Extraction::FullLatticeGated;
    const auto rf = GatedMarchingCubes::Compute(l, slab, sphere, full, p);
    p.extraction = GatedMarchingCubes::Extraction::Plain;
    const auto rp = GatedMarchingCubes::Compute(l, slab, sphere, plain, p);

    EXPECT_EQ(rf.evaluations, size_t(l.CornerCount()));
    EXPECT_EQ(rp.evaluations, size_t(l.CornerCount()));
    EXPECT_LT(rs.evaluations, rf.evaluations);
    // The sparse extraction evaluates the corners of the SODS cells and of the hole cells,
    // no more than a cell's layer beyond the crossed cells.
    EXPECT_GE(rs.evaluations, rs.crossed_corners);
    EXPECT_EQ(rs.crossed_corners, rf.crossed_corners);

    // Same mesh, same order, for the two gated extractions (surface and holes).
    ASSERT_EQ(sparse.vert.size(), full.vert.size());
    ASSERT_EQ(sparse.face.size(), full.face.size());
    EXPECT_EQ(rs.surface_faces, rf.surface_faces);
    EXPECT_EQ(rs.face_region, rf.face_region);
    for (size_t i = 0; i < sparse.vert.size(); ++i)
        ASSERT_EQ(sparse.vert[i].cP(), full.vert[i].cP()) << i;

    // Plain marching cubes: the closed sphere; its triangles in SODS cells are the surface's.
    EXPECT_EQ(rp.surface_faces, plain.face.size());
    EXPECT_TRUE(rp.face_region.empty());
    EXPECT_EQ(test::Check(plain).border_edges, 0);
    CoreMesh surfaceOnly;
    p.extraction = GatedMarchingCubes::Extraction::SodsDriven;
    p.holes = false;
    GatedMarchingCubes::Compute(l, slab, sphere, surfaceOnly, p);
    const auto gated = Triangles(surfaceOnly, l);
    ASSERT_GT(gated.size(), 100u);
    EXPECT_EQ(Triangles(plain, l, &slab), gated);
}
