#include "reconstruct.h"
#include "tiling.h"

#include "geometry.h"

#include <gtest/gtest.h>
#include <vcg/complex/append.h>

#include <string>

using namespace ib;

namespace {
/// What Compute says about P with tile t (and the resolution given), or "" when it runs.
std::string TileMessage(const Points& P, const Points& N, const Tile& t, int resolution = 0)
{
    Reconstruction::Param p;
    p.tile = t;
    p.resolution = resolution;
    try {
        CoreMesh m;
        Reconstruction::Compute(P, N, p, m);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

/// The grid of a tiled run over P: cells of 0.6 spacings (the automatic resolution's), from a
/// few cells below the samples to a few above.
Tile WholeScan(const Points& P, double spacing)
{
    Tile t;
    t.cell = Reconstruction::kCellPerSpacing * spacing;
    t.origin = P.colwise().minCoeff().transpose() - Eigen::Vector3d::Constant(3.3 * t.cell);
    t.end = P.colwise().maxCoeff().transpose() + Eigen::Vector3d::Constant(3.3 * t.cell);
    t.spacing = spacing;
    return t;
}

size_t BorderEdges(CoreMesh& m)
{
    size_t n = 0;
    for (const BoundaryLoop& loop : BoundaryLoops::Compute(m))
        n += loop.vertices.size();
    return n;
}
} // namespace

TEST(Tiling, BadLatticesAndBlocksAreRefusedWithWhatToDo)
{
    Points P, N;
    test::SpherePoints(2000, 1.0, P, N, 0.0);
    Tile t = WholeScan(P, 0.05);
    EXPECT_EQ(TileMessage(P, N, t), "");
    EXPECT_NE(TileMessage(P, N, t, 64).find("leave the resolution at 0"), std::string::npos);
    Tile flat = t;
    flat.end[2] = flat.origin[2];
    EXPECT_NE(TileMessage(P, N, flat).find("end above its origin"), std::string::npos);
    Tile fine = t;
    fine.cell = 1e-7;
    EXPECT_NE(TileMessage(P, N, fine).find("use a larger cell"), std::string::npos);
    Tile small = t;
    small.end[0] = 0.5;
    EXPECT_NE(TileMessage(P, N, small).find("outside the fixed lattice"), std::string::npos);
    Tile flatBlock = t;
    flatBlock.block = Eigen::AlignedBox3d(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 1));
    EXPECT_NE(TileMessage(P, N, flatBlock).find("block to keep is flat"), std::string::npos);
    Tile blockAlone;
    blockAlone.block = Eigen::AlignedBox3d(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 1));
    EXPECT_NE(TileMessage(P, N, blockAlone).find("needs the fixed lattice"), std::string::npos);
    Tile negative;
    negative.cell = -1;
    EXPECT_NE(TileMessage(P, N, negative).find("must be positive"), std::string::npos);
}

TEST(Tiling, ClipKeepsEachFaceInExactlyOneOfTwoBlocks)
{
    CoreMesh whole;
    test::Grid(10, 0.1, whole);
    Tile left, right;
    left.block = Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(0.5, 2, 1));
    right.block = Eigen::AlignedBox3d(Eigen::Vector3d(0.5, -1, -1), Eigen::Vector3d(2, 2, 1));
    CoreMesh a, b;
    vcg::tri::Append<CoreMesh, CoreMesh>::MeshCopy(a, whole);
    vcg::tri::Append<CoreMesh, CoreMesh>::MeshCopy(b, whole);
    left.Clip(a);
    right.Clip(b);
    EXPECT_EQ(a.face.size(), 100u);  // the grid's 200 faces, split at x = 0.5
    EXPECT_EQ(b.face.size(), 100u);
    EXPECT_EQ(a.vert.size(), 66u);   // 6 × 11 vertices: the unreferenced ones are gone
    for (const CoreFace& f : a.face)
        EXPECT_LT((f.cP(0) + f.cP(1) + f.cP(2))[0] / 3, 0.5);
    EXPECT_EQ(BorderEdges(a), 30u);  // 5 + 10 + 5 + 10: the border, one square of the seam
}

