#pragma once
/// \file normals.h
/// Normals for point sets that come without them: PCA planes over k neighbours, oriented
/// consistently by VCGlib (vcg::tri::PointCloudNormal: Hoppe et al. 1992's propagation over
/// the neighbour graph, or towards a viewpoint when one is given).

#include "lattice.h"

#include <vcg/complex/complex.h>
#include <vcg/complex/algorithms/pointcloud_normal.h>

#include <optional>

namespace ib {

class PointVertex;
struct PointUsedTypes : public vcg::UsedTypes<vcg::Use<PointVertex>::AsVertexType>
{
};
/// What VCG's normal estimation works on: positions, normals, flags and marks.
class PointVertex : public vcg::Vertex<PointUsedTypes, vcg::vertex::Coord3d, vcg::vertex::Normal3d,
                                       vcg::vertex::BitFlags, vcg::vertex::Mark>
{
};
class PointCloud : public vcg::tri::TriMesh<std::vector<PointVertex>>
{
};

class PointNormals
{
public:
    struct Param
    {
        int neighbours = 10;                      ///< k of the PCA fit and of the propagation
        int smoothing_iterations = 0;             ///< neighbour averaging passes after the fit
        std::optional<Eigen::Vector3d> viewpoint; ///< scanner position: normals face it
    };

    /// n×3 unit normals of the n×3 samples P. Without a viewpoint, propagation fixes the
    /// orientation only up to one global flip per connected neighbour graph; we flip the whole
    /// set so that most normals point away from the centroid (right for a scan of one object).
    /// Returns whether that global flip was applied through `flipped`.
    static Points Compute(const Points& P, const Param& p, bool* flipped = nullptr)
    {
        PointCloud m;
        auto vi = vcg::tri::Allocator<PointCloud>::AddVertices(m, size_t(P.rows()));
        for (Eigen::Index i = 0; i < P.rows(); ++i, ++vi)
            vi->P() = vcg::Point3d(P(i, 0), P(i, 1), P(i, 2));

        vcg::tri::PointCloudNormal<PointCloud>::Param vp;
        vp.fittingAdjNum = p.neighbours;
        vp.coherentAdjNum = p.neighbours;
        vp.smoothingIterNum = p.smoothing_iterations;
        if (p.viewpoint) {
            vp.useViewPoint = true;
            vp.viewPoint = vcg::Point3d((*p.viewpoint)[0], (*p.viewpoint)[1], (*p.viewpoint)[2]);
        }
        vcg::tri::PointCloudNormal<PointCloud>::Compute(m, vp, nullptr);

        Points N(P.rows(), 3);
        for (Eigen::Index i = 0; i < P.rows(); ++i) {
            vcg::Point3d n = m.vert[size_t(i)].cN();
            n.Normalize();
            N.row(i) << n[0], n[1], n[2];
        }
        bool flip = false;
        if (!p.viewpoint) {
            const Eigen::RowVector3d centroid = P.colwise().mean();
            flip = ((P.rowwise() - centroid).array() * N.array()).rowwise().sum().sum() < 0;
            if (flip)
                N = -N;
        }
        if (flipped)
            *flipped = flip;
        return N;
    }
};

} // namespace ib
