#pragma once
/// \file normals.h
/// Normals for point sets that come without them: PCA planes over k neighbours (VCGlib's
/// vcg::tri::PointCloudNormal), oriented towards a viewpoint when one is given, else by
/// propagation over the neighbour graph (Hoppe et al. 1992) with the mirror rule of König and
/// Gumhold 2009 (Propagate), then a neighbour vote that turns the few normals the propagation
/// got wrong.

#include "lattice.h"
#include "parallel.h"
#include "samples.h"

#include <Eigen/Eigenvalues>
#include <vcg/complex/complex.h>
#include <vcg/complex/algorithms/pointcloud_normal.h>

#include <numeric>
#include <optional>
#include <queue>
#include <tuple>

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
        /// n×3, or empty: per sample, a direction its normal must face (towards the scanner of
        /// its scan, or its range grid's triangle normal); zero rows: unknown, oriented by
        /// their neighbours. Used without a viewpoint.
        Points facing;
        int threads = 0;                          ///< for the neighbour vote; 0 = all cores
    };

    /// What Compute did beyond the PCA fit.
    struct Report
    {
        bool flipped = false;   ///< a connected piece was turned to point away from its centroid
        size_t turned = 0;      ///< normals turned by the neighbour vote
    };

    /// n×3 unit normals of the n×3 samples samples.P(). Without a viewpoint, propagation fixes
    /// the orientation only up to one flip per connected piece of the neighbour graph; each
    /// piece is turned so that most of its normals point away from its centroid (right for a
    /// scan of one object).
    static Points Compute(const SampleIndex& samples, const Param& p, Report* report = nullptr)
    {
        const Points& P = samples.P();
        PointCloud m;
        auto vi = vcg::tri::Allocator<PointCloud>::AddVertices(m, size_t(P.rows()));
        for (Eigen::Index i = 0; i < P.rows(); ++i, ++vi)
            vi->P() = vcg::Point3d(P(i, 0), P(i, 1), P(i, 2));

        vcg::tri::PointCloudNormal<PointCloud>::Param vp;
        vp.fittingAdjNum = p.neighbours;
        vp.smoothingIterNum = p.smoothing_iterations;
        vp.coherentAdjNum = 0;  // the planes only: oriented below
        vcg::tri::PointCloudNormal<PointCloud>::Compute(m, vp, nullptr);

        Points N(P.rows(), 3);
        for (Eigen::Index i = 0; i < P.rows(); ++i) {
            vcg::Point3d n = m.vert[size_t(i)].cN();
            n.Normalize();
            N.row(i) << n[0], n[1], n[2];
        }
        Report r;
        if (p.viewpoint) {
            for (Eigen::Index i = 0; i < P.rows(); ++i)
                if (N.row(i).dot(p.viewpoint->transpose() - P.row(i)) < 0)
                    N.row(i) = -N.row(i);
        } else if (p.facing.rows() == P.rows() && (p.facing.array() != 0).any()) {
            std::vector<Eigen::Index> unknown;
            for (Eigen::Index i = 0; i < P.rows(); ++i) {
                const double agree = N.row(i).dot(p.facing.row(i));
                if (agree < 0)
                    N.row(i) = -N.row(i);
                else if (!(agree > 0))  // no direction given (or one in the tangent plane)
                    unknown.push_back(i);
            }
            FillMissing(samples, N, unknown, p.neighbours);
        } else {
            r.flipped = Propagate(samples, p.neighbours, N);
        }
        r.turned = TurnOutvoted(samples, p.neighbours, p.threads, N);
        if (report)
            *report = r;
        return N;
    }

    /// The given normals N (n×3) of the samples, scaled to unit length; rows that are zero, NaN
    /// or infinite are estimated (FillMissing with k neighbours), their count in `filled`.
    static Points Given(const SampleIndex& samples, const Points& N, int k, size_t& filled)
    {
        Points normals = N;
        std::vector<Eigen::Index> missing;
        for (Eigen::Index i = 0; i < N.rows(); ++i) {
            const double length = N.row(i).norm();
            if (std::isfinite(length) && length > 0)
                normals.row(i) /= length;
            else
                missing.push_back(i);
        }
        FillMissing(samples, normals, missing, k);
        filled = missing.size();
        return normals;
    }

    /// Fills the rows `missing` of the n×3 normals N whose other rows are given unit normals:
    /// each gets the normal of the plane through its k nearest samples (PCA), turned to agree
    /// with the known normals among those neighbours. A patch of missing normals fills from its
    /// edge inward, one ring per pass; a piece with none known starts from one normal facing
    /// away from the samples' centroid. MeshLab's import of a range scan leaves
    /// zero normals on the few grid points no triangle uses (11 of bun000's 40,256):
    /// estimating every normal again would throw away the scanner's orientation of the rest.
    static void FillMissing(const SampleIndex& samples, Points& N, const std::vector<Eigen::Index>& missing, int k)
    {
        const Points& P = samples.P();
        k = std::min<int>(k, int(P.rows()) - 1);
        std::vector<char> known(size_t(P.rows()), 1);
        for (Eigen::Index i : missing)
            known[size_t(i)] = 0;
        std::vector<std::vector<Eigen::Index>> around(missing.size());
        SampleIndex::Queue queue;
        for (size_t m = 0; m < missing.size(); ++m) {
            samples.Nearest(P.row(missing[m]).transpose(), k + 1, queue);
            Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
            Eigen::Vector3d mean = Eigen::Vector3d::Zero();
            for (int q = 0; q < queue.getNofElements(); ++q) {
                around[m].push_back(queue.getIndex(q));
                mean += P.row(queue.getIndex(q)).transpose();
            }
            mean /= double(around[m].size());
            for (Eigen::Index j : around[m]) {
                const Eigen::Vector3d d = P.row(j).transpose() - mean;
                scatter += d * d.transpose();
            }
            N.row(missing[m]) = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0).transpose();
        }
        const Eigen::RowVector3d centroid = P.colwise().mean();
        std::vector<size_t> left(missing.size());
        std::iota(left.begin(), left.end(), size_t(0));
        while (!left.empty()) {  // one ring of the patches per pass
            std::vector<size_t> later;
            for (size_t m : left) {
                const Eigen::Index i = missing[m];
                double agreement = 0;
                bool seen = false;
                for (Eigen::Index j : around[m])
                    if (j != i && known[size_t(j)]) {
                        agreement += N.row(i).dot(N.row(j));
                        seen = true;
                    }
                if (!seen) {
                    later.push_back(m);
                    continue;
                }
                if (agreement < 0)
                    N.row(i) *= -1;
                known[size_t(i)] = 1;
            }
            if (later.size() == left.size()) {  // a piece with no normal given: seed it
                const Eigen::Index i = missing[later.back()];
                if (N.row(i).dot(P.row(i) - centroid) < 0)
                    N.row(i) *= -1;
                known[size_t(i)] = 1;
                later.pop_back();
            }
            left.swap(later);
        }
    }

