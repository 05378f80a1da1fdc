// Signed distance to a mesh as the implicit function: an icosphere, with and without a crack;
// how far points lie past an open mesh's border.
#include "geometry.h"
#include "implicit/mesh_distance.h"
#include "reconstruct.h"

#include <gtest/gtest.h>

using namespace ib;

namespace {
/// Points on random rays at the given radii.
Points Shell(int n, double radius, unsigned seed)
{
    std::srand(seed);
    Points Q(n, 3);
    for (int i = 0; i < n; ++i) {
        Eigen::Vector3d d = Eigen::Vector3d::Random().normalized();
        Q.row(i) = (radius * d).transpose();
    }
    return Q;
}
} // namespace

TEST(MeshDistance, IsTheSignedDistanceToAClosedMesh)
{
    Points V;
    Faces F;
    test::Icosphere(V, F);
    const MeshDistance f(V, F);
    EXPECT_EQ(f.Statistics().border_edges, 0);
    for (double r : {0.3, 0.9, 0.99, 1.01, 1.2, 3.0}) {
        const Points Q = Shell(500, r, 7);
        Eigen::VectorXd v(Q.rows());
        f.Eval(Q, v);
        // The icosphere's faces lie within 0.0025 inside the unit sphere.
        EXPECT_LT((v.array() - (r - 1)).abs().maxCoeff(), 0.003) << r;
        EXPECT_TRUE(r < 1 ? (v.array() < 0).all() : (v.array() > 0).all()) << r;
    }
}

TEST(MeshDistance, KeepsAUsableSignAcrossACrack)
{
    // Remove a strip of faces: the mesh is open, the sign must still be right near it.
    Points V;
    Faces F;
    test::Icosphere(V, F);
    std::vector<int> kept;
    for (Eigen::Index i = 0; i < F.rows(); ++i) {
        const Eigen::Vector3d c = (V.row(F(i, 0)) + V.row(F(i, 1)) + V.row(F(i, 2))).transpose() / 3;
        if (!(std::abs(c[0]) < 0.03 && c[2] > 0.5))
            kept.push_back(int(i));
    }
    const Faces cracked = F(kept, Eigen::all);
    ASSERT_LT(cracked.rows(), F.rows());
    const MeshDistance f(V, cracked);
    EXPECT_GT(f.Statistics().border_edges, 0);
    int wrong = 0, total = 0;
    for (double r : {0.9, 0.95, 1.05, 1.1}) {
        const Points Q = Shell(2000, r, 11);
        Eigen::VectorXd v(Q.rows());
        f.Eval(Q, v);
        for (Eigen::Index i = 0; i < Q.rows(); ++i, ++total)
            wrong += (v[i] < 0) != (r < 1);
    }
    EXPECT_EQ(wrong, 0) << " of " << total;
}

TEST(MeshDistance, RejectsUnusableMeshes)
{
    const Points V = Points::Random(5, 3);
    EXPECT_THROW(MeshDistance(V, Faces(0, 3)), std::invalid_argument);
    Faces bad(1, 3);
    bad << 0, 1, 7;
    EXPECT_THROW(MeshDistance(V, bad), std::invalid_argument);
    Faces flat(1, 3);
    flat << 0, 0, 1;
    EXPECT_THROW(MeshDistance(V, flat), std::invalid_argument);
}

TEST(MeshDistance, SamplesOnHalfTheSphereGiveOneLoopAtTheRim)
{
    Points V;
    Faces F;
    test::Icosphere(V, F);
    const MeshDistance sphere(V, F);
    Points P, N;
    test::SpherePoints(4000, 1.0, P, N, 0.0);  // the upper half only
    Reconstruction::Param p;
    p.implicit = Reconstruction::Implicit::Given;
    p.given = &sphere;
    p.resolution = 40;
    CoreMesh m;
    const auto r = Reconstruction::Compute(P, N, p, m);
    ASSERT_EQ(r.loops.size(), 1u);
    double rimError = 0;
    for (int v : r.loops[0].vertices)
        rimError = std::max(rimError, std::abs(m.vert[size_t(v)].cP()[2]));
    EXPECT_LT(rimError, 1.5 * r.cell_size);  // the rim is the equator
    // The surface follows the mesh (within a fraction of a cell) and stays on the sampled half.
    double off = 0, lowest = 1;
    for (const auto& v : m.vert) {
        off = std::max(off, std::abs(v.cP().Norm() - 1));
        lowest = std::min(lowest, v.cP()[2]);
    }
    EXPECT_LT(off, 0.1 * r.cell_size);
    EXPECT_GT(lowest, -1.5 * r.cell_size);
    const auto t = test::Check(m);
    EXPECT_EQ(t.non_manifold_edges, 0);
    EXPECT_TRUE(t.oriented);

    p.given = nullptr;
    EXPECT_THROW(Reconstruction::Compute(P, N, p, m), InputError);
}

