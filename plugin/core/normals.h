#pragma once
/// \file normals.h
/// Normals for point sets that come without them: PCA planes over k neighbours, oriented
/// consistently by VCGlib (vcg::tri::PointCloudNormal: Hoppe et al. 1992's propagation over
/// the neighbour graph, or towards a viewpoint when one is given), then a neighbour vote
/// that turns the few normals the propagation got wrong.

#include "lattice.h"
#include "parallel.h"
#include "samples.h"

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
        int neighbours = 15;                      ///< k of the PCA fit and of the propagation
        int smoothing_iterations = 0;             ///< neighbour averaging passes after the fit
        std::optional<Eigen::Vector3d> viewpoint; ///< scanner position: normals face it
        int threads = 0;                          ///< for the neighbour vote; 0 = all cores
    };

    /// What Compute did beyond the PCA fit.
    struct Report
    {
        bool flipped = false;   ///< the whole set was turned to point away from the centroid
        size_t turned = 0;      ///< normals turned by the neighbour vote
    };

    /// n×3 unit normals of the n×3 samples samples.P(). Without a viewpoint, propagation fixes
    /// the orientation only up to one global flip per connected neighbour graph; we flip the
    /// whole set so that most normals point away from the centroid (right for a scan of one
    /// object).
    static Points Compute(const SampleIndex& samples, const Param& p, Report* report = nullptr)
    {
        const Points& P = samples.P();
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
        const size_t turned = TurnOutvoted(samples, p.neighbours, p.threads, N);
        bool flip = false;
        if (!p.viewpoint) {
            const Eigen::RowVector3d centroid = P.colwise().mean();
            flip = ((P.rowwise() - centroid).array() * N.array()).rowwise().sum().sum() < 0;
            if (flip)
                N = -N;
        }
        if (report)
            *report = Report{flip, turned};
        return N;
    }

private:
    /// Propagation (and a viewpoint at grazing angles) passes a wrong orientation on through a
    /// noisy normal now and then: an isolated sample or a small group then faces the other way
    /// and bends the implicit function into a dimple (a torus with 0.5%-diagonal noise and 10
    /// neighbours: 1 of 23,130 normals). A normal is turned when its k nearest neighbours clearly disagree:
    /// the sum of their dot products with it is below -k/2. Decided from the normals as they
    /// were (one pass, independent of the order and of the thread count); a real fold, where
    /// the surface's two sides meet, has neighbours on both sides and is left alone.
    static size_t TurnOutvoted(const SampleIndex& index, int k, int threads, Points& N)
    {
        const Points& P = index.P();
        if (P.rows() <= k)
            return 0;
        std::vector<char> turn(size_t(P.rows()), 0);
        ParallelFor(size_t(P.rows()), threads, [&](size_t begin, size_t end, int) {
            SampleIndex::Queue queue;
            for (size_t i = begin; i < end; ++i) {
                index.Nearest(P.row(Eigen::Index(i)).transpose(), k + 1, queue);  // +1: itself
                double agreement = 0;
                for (int q = 0; q < queue.getNofElements(); ++q) {
                    const Eigen::Index j = queue.getIndex(q);
                    if (j != Eigen::Index(i))
                        agreement += N.row(j).dot(N.row(Eigen::Index(i)));
                }
                turn[i] = agreement < -0.5 * k;
            }
        });
        size_t turned = 0;
        for (Eigen::Index i = 0; i < P.rows(); ++i)
            if (turn[size_t(i)]) {
                N.row(i) = -N.row(i);
                ++turned;
            }
        return turned;
    }
};

} // namespace ib
