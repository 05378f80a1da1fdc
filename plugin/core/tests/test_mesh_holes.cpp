// Holes of an input mesh kept open: a wavy sheet given as a triangle mesh, with holes smaller
// than the tangent disks bridge.
#include "geometry.h"
#include "reconstruct.h"

#include <gtest/gtest.h>

using namespace ib;

namespace {

/// A wavy sheet over [0, 1]^2 triangulated on a grid of 40 × 40 squares (spacing 0.025), with
/// the vertices within `hole` of (0.5, 0.5) (in the plane) and their faces left out; unit
/// normals N.
void HoledSheet(double hole, Points& V, Points& N, Faces& F)
{
    const int n = 40;
    const double h = 1.0 / n;
    auto z = [](double x, double y) { return 0.05 * std::sin(4 * x) * std::cos(3 * y); };
    std::vector<int> row(size_t((n + 1) * (n + 1)), -1);
    std::vector<Eigen::Vector3d> ps, ns;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const double x = i * h, y = j * h;
            if (std::hypot(x - 0.5, y - 0.5) < hole)
                continue;
            row[size_t(j * (n + 1) + i)] = int(ps.size());
            ps.emplace_back(x, y, z(x, y));
            const double dx = 0.2 * std::cos(4 * x) * std::cos(3 * y), dy = -0.15 * std::sin(4 * x) * std::sin(3 * y);
            ns.push_back(Eigen::Vector3d(-dx, -dy, 1).normalized());
        }
    std::vector<Eigen::Vector3i> fs;
    auto at = [&](int i, int j) { return row[size_t(j * (n + 1) + i)]; };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const int a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
            if (a >= 0 && b >= 0 && c >= 0)
                fs.emplace_back(a, b, c);
            if (a >= 0 && c >= 0 && d >= 0)
                fs.emplace_back(a, c, d);
        }
    V.resize(Eigen::Index(ps.size()), 3);
    N.resize(Eigen::Index(ps.size()), 3);
    F.resize(Eigen::Index(fs.size()), 3);
    for (size_t k = 0; k < ps.size(); ++k) {
        V.row(Eigen::Index(k)) = ps[k].transpose();
        N.row(Eigen::Index(k)) = ns[k].transpose();
    }
    for (size_t k = 0; k < fs.size(); ++k)
        F.row(Eigen::Index(k)) = fs[k].transpose();
}

size_t Loops(const Points& V, const Points& N, const Faces& F, int minEdges = BoundaryStage::kDefaultMinBoundaryEdges)
{
    Reconstruction::Param p;
    p.faces = F;
    p.min_boundary_edges = minEdges;
    CoreMesh m;
    const Reconstruction::Result r = Reconstruction::Compute(V, N, p, m);
    const test::Topology t = test::Check(m);
    EXPECT_EQ(t.non_manifold_edges, 0);
    EXPECT_TRUE(t.oriented);
    return r.loops.size();
}

} // namespace

TEST(MeshHoles, AHoleOfTheTriangulationStaysOpenWhereTheDisksBridgeIt)
{
    Points V, N;
    Faces F;
    HoledSheet(0.05, V, N, F);  // an empty circle of about two spacings
    EXPECT_EQ(Loops(V, N, Faces()), 1u) << "as a point cloud the hole is undersampling";
    EXPECT_EQ(Loops(V, N, F), 2u) << "the mesh says it is a hole";
}

TEST(MeshHoles, AMissingVertexIsUndersamplingAsInAPointCloud)
{
    Points V, N;
    Faces F;
    HoledSheet(0.01, V, N, F);  // one vertex and its six faces
    ASSERT_EQ(V.rows(), 41 * 41 - 1);
    EXPECT_EQ(Loops(V, N, F), 1u) << "its opening has fewer than min_boundary_edges edges";
    EXPECT_EQ(Loops(V, N, F, 0), 2u) << "min_boundary_edges 0 keeps every hole";
}

TEST(MeshHoles, AClosedMeshStaysClosed)
{
    Points V, N;
    Faces F;
    test::Icosphere(V, F);
    N = V.rowwise().normalized();
    EXPECT_EQ(Loops(V, N, F), 0u);
}