TEST(MeshDistance, PastBorderIsTheInPlaneDistanceBeyondAnOpenEdge)
{
    // The unit square of two triangles in z = 0: its four edges are its border.
    Points V;
    Faces F;
    test::UnitSquare(V, F);
    const MeshDistance square(V, F);
    Points Q(5, 3);
    Q << 0.5, 0.5, 0.8,   // over the inside, high above it
        0.5, 0.5, -0.1,   // under it
        0.5, 0.5, 0,      // on the diagonal, an edge both faces share
        1.3, 0.5, 0.4,    // 0.3 past the edge x = 1, 0.4 above
        -0.3, -0.4, 0;    // 0.5 past the corner at the origin
    const Eigen::VectorXd past = square.PastBorder(Q);
    EXPECT_EQ(past[0], 0);
    EXPECT_EQ(past[1], 0);
    EXPECT_EQ(past[2], 0);
    EXPECT_NEAR(past[3], 0.3, 1e-12);
    EXPECT_NEAR(past[4], 0.5, 1e-12);

    // On a closed mesh nothing is past the border.
    Points S;
    Faces T;
    test::Icosphere(S, T, 2);
    EXPECT_EQ(MeshDistance(S, T).PastBorder(Shell(200, 1.5, 3)).maxCoeff(), 0);
}

TEST(MeshDistance, PastBorderIsTheInPlaneDistanceToAPlaneWithAHole)
{
    // A 10 x 10 grid of unit squares in z = 0 without its 2 x 2 middle squares: the region
    // [0, 10]^2 less (4, 6)^2. Its closest point to p is the region's closest point to p's
    // (x, y), on the border when (x, y) is outside the region; PastBorder is their distance.
    // Points over the inside far from any border are answered without the closest-point
    // search, those near it by the search: both must agree with the plane's geometry.
    CoreMesh grid;
    test::Grid(10, 1.0, grid);
    for (CoreMesh::FaceType& f : grid.face) {
        const vcg::Point3d c = vcg::Barycenter(f);
        if (c[0] > 4 && c[0] < 6 && c[1] > 4 && c[1] < 6)
            vcg::tri::Allocator<CoreMesh>::DeleteFace(grid, f);
    }
    vcg::tri::Allocator<CoreMesh>::CompactEveryVector(grid);
    Points V;
    Faces F;
    test::Matrices(grid, V, F);
    const MeshDistance plane(V, F);

    std::srand(7);
    const int n = 4000;
    Points Q(n, 3);
    Eigen::VectorXd expected(n);
    for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d r = Eigen::Vector3d::Random();  // in [-1, 1]^3
        const double x = 5 + 7 * r[0], y = 5 + 7 * r[1];
        Q.row(i) << x, y, 0.8 * r[2];
        const double outside = std::hypot(std::max({0.0, -x, x - 10}), std::max({0.0, -y, y - 10}));
        const bool inHole = x > 4 && x < 6 && y > 4 && y < 6;
        expected[i] = inHole ? std::min({x - 4, 6 - x, y - 4, 6 - y}) : outside;
    }
    const Eigen::VectorXd past = plane.PastBorder(Q);
    int over = 0;
    for (int i = 0; i < n; ++i) {
        EXPECT_NEAR(past[i], expected[i], 1e-9) << "at " << Q.row(i);
        over += expected[i] == 0;
    }
    EXPECT_GT(over, n / 4);  // many points are over the plane, inside its border

    // The same, asked row by row across a lattice, as the faces of marching cubes come: each
    // point is near the one before, so most are answered by an earlier point's margin.
    const int side = 141;  // x, y from -2 to 12, 0.1 apart
    Points R(side * side, 3);
    Eigen::VectorXd rowExpected(R.rows());
    for (int j = 0; j < side; ++j)
        for (int i = 0; i < side; ++i) {
            const double x = -2 + 0.1 * i, y = -2 + 0.1 * j;
            R.row(j * side + i) << x, y, 0.3;
            const double outside = std::hypot(std::max({0.0, -x, x - 10}), std::max({0.0, -y, y - 10}));
            const bool inHole = x > 4 && x < 6 && y > 4 && y < 6;
            rowExpected[j * side + i] = inHole ? std::min({x - 4, 6 - x, y - 4, 6 - y}) : outside;
        }
    const Eigen::VectorXd rowPast = plane.PastBorder(R);
    for (Eigen::Index i = 0; i < R.rows(); ++i)
        EXPECT_NEAR(rowPast[i], rowExpected[i], 1e-9) << "at " << R.row(i);
}