TEST(Tiling, TilesReconstructedApartJoinIntoTheSurfaceOfOneRun)
{
    // An open hemisphere of 20,000 samples in 4 blocks (cut off the axes, so a seam crosses the
    // pole's neighbourhood too), each reconstructed from its block plus a halo of 20 spacings on
    // the whole scan's lattice: joined, welded by position, they give one surface with the
    // single run's faces, its one loop, no border along a seam, and every vertex on the single
    // run's surface (to rounding).
    Points P, N;
    test::SpherePoints(40000, 1.0, P, N, 0.0);
    const double spacing = std::sqrt(2 * M_PI / P.rows());
    const Tile grid = WholeScan(P, spacing);
    Reconstruction::Param one;
    one.tile = grid;
    CoreMesh single;
    const Reconstruction::Result whole = Reconstruction::Compute(P, N, one, single);
    ASSERT_EQ(whole.loops.size(), 1u);

    const double halo = 20 * spacing;
    const double cut[2] = {grid.origin[0] + 97 * grid.cell, grid.origin[1] + 83 * grid.cell};
    CoreMesh joined;
    size_t pieces = 0;
    for (int bx = 0; bx < 2; ++bx)
        for (int by = 0; by < 2; ++by) {
            Reconstruction::Param p = one;
            Eigen::Vector3d lo = grid.origin, hi = grid.end;
            (bx ? lo : hi)[0] = cut[0];
            (by ? lo : hi)[1] = cut[1];
            p.tile.block = Eigen::AlignedBox3d(lo, hi);
            std::vector<Eigen::Index> rows;  // ascending, as a tiled run reads them
            for (Eigen::Index i = 0; i < P.rows(); ++i)
                if ((P.row(i).transpose().array() >= lo.array() - halo).all() &&
                    (P.row(i).transpose().array() <= hi.array() + halo).all())
                    rows.push_back(i);
            CoreMesh piece;
            Reconstruction::Compute(P(rows, Eigen::all), N(rows, Eigen::all), p, piece);
            pieces += piece.face.size();
            for (const CoreFace& f : piece.face)
                test::AddTriangle(joined, f.cP(0), f.cP(1), f.cP(2));
        }
    // Welded by position, within a billionth of a cell: a seam vertex that the boundary stage
    // moved (smoothing, the fit) sums its neighbours in another order in each tile.
    vcg::tri::Clean<CoreMesh>::RemoveDuplicateVertex(joined);
    vcg::tri::Clean<CoreMesh>::MergeCloseVertex(joined, 1e-9 * grid.cell);
    vcg::tri::Clean<CoreMesh>::RemoveDegenerateFace(joined);
    vcg::tri::Clean<CoreMesh>::RemoveUnreferencedVertex(joined);
    vcg::tri::Allocator<CoreMesh>::CompactEveryVector(joined);
    vcg::tri::UpdateTopology<CoreMesh>::FaceFace(joined);
    const size_t singleBorder = BorderEdges(single), joinedBorder = BorderEdges(joined);
    const std::vector<BoundaryLoop> loops = BoundaryLoops::Compute(joined);

    Points V, Vs;
    Faces F, Fs;
    test::Matrices(joined, V, F);
    test::Matrices(single, Vs, Fs);
    const MeshDistance singleSurface(Vs, Fs);
    Eigen::VectorXd d(V.rows());
    singleSurface.Eval(V, d);
    EXPECT_EQ(pieces, single.face.size());
    EXPECT_EQ(joined.face.size(), single.face.size());
    EXPECT_EQ(loops.size(), 1u);
    EXPECT_EQ(joinedBorder, singleBorder);
    EXPECT_LT(d.cwiseAbs().maxCoeff(), 1e-6 * grid.cell);
}