TEST(MeshHoles, FacesOutsideTheLayerAreRefused)
{
    Points V, N;
    Faces F;
    HoledSheet(0.05, V, N, F);
    F(3, 1) = int(V.rows());
    Reconstruction::Param p;
    p.faces = F;
    CoreMesh m;
    try {
        Reconstruction::Compute(V, N, p, m);
        FAIL() << "accepted a face index past the last vertex";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("1 of " + std::to_string(F.rows()) + " faces refer to vertices"),
                  std::string::npos) << e.what();
    }
}

TEST(MeshHoles, CoveredTellsHoleRegionsOverTheMeshFromThosePastItsBorder)
{
    // The input: the unit square in z = 0. The extraction: a grid over [0, 1.5] x [0, 1] in
    // z = 0.1 whose faces are all hole faces, region 0 left of x = 0.9 (over the square), region
    // 1 right of x = 1.1 (past its border), region 2 across the border.
    Points V;
    Faces F;
    test::UnitSquare(V, F);
    const MeshDistance square(V, F);
    CoreMesh all;
    test::Grid(30, 0.05, all);
    std::vector<int> region;
    for (const CoreFace& f : all.face) {
        const vcg::Point3d c = vcg::Barycenter(f);
        region.push_back(c[1] > 0.5 ? 2 : c[0] < 0.9 ? 0 : c[0] > 1.1 ? 1 : 2);
    }
    for (CoreVertex& v : all.vert)
        v.P()[2] = 0.1;
    const std::vector<char> covered = MeshHoles::Covered(all, 0, region, {1, 1, 1}, square, 0.05);
    EXPECT_EQ(covered, (std::vector<char>{1, 0, 0}));
    EXPECT_EQ(MeshHoles::Covered(all, 0, region, {0, 1, 1}, square, 0.05), (std::vector<char>{0, 0, 0}))
        << "only the regions asked about";
}

TEST(MeshHoles, CoveredLeavesOpenAHoleWhoseFacesBalloonAwayFromTheMesh)
{
    // The input: the unit square in z = 0, sampled every 0.1. The extraction: hole faces over
    // it (x, y < 0.9), region 0 at z = 0.1 (one spacing above the square), region 1 at z = 0.3
    // (three: a fill that balloons away from the triangles), region 2 the slope between them;
    // region 3 reaches past the square's border. Only region 0 fills the square's surface.
    Points V;
    Faces F;
    test::UnitSquare(V, F);
    const MeshDistance square(V, F);
    Points samples(121, 3);
    for (int j = 0, k = 0; j <= 10; ++j)
        for (int i = 0; i <= 10; ++i, ++k)
            samples.row(k) << 0.1 * i, 0.1 * j, 0;
    const SampleIndex index(samples);
    const Eigen::VectorXd spacing = Eigen::VectorXd::Constant(samples.rows(), 0.1);
    CoreMesh all;
    test::Grid(30, 0.05, all);
    for (CoreVertex& v : all.vert)
        v.P()[2] = v.P()[1] < 0.42 ? 0.1 : v.P()[1] > 0.58 ? 0.3 : 0.1 + 0.2 * (v.P()[1] - 0.42) / 0.16;
    std::vector<int> region;
    for (const CoreFace& f : all.face) {
        const vcg::Point3d c = vcg::Barycenter(f);
        region.push_back(c[0] > 0.9 || c[1] > 0.9 ? 3 : c[1] < 0.4 ? 0 : c[1] > 0.6 ? 1 : 2);
    }
    EXPECT_EQ(MeshHoles::Covered(all, 0, region, {1, 1, 1, 1}, square, 0.05, &index, &spacing),
              (std::vector<char>{1, 0, 0, 0}));
    EXPECT_EQ(MeshHoles::Covered(all, 0, region, {1, 1, 1, 1}, square, 0.05), (std::vector<char>{1, 1, 1, 0}))
        << "without the samples, only over the triangles is asked";
}
