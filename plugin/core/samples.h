#pragma once
/// \file samples.h
/// The input samples with a k-d tree over them (VCGlib's vcg::KdTree), built once and shared
/// by the spacing estimate, the implicit function and the boundary trim.

#include "lattice.h"

#include <vcg/space/index/kdtree/kdtree.h>

#include <algorithm>
#include <vector>

namespace ib {

class SampleIndex
{
public:
    using Queue = vcg::KdTree<double>::PriorityQueue;

    /// P: n×3 samples; kept by reference, so it must outlive the index.
    explicit SampleIndex(const Points& P)
        : P_(P), tree_(vcg::ConstDataWrapper<vcg::Point3d>(reinterpret_cast<const vcg::Point3d*>(P.data()), int(P.rows())))
    {
    }

    const Points& P() const { return P_; }
    Eigen::Index Size() const { return P_.rows(); }

    /// The k nearest samples of q into `queue` (a max-heap on squared distance, unsorted).
    /// Safe from several threads, each with its own queue.
    void Nearest(const Eigen::Vector3d& q, int k, Queue& queue) const
    {
        tree_.doQueryK(vcg::Point3d(q[0], q[1], q[2]), k, queue);
    }

private:
    const Points& P_;
    // VCG's queries are not const but touch only the caller's queue.
    mutable vcg::KdTree<double> tree_;
};

/// Per sample of `kept` (rows of an input of `rows` rows, several scans one after the other
/// with `sizes` rows each), the index of its scan; empty for a single scan.
inline std::vector<int> ScanOfSamples(const std::vector<Eigen::Index>& sizes, Eigen::Index rows,
                                      const std::vector<Eigen::Index>& kept)
{
    if (sizes.size() <= 1)
        return {};
    std::vector<int> scanOfRow(size_t(rows), 0);
    Eigen::Index row = 0;
    for (size_t s = 0; s < sizes.size(); ++s)
        for (Eigen::Index i = 0; i < sizes[s] && row < rows; ++i)
            scanOfRow[size_t(row++)] = int(s);
    std::vector<int> scan;
    scan.reserve(kept.size());
    for (Eigen::Index i : kept)
        scan.push_back(scanOfRow[size_t(i)]);
    return scan;
}

/// The samples of each scan: for `scan` (ScanOfSamples, not empty), per scan index the rows that
/// belong to it, ascending.
inline std::vector<std::vector<Eigen::Index>> RowsOfScans(const std::vector<int>& scan)
{
    std::vector<std::vector<Eigen::Index>> rows(size_t(*std::max_element(scan.begin(), scan.end()) + 1));
    for (size_t i = 0; i < scan.size(); ++i)
        rows[size_t(scan[i])].push_back(Eigen::Index(i));
    return rows;
}

} // namespace ib
