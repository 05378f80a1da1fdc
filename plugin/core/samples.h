#pragma once
/// \file samples.h
/// The input samples with a k-d tree over them (VCGlib's vcg::KdTree), built once and shared
/// by the spacing estimate, the implicit function and the boundary trim.

#include "lattice.h"

#include <vcg/space/index/kdtree/kdtree.h>

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

} // namespace ib
