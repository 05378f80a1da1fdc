#pragma once
/// \file outliers.h
/// Outliers: samples that no well-placed sample has among its nearest neighbours. A sample on a
/// surface is among the nearest neighbours of the samples around it, whatever the density
/// there (a sparse sample next to a dense region is still among the nearest of the sparse
/// samples beside it), and those samples are in turn among the nearest of several others. A
/// stray sample off the surface, farther from it than the surface's samples are from each
/// other, is nobody's neighbour, or only that of another stray (the in-degree of the
/// k-nearest-neighbour graph, Hautamäki et al., "Outlier detection using k-nearest neighbour
/// graph", ICPR 2004, taken one step further for strays that claim each other). Left in, one
/// such sample stretches the bounding box, and with it the lattice (one sample at ten times
/// the scan's size coarsens the automatic resolution), and its huge local spacing gives it a
/// tangent disk as large as the gap around it: a sheet of invented surface, and a local fit
/// whose support reaches across the object. Measured with 0.1% of the samples drawn in the
/// bounding box (bun_zipper, nefertiti): every stray farther than 2.5 spacings from the
/// surface is found, and 1 of the 80,000 samples of the two scans (at a cut's edge).

#include "parallel.h"
#include "samples.h"

#include <atomic>
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
    /// kNeighbours nearest. With kNeighbours or fewer samples, all of them.
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
        ForEachNeighbour(samples, threads, [&](Eigen::Index, Eigen::Index j) {
            claims[size_t(j)].fetch_add(1, std::memory_order_relaxed);
        });
        std::unique_ptr<std::atomic<char>[]> claimed(new std::atomic<char>[size_t(n)]());
        ForEachNeighbour(samples, threads, [&](Eigen::Index i, Eigen::Index j) {
            if (claims[size_t(i)].load(std::memory_order_relaxed) >= kNeighbours / 2)
                claimed[size_t(j)].store(1, std::memory_order_relaxed);
        });
        for (Eigen::Index i = 0; i < n; ++i)
            if (claimed[size_t(i)].load(std::memory_order_relaxed))
                kept.push_back(i);
        return kept;
    }

private:
    /// Calls f(i, j) for every sample i and each j != i of its kNeighbours nearest, from
    /// several threads.
    template <class F>
    static void ForEachNeighbour(const SampleIndex& samples, int threads, F&& f)
    {
        ParallelFor(size_t(samples.Size()), threads, [&](size_t begin, size_t end, int) {
            SampleIndex::Queue queue;
            for (size_t i = begin; i < end; ++i) {
                samples.Nearest(samples.P().row(Eigen::Index(i)).transpose(), kNeighbours + 1, queue);  // +1: itself
                for (int q = 0; q < queue.getNofElements(); ++q)
                    if (size_t(queue.getIndex(q)) != i)
                        f(Eigen::Index(i), Eigen::Index(queue.getIndex(q)));
            }
        }, 256);
    }
};

} // namespace ib
