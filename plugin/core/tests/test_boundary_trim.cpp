// The boundary trim: unsupported faces peeled off from the boundary, scraps and pieces
// supported by too few samples removed.
#include "boundary_trim.h"
#include "geometry.h"
#include "spacing.h"

#include <gtest/gtest.h>

using namespace ib;

namespace {
using test::AddTriangle;

/// Samples on a square grid of spacing s over [0, w] × [0, 1] at z = 0.
Points HalfScan(double s, double w)
{
    std::vector<Eigen::RowVector3d> pts;
    for (int j = 0; j * s <= 1 + 1e-9; ++j)
        for (int i = 0; i * s <= w + 1e-9; ++i)
            pts.emplace_back(i * s, j * s, 0);
    Points P(Eigen::Index(pts.size()), 3);
    for (size_t i = 0; i < pts.size(); ++i)
        P.row(Eigen::Index(i)) = pts[i];
    return P;
}

double CentroidX(const CoreFace& f)
{
    return vcg::Barycenter(f)[0];
}
} // namespace

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

TEST(BoundaryTrim, PeelsTheFacesPastTheSamplesAndKeepsTheGapsBetweenThem)
{
    // A 10 × 10 grid over [0, 1]^2, samples on its left half only (spacing 0.05): the faces
    // right of x = 0.5 have every sample on one side and go; those on the left are farther than
    // the reach from every sample too (0.024 > 0.0125) but surrounded by samples, and stay.
    CoreMesh m;
    test::Grid(10, 0.1, m);
    const Points P = HalfScan(0.05, 0.5);
    const SampleIndex samples(P);
    std::vector<char> inSurface(m.face.size(), 1);
    EXPECT_EQ(BoundaryTrim::Compute(m, samples, Eigen::VectorXd::Constant(P.rows(), 0.0125), inSurface, 2), 100u);
    for (size_t f = 0; f < m.face.size(); ++f)
        EXPECT_EQ(inSurface[f] != 0, CentroidX(m.face[f]) < 0.5) << f;

    // A reach beyond every face: nothing is far, nothing goes.
    std::vector<char> all(m.face.size(), 1);
    EXPECT_EQ(BoundaryTrim::Compute(m, samples, Eigen::VectorXd::Constant(P.rows(), 1.0), all), 0u);
    EXPECT_EQ(std::count(all.begin(), all.end(), 1), 200);
}

TEST(BoundaryTrim, OnlyFacesReachableFromTheBoundaryArePeeled)
{
    // Reach 0.05: the faces right of x = 0.55 are far from the left half's samples and go (the
    // column at x = 0.533 is within reach). With samples along the grid's border too, every
    // face at the boundary is supported: the same unsupported faces inside are left alone.
    CoreMesh m;
    test::Grid(10, 0.1, m);
    Points P = HalfScan(0.05, 0.5);
    std::vector<char> inSurface(m.face.size(), 1);
    EXPECT_EQ(BoundaryTrim::Compute(m, SampleIndex(P), Eigen::VectorXd::Constant(P.rows(), 0.05), inSurface), 90u);
    for (size_t f = 0; f < m.face.size(); ++f)
        EXPECT_EQ(inSurface[f] != 0, CentroidX(m.face[f]) < 0.55) << f;

    const Eigen::Index half = P.rows();
    P.conservativeResize(half + 4 * 20, 3);
    for (int k = 0; k < 20; ++k) {
        P.row(half + 4 * k) << 0.05 * k, 0, 0;
        P.row(half + 4 * k + 1) << 1, 0.05 * k, 0;
        P.row(half + 4 * k + 2) << 1 - 0.05 * k, 1, 0;
        P.row(half + 4 * k + 3) << 0, 1 - 0.05 * k, 0;
    }
    std::vector<char> ringed(m.face.size(), 1);
    EXPECT_EQ(BoundaryTrim::Compute(m, SampleIndex(P), Eigen::VectorXd::Constant(P.rows(), 0.05), ringed), 0u);
}