private:
    /// Orients the unoriented unit normals N in place, growing each connected piece of the
    /// k-nearest-neighbour graph from its first sample, most confident step first (Prim's
    /// order, Hoppe et al. 1992). A sample is oriented by the votes of all its oriented
    /// neighbours, not by the one step that reached it: each votes for its own normal
    /// reflected across the plane bisecting the two samples (König and Gumhold, "Consistent
    /// propagation of normal orientations in point clouds", VMV 2009: on a circle through both
    /// samples their outward normals are such mirror images; on one flat sheet the mirror is
    /// the normal itself, Hoppe's rule). A vote counts by how well it agrees with the sample's
    /// plane and by how nearly the two lie in each other's tangent plane: with scan noise, a
    /// step out of the plane is unreliable, so steps along the sheet go first. Unlike VCGlib's
    /// propagation, no step is dropped for normals far apart (there, each region it could not
    /// reach got an arbitrary side). Measured over the corpus without normals (bench/corpus.py):
    /// 10 of 15 meshes with exactly their boundaries, against 8 with VCGlib's propagation (a
    /// cartoon cow and a cartoon figure: inside-out regions behind seams before). Neither
    /// orients both sides of a closed plate thinner than about 3 spacings. Returns true when a
    /// piece was turned to face away from its centroid.
    static bool Propagate(const SampleIndex& index, int k, Points& N)
    {
        const Points& P = index.P();
        const Eigen::Index n = P.rows();
        std::vector<char> done(size_t(n), 0);
        using Step = std::tuple<double, Eigen::Index, Eigen::Index>;  // confidence, -target, source
        std::priority_queue<Step> frontier;
        SampleIndex::Queue queue;
        // The vote of oriented sample j on sample i's orientation, weighted by its confidence.
        auto vote = [&](Eigen::Index j, Eigen::Index i) {
            const double agreement = Mirror(P, N, j, i).dot(N.row(i));
            return agreement * std::abs(agreement) * Clarity(P, N, j, i);
        };
        // Orients sample i, reached from `source`, by the votes of its oriented neighbours and
        // the source (one noisy step alone can mislead), then offers the steps to its other
        // neighbours.
        auto visit = [&](Eigen::Index i, Eigen::Index source) {
            index.Nearest(P.row(i).transpose(), k + 1, queue);
            double votes = source >= 0 ? vote(source, i) : 0;
            for (int q = 0; q < queue.getNofElements(); ++q) {
                const Eigen::Index j = queue.getIndex(q);
                if (j != i && j != source && done[size_t(j)])
                    votes += vote(j, i);
            }
            if (votes < 0)
                N.row(i) = -N.row(i);
            done[size_t(i)] = 1;
            for (int q = 0; q < queue.getNofElements(); ++q) {
                const Eigen::Index j = queue.getIndex(q);
                if (done[size_t(j)])
                    continue;
                const double confidence = std::abs(Mirror(P, N, i, j).dot(N.row(j))) * Clarity(P, N, i, j);
                frontier.emplace(confidence, -j, i);
            }
        };
        bool flipped = false;
        std::vector<Eigen::Index> piece;
        for (Eigen::Index seed = 0; seed < n; ++seed) {
            if (done[size_t(seed)])
                continue;
            piece.assign(1, seed);
            visit(seed, -1);
            while (!frontier.empty()) {
                const auto [confidence, target, source] = frontier.top();
                frontier.pop();
                if (done[size_t(-target)])
                    continue;
                piece.push_back(-target);
                visit(-target, source);
            }
            Eigen::RowVector3d centroid = Eigen::RowVector3d::Zero();
            for (Eigen::Index i : piece)
                centroid += P.row(i);
            centroid /= double(piece.size());
            double outward = 0;
            for (Eigen::Index i : piece)
                outward += (P.row(i) - centroid).dot(N.row(i));
            if (outward < 0) {
                for (Eigen::Index i : piece)
                    N.row(i) = -N.row(i);
                flipped = true;
            }
        }
        return flipped;
    }

    /// Unit vector from sample i to sample j (zero for coincident samples).
    static Eigen::RowVector3d Direction(const Points& P, Eigen::Index i, Eigen::Index j)
    {
        const Eigen::RowVector3d d = P.row(j) - P.row(i);
        const double length = d.norm();
        return length > 0 ? Eigen::RowVector3d(d / length) : Eigen::RowVector3d::Zero();
    }

    /// How much a step from sample i to sample j can be trusted, 1 to 0: fully where j lies in
    /// i's tangent plane, not at all along its normal. (Trusting steps straight along the
    /// normal too, where the mirror would orient a thin plate's far side, turned whole regions
    /// of a noisy torus inside out: scan noise looks the same at that scale.)
    static double Clarity(const Points& P, const Points& N, Eigen::Index i, Eigen::Index j)
    {
        return 1 - std::abs(Direction(P, i, j).dot(N.row(i)));
    }

    /// Normal i reflected across the plane bisecting samples i and j.
    static Eigen::RowVector3d Mirror(const Points& P, const Points& N, Eigen::Index i, Eigen::Index j)
    {
        const Eigen::RowVector3d d = Direction(P, i, j);
        return N.row(i) - 2 * N.row(i).dot(d) * d;
    }

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
