#pragma once
/// \file outliers.h
/// Outliers: samples that no well-placed sample has among its nearest neighbours. A sample on a
/// surface is among the nearest neighbours of the samples around it, whatever the density
/// there (a sparse sample next to a dense region is still among the nearest of the sparse
/// samples beside it), and those samples are in turn among the nearest of several others. A
/// stray sample off the surface, farther from it than the surface's samples are from each
/// other, is nobody's neighbour, or only that of another stray (the in-degree of the
/// k-nearest-neighbour graph, Hautamäki et al., "Outlier detection using k-nearest neighbour
/// graph", ICPR 2004, taken one step further for strays that claim each other), unless it lies
/// on the sheet they span (a sample alone in a gap of the sampling is nobody's neighbour either,
/// but it is on the surface: kOnSheet). Left in, one
/// such sample stretches the bounding box, and with it the lattice (one sample at ten times
/// the scan's size coarsens the automatic resolution), and its huge local spacing gives it a
/// tangent disk as large as the gap around it: a sheet of invented surface, and a local fit
/// whose support reaches across the object. Measured with 0.1% of the samples drawn in the
/// bounding box (bun_zipper, nefertiti): every stray farther than 2.5 spacings from the
/// surface is found, and 1 of the 80,000 samples of the two scans (at a cut's edge). A range
/// scan leaves most of its box empty, and strays there form larger groups: those are told
/// from a surface by their neighbourhoods' thickness (kScatter).

#include "parallel.h"
#include "samples.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <vector>

namespace ib {

class Outliers
{
public:
    /// Neighbours per sample: as many as the local spacing is estimated from (spacing.h).
    static constexpr int kNeighbours = 8;

    /// Ascending indices of the samples that at least one well-placed sample (one that is
    /// among the kNeighbours nearest of at least kNeighbours / 2 others) has among its
    /// kNeighbours nearest, or that lie on the sheet of their own kNeighbours nearest
    /// (kOnSheet). With kNeighbours or fewer samples, all of them.
    static std::vector<Eigen::Index> Kept(const SampleIndex& samples, int threads = 0)
    {
        const Eigen::Index n = samples.Size();
        std::vector<Eigen::Index> kept;
        if (n <= kNeighbours + 1) {
            for (Eigen::Index i = 0; i < n; ++i)
                kept.push_back(i);
            return kept;
        }
        // Claims from several threads land on the same samples: atomic counters (the result
        // does not depend on the order).
        std::unique_ptr<std::atomic<int>[]> claims(new std::atomic<int>[size_t(n)]());
        std::vector<double> reach(size_t(n), 0);  // squared distance to the kNeighbours-th nearest
        ForEachNeighbour(samples, threads, [&](Eigen::Index i, Eigen::Index j, double d2) {
            claims[size_t(j)].fetch_add(1, std::memory_order_relaxed);
            reach[size_t(i)] = std::max(reach[size_t(i)], d2);  // i's own slot: one thread
        });
        std::unique_ptr<std::atomic<char>[]> claimed(new std::atomic<char>[size_t(n)]());
        ForEachNeighbour(samples, threads, [&](Eigen::Index i, Eigen::Index j, double) {
            if (claims[size_t(i)].load(std::memory_order_relaxed) >= kNeighbours / 2)
                claimed[size_t(j)].store(1, std::memory_order_relaxed);
        });
        std::vector<char> keep(size_t(n), 0);
        SampleIndex::Queue queue;
        for (Eigen::Index i = 0; i < n; ++i)
            keep[size_t(i)] = claimed[size_t(i)].load(std::memory_order_relaxed) ||
                              OnNeighboursSheet(samples, i, std::sqrt(reach[size_t(i)]), queue);
        DropSparseGroups(samples, reach, keep);
        for (Eigen::Index i = 0; i < n; ++i)
            if (keep[size_t(i)])
                kept.push_back(i);
        return kept;
    }

    /// The rows `rows` of P (ascending) without their outliers (Kept over P(rows)), in order;
    /// the outliers' rows are appended to `outliers`.
    static std::vector<Eigen::Index> KeptRows(const Points& P, std::vector<Eigen::Index> rows,
                                              std::vector<Eigen::Index>& outliers, int threads = 0)
    {
        const std::vector<Eigen::Index> inliers = Kept(SampleIndex(P(rows, Eigen::all)), threads);
        outliers.reserve(outliers.size() + rows.size() - inliers.size());
        for (size_t i = 0, j = 0; i < rows.size(); ++i) {
            if (j < inliers.size() && inliers[j] == Eigen::Index(i))
                rows[j++] = rows[i];
            else
                outliers.push_back(rows[i]);
        }
        rows.resize(inliers.size());
        return rows;
    }