TEST(BoundaryTrim, PiecesWithTooFewNearestSamplesAreRemoved)
{
    // A 4 × 4 grid with a sample at each of its 25 vertices, and a lone triangle far away with
    // one sample beside it: the triangle's piece has one distinct nearest sample.
    CoreMesh m;
    test::Grid(4, 0.25, m);
    AddTriangle(m, vcg::Point3d(5, 0, 0), vcg::Point3d(6, 0, 0), vcg::Point3d(5, 1, 0));
    vcg::tri::UpdateTopology<CoreMesh>::FaceFace(m);
    Points P(26, 3);
    for (int v = 0; v < 25; ++v)
        P.row(v) << m.vert[size_t(v)].cP()[0], m.vert[size_t(v)].cP()[1], 0;
    P.row(25) << 5.3, 0.3, 0.1;
    const SampleIndex samples(P);
    std::vector<char> inSurface(m.face.size(), 1);
    EXPECT_EQ(BoundaryTrim::RemoveUnsupported(m, samples, 1, inSurface), 0u);
    EXPECT_EQ(BoundaryTrim::RemoveUnsupported(m, samples, 10, inSurface), 1u);
    EXPECT_EQ(inSurface.back(), 0);
    EXPECT_EQ(std::count(inSurface.begin(), inSurface.end(), 1), 32);
    EXPECT_EQ(BoundaryTrim::RemoveUnsupported(m, samples, 26, inSurface), 32u);  // 25 distinct at most
}

TEST(BoundaryTrim, AGapBesideASparserPartIsNoEdge)
{
    // Samples 0.02 apart left of x = 0.5 and 0.1 apart (5 times sparser) right of x = 0.62: the
    // faces in the gap next to the dense part have only dense samples among their nearest, all
    // to one side. Looking across the gap they find the sparse samples within 2 of their
    // spacings and stay; without the spacings they are peeled from the border in. With the
    // sparse part gone, the faces past the dense part's edge go either way.
    CoreMesh m;
    test::Grid(25, 0.04, m);
    const Points dense = HalfScan(0.02, 0.5);
    Points P = dense;
    for (int j = 0; j <= 10; ++j)
        for (int i = 0; 0.62 + 0.1 * i <= 1 + 1e-9; ++i) {
            P.conservativeResize(P.rows() + 1, 3);
            P.row(P.rows() - 1) << 0.62 + 0.1 * i, 0.1 * j, 0;
        }
    const SampleIndex samples(P);
    const Eigen::VectorXd spacing = SampleSpacing::Local(samples);
    auto besideDense = [&](const std::vector<char>& inSurface) {  // the cells over 0.52 < x < 0.56, inside rows
        int kept = 0;
        for (size_t f = 0; f < m.face.size(); ++f) {
            const vcg::Point3d c = vcg::Barycenter(m.face[f]);
            kept += inSurface[f] && c[0] > 0.52 && c[0] < 0.56 && c[1] > 0.04 && c[1] < 0.96;
        }
        return kept;
    };
    std::vector<char> across(m.face.size(), 1), blind(m.face.size(), 1);
    BoundaryTrim::Compute(m, samples, Eigen::VectorXd(0.25 * spacing), across, 1, &spacing);
    BoundaryTrim::Compute(m, samples, Eigen::VectorXd(0.25 * spacing), blind, 1);
    EXPECT_EQ(besideDense(across), 23 * 2);
    EXPECT_EQ(besideDense(blind), 0);

    const SampleIndex alone(dense);
    const Eigen::VectorXd own = SampleSpacing::Local(alone);
    std::vector<char> edge(m.face.size(), 1);
    BoundaryTrim::Compute(m, alone, Eigen::VectorXd(0.25 * own), edge, 1, &own);
    EXPECT_EQ(besideDense(edge), 0);
}
