#pragma once
/// \file spacing.h
/// Sample spacing: the typical distance between neighbouring samples, sqrt(area per sample),
/// with the area per sample estimated as pi r_k^2 / k from the distance r_k to the k-th
/// nearest neighbour. It sets the automatic lattice resolution and the tangent-disk radii.

#include "lattice.h"
#include "parallel.h"

#include <vcg/space/index/kdtree/kdtree.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace ib {

class SampleSpacing
{
public:
    static constexpr int kNeighbours = 8;

    /// Spacing around every `stride`-th sample of the n×3 set P: vector of ceil(n/stride).
    static Eigen::VectorXd Local(const Points& P, Eigen::Index stride = 1, int threads = 0)
    {
        const int k = std::min<int>(kNeighbours, int(P.rows()) - 1);
        vcg::KdTree<double> tree(vcg::ConstDataWrapper<vcg::Point3d>(reinterpret_cast<const vcg::Point3d*>(P.data()), int(P.rows())));
        Eigen::VectorXd spacing((P.rows() + stride - 1) / stride);
        ParallelFor(size_t(spacing.size()), threads, [&](size_t begin, size_t end, int) {
            vcg::KdTree<double>::PriorityQueue queue;
            for (size_t i = begin; i < end; ++i) {
                const auto row = P.row(Eigen::Index(i) * stride);
                tree.doQueryK(vcg::Point3d(row[0], row[1], row[2]), k + 1, queue);  // +1: the sample itself
                spacing[Eigen::Index(i)] = std::sqrt(M_PI * queue.getTopWeight() / k);
            }
        }, 256);
        return spacing;
    }

    /// Median spacing over up to 4096 evenly strided samples (robust to outliers and clusters).
    static double Median(const Points& P, int threads = 0)
    {
        Eigen::VectorXd s = Local(P, std::max<Eigen::Index>(1, P.rows() / 4096), threads);
        std::nth_element(s.data(), s.data() + s.size() / 2, s.data() + s.size());
        return s[s.size() / 2];
    }
};

} // namespace ib