    /// A sparse group is a set of samples, each with a neighbourhood over kSparse times wider
    /// than the median one, linked by being among each other's nearest, with fewer than
    /// kMinGroup members. Strays scattered through the empty space of a bounding box form such
    /// groups and claim each other: their neighbourhoods reach across the emptiness, so their
    /// tangent disks were 18 to 32 spacings wide (nefertiti with 0.1% strays: 1.7M cells in the
    /// SODS against 0.36M). A real sparse region, however sparse, is a patch of many samples.
    static constexpr double kSparse = 4;
    /// Fewer samples than two neighbourhoods: no sample of the group has its neighbours in it.
    static constexpr size_t kMinGroup = 2 * kNeighbours;
    /// A sparse sample whose neighbourhood is thicker than this (the smallest PCA variance of
    /// it and its kNeighbours nearest over the sum of the three, Pauly's surface variation: 0 on
    /// a plane, 1/3 in a uniform cloud) lies in empty space, as no sample of a surface does,
    /// however sparse. A range scan is a sheet that leaves most of its box empty, and strays
    /// drawn in that box are each other's nearest in groups larger than kMinGroup (pymeshlab's
    /// face000.ply, its triangulated grid points with 0.1% strays: 28 of the 86 kept, whose
    /// tangent disks would have occupied 63.5M cells for the scan's 0.67M; the filter refused
    /// for memory; now none). Measured on the sparse samples of real and generated scans: under
    /// 0.03 but for 3 of gargoyle's 14; strays 0.07-0.12 in the median. Not enough where strays
    /// join a sparse patch of flat ones: face000 with the 667 grid points no triangle uses
    /// still keeps 19 of the 86 (7.8M cells, 1.1M without strays).
    static constexpr double kScatter = 0.03;
    /// A sample nobody claims is kept when it lies on the sheet its kNeighbours nearest span:
    /// its height above their plane is under this fraction of its distance to the farthest of
    /// them. Random samples leave gaps over 4 spacings wide with one sample inside, whose
    /// neighbours all have their nearest on their own side: 26 of 200,000 random samples of a
    /// smooth cap, each within 0.06 of that plane (as a fraction of its nearest neighbour's
    /// distance); left out, two gaps opened as holes of 53 and 59 edges. A stray at a height H
    /// over a sheet of spacing s is at least H from its neighbours and about sqrt(H² + 2.5 s²):
    /// under this fraction only while H is under 0.16 s, on the sheet as far as any tangent
    /// disk (half a slab: 0.32 s) can tell.
    static constexpr double kOnSheet = 0.1;
    /// ... and when it lies among them: no farther from their centroid than this many times the
    /// farthest of them. A stray far out in a flat scan's own plane is on their plane too. The
    /// lone sample of a gap has its nearest on the gap's closest side: up to 1.35 times on the
    /// cap above.
    static constexpr double kAmongNeighbours = 2;

private:
    /// Clears keep[i] for the samples of sparse groups, and sparse samples in empty space
    /// (kScatter), among those kept; reach[i]: the squared distance from sample i to its
    /// kNeighbours-th nearest.
    static void DropSparseGroups(const SampleIndex& samples, const std::vector<double>& reach, std::vector<char>& keep)
    {
        const Eigen::Index n = samples.Size();
        std::vector<double> kept;
        for (Eigen::Index i = 0; i < n; ++i)
            if (keep[size_t(i)])
                kept.push_back(reach[size_t(i)]);
        if (kept.empty())
            return;
        std::nth_element(kept.begin(), kept.begin() + long(kept.size() / 2), kept.end());
        const double sparse = kSparse * kSparse * kept[kept.size() / 2];
        std::vector<Eigen::Index> group(size_t(n), -1);  // union-find over the sparse samples
        for (Eigen::Index i = 0; i < n; ++i)
            if (keep[size_t(i)] && reach[size_t(i)] > sparse)
                group[size_t(i)] = i;
        auto find = [&](Eigen::Index i) {
            while (group[size_t(i)] != i)
                i = group[size_t(i)] = group[size_t(group[size_t(i)])];
            return i;
        };
        // A sparse sample whose neighbourhood is not flat lies in empty space among strays.
        SampleIndex::Queue queue;
        for (Eigen::Index i = 0; i < n; ++i) {
            if (group[size_t(i)] < 0)
                continue;
            samples.Nearest(samples.P().row(i).transpose(), kNeighbours + 1, queue);
            Points neighbourhood(queue.getNofElements(), 3);
            for (int q = 0; q < queue.getNofElements(); ++q)
                neighbourhood.row(q) = samples.P().row(queue.getIndex(q));
            if (SurfaceVariation(neighbourhood) > kScatter) {
                keep[size_t(i)] = 0;
                group[size_t(i)] = -1;  // left out, and links no group
            }
        }
        for (Eigen::Index i = 0; i < n; ++i) {
            if (group[size_t(i)] < 0)
                continue;
            samples.Nearest(samples.P().row(i).transpose(), kNeighbours + 1, queue);
            for (int q = 0; q < queue.getNofElements(); ++q) {
                const Eigen::Index j = queue.getIndex(q);
                if (group[size_t(j)] >= 0)
                    group[size_t(find(i))] = find(j);
            }
        }
        std::vector<size_t> size(size_t(n), 0);
        for (Eigen::Index i = 0; i < n; ++i)
            if (group[size_t(i)] >= 0)
                ++size[size_t(find(i))];
        for (Eigen::Index i = 0; i < n; ++i)
            if (group[size_t(i)] >= 0 && size[size_t(find(i))] < kMinGroup)
                keep[size_t(i)] = 0;
    }

