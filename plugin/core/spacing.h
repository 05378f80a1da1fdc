#pragma once
/// \file spacing.h
/// Sample spacing: the typical distance between neighbouring samples, sqrt(area per sample),
/// with the area per sample estimated as pi r_k^2 / k from the distance r_k to the k-th
/// nearest neighbour. It sets the automatic lattice resolution and the tangent-disk radii.
/// Given normals, r_k is measured in each sample's tangent plane: noise across the surface
/// moves samples off it, not apart along it, and should not coarsen the lattice (a neighbour
/// facing away, across a thin part, keeps its distance in space).

#include "parallel.h"
#include "samples.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace ib {

class SampleSpacing
{
public:
    static constexpr int kNeighbours = 8;

    /// Spacing around every `stride`-th sample: vector of ceil(n/stride). N: n×3 unit normals
    /// (null or zero rows: distances in space), along which the neighbours' offsets are left out.
    static Eigen::VectorXd Local(const SampleIndex& samples, Eigen::Index stride = 1, int threads = 0,
                                 const Points* N = nullptr)
    {
        const int k = std::min<int>(kNeighbours, int(samples.Size()) - 1);
        Eigen::VectorXd spacing((samples.Size() + stride - 1) / stride);
        ParallelFor(size_t(spacing.size()), threads, [&](size_t begin, size_t end, int) {
            SampleIndex::Queue queue;
            for (size_t i = begin; i < end; ++i) {
                const Eigen::Index row = Eigen::Index(i) * stride;
                const Eigen::Vector3d p = samples.P().row(row).transpose();
                samples.Nearest(p, k + 1, queue);  // +1: itself
                double reach2 = queue.getTopWeight();
                if (N && N->row(row).squaredNorm() > 0) {
                    const Eigen::Vector3d n = N->row(row).transpose();
                    reach2 = 0;
                    for (int j = 0; j < queue.getNofElements(); ++j) {
                        const Eigen::Index other = queue.getIndex(j);
                        const Eigen::Vector3d d = samples.P().row(other).transpose() - p;
                        // A neighbour facing away lies on the other side of a thin part: the
                        // part's thickness is no noise.
                        const bool sameSide = N->row(other).dot(n) > 0;
                        reach2 = std::max(reach2, d.squaredNorm() - (sameSide ? std::pow(d.dot(n), 2) : 0.0));
                    }
                }
                spacing[Eigen::Index(i)] = std::sqrt(M_PI * reach2 / k);
            }
        }, 256);
        return spacing;
    }

    /// The median of local spacings (robust to outliers and clusters).
    static double Median(Eigen::VectorXd spacing)
    {
        std::nth_element(spacing.data(), spacing.data() + spacing.size() / 2, spacing.data() + spacing.size());
        return spacing[spacing.size() / 2];
    }

    /// Local sample spacing, measured among the samples of each sample's own scan (`scan`: the
    /// scan index per sample, empty for one scan). The samples of a scan too small to measure
    /// get the spacing among all samples. N: as for Local.
    static Eigen::VectorXd PerScan(const SampleIndex& samples, const std::vector<int>& scan, int threads,
                                   const Points* N = nullptr)
    {
        if (scan.empty())
            return Local(samples, 1, threads, N);
        const std::vector<std::vector<Eigen::Index>> rows = RowsOfScans(scan);
        Eigen::VectorXd spacing(samples.Size());
        std::vector<Eigen::Index> unmeasured;
        for (const std::vector<Eigen::Index>& own : rows) {
            if (own.size() <= size_t(kNeighbours)) {
                unmeasured.insert(unmeasured.end(), own.begin(), own.end());
                continue;
            }
            const Points ownN = N ? Points((*N)(own, Eigen::all)) : Points();
            spacing(own) = Local(SampleIndex(samples.P()(own, Eigen::all)), 1, threads, N ? &ownN : nullptr);
        }
        if (!unmeasured.empty())
            spacing(unmeasured) = Local(samples, 1, threads, N)(unmeasured);
        return spacing;
    }

    /// How many sheets of samples overlap where scans are merged: (the median of `perScan`,
    /// PerScan's spacings, / the median spacing among all samples)^2, at least 1 (1 for one
    /// scan; the 9 Stanford bunny scans: 2.4). N: as for Local (the normals perScan was measured with).
    static double Overlap(const SampleIndex& samples, const Eigen::VectorXd& perScan, int threads,
                          const Points* N = nullptr)
    {
        const double merged = Median(Local(samples, 1, threads, N));
        return merged > 0 ? std::max(1.0, std::pow(Median(perScan) / merged, 2)) : 1.0;
    }
};

} // namespace ib