    /// Whether sample i lies on the flat sheet of its kNeighbours nearest (kScatter): within
    /// kOnSheet × reach (the distance to the farthest of them) of their plane, and among them
    /// (kAmongNeighbours).
    static bool OnNeighboursSheet(const SampleIndex& samples, Eigen::Index i, double reach, SampleIndex::Queue& queue)
    {
        const Eigen::Vector3d p = samples.P().row(i).transpose();
        samples.Nearest(p, kNeighbours + 1, queue);
        Points neighbourhood(kNeighbours, 3);
        int m = 0;
        for (int q = 0; q < queue.getNofElements() && m < kNeighbours; ++q)
            if (queue.getIndex(q) != i)
                neighbourhood.row(m++) = samples.P().row(queue.getIndex(q));
        if (m < 3)
            return false;
        neighbourhood.conservativeResize(m, 3);
        const Eigen::RowVector3d centroid = neighbourhood.colwise().mean();
        const Points centred = neighbourhood.rowwise() - centroid;
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> pca(centred.transpose() * centred);
        const Eigen::Vector3d lambda = pca.eigenvalues();
        if (!(lambda.sum() > 0) || lambda[0] / lambda.sum() > kScatter)
            return false;
        const Eigen::Vector3d offset = p - centroid.transpose();
        return std::abs(offset.dot(pca.eigenvectors().col(0))) <= kOnSheet * reach &&
               offset.norm() <= kAmongNeighbours * centred.rowwise().norm().maxCoeff();
    }

    /// The smallest variance of the rows of Q (k×3) about their centroid over the sum of all
    /// three (0 for points on a plane, 1/3 for an isotropic cloud).
    static double SurfaceVariation(const Points& Q)
    {
        const Points centred = Q.rowwise() - Q.colwise().mean();
        const Eigen::Matrix3d covariance = centred.transpose() * centred;
        const Eigen::Vector3d lambda = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance).eigenvalues();
        return lambda.sum() > 0 ? lambda[0] / lambda.sum() : 0;
    }

    /// Calls f(i, j, squared distance) for every sample i and each j != i of its kNeighbours
    /// nearest, from several threads (each i from one).
    template <class F>
    static void ForEachNeighbour(const SampleIndex& samples, int threads, F&& f)
    {
        ParallelFor(size_t(samples.Size()), threads, [&](size_t begin, size_t end, int) {
            SampleIndex::Queue queue;
            for (size_t i = begin; i < end; ++i) {
                samples.Nearest(samples.P().row(Eigen::Index(i)).transpose(), kNeighbours + 1, queue);  // +1: itself
                for (int q = 0; q < queue.getNofElements(); ++q)
                    if (size_t(queue.getIndex(q)) != i)
                        f(Eigen::Index(i), Eigen::Index(queue.getIndex(q)), double(queue.getWeight(q)));
            }
        }, 256);
    }
};

} // namespace ib
