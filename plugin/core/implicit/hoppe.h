#pragma once
/// \file hoppe.h
/// Signed distance to the tangent planes of the nearest samples, after
/// H. Hoppe, T. DeRose, T. Duchamp, J. McDonald, W. Stuetzle,
/// "Surface reconstruction from unorganized points", SIGGRAPH 1992.
///
/// Hoppe et al. take the distance to the plane of the single nearest tangent-plane centre,
/// which makes the function jump between Voronoi regions of the samples and the extracted
/// surface jagged. We blend the signed distances to the planes of the k nearest samples with
/// Gaussian weights (scale: the distance to the k-th neighbour), which keeps the zero set on
/// the tangent planes where they agree and makes it continuous where they do not.

#include "implicit_function.h"
#include "../parallel.h"

#include <vcg/space/index/kdtree/kdtree.h>

#include <memory>
#include <vector>

namespace ib {

class HoppeDistance : public ImplicitFunction
{
public:
    /// P, N: n×3 sample positions and unit outward normals (rows). k: planes blended per query.
    HoppeDistance(const Points& P, const Points& N, int k = 8, int threads = 0)
        : P_(P), N_(N), k_(std::max(1, std::min<int>(k, int(P.rows())))), threads_(threads)
    {
        tree_ = std::make_unique<vcg::KdTree<double>>(vcg::ConstDataWrapper<vcg::Point3d>(
            reinterpret_cast<const vcg::Point3d*>(P_.data()), int(P_.rows())));
    }

    void Eval(const Points& Q, Eigen::Ref<Eigen::VectorXd> values) const override
    {
        ParallelFor(size_t(Q.rows()), threads_, [&](size_t begin, size_t end, int) {
            vcg::KdTree<double>::PriorityQueue queue;
            for (size_t i = begin; i < end; ++i)
                values[Eigen::Index(i)] = EvalOne(Q.row(Eigen::Index(i)).transpose(), queue);
        });
    }

private:
    double EvalOne(const Eigen::Vector3d& q, vcg::KdTree<double>::PriorityQueue& queue) const
    {
        tree_->doQueryK(vcg::Point3d(q[0], q[1], q[2]), k_, queue);
        const int found = queue.getNofElements();
        // The queue is a max-heap on squared distance: its top is the farthest neighbour.
        const double scale2 = std::max(queue.getTopWeight(), 1e-300);
        double sum = 0, weights = 0;
        for (int j = 0; j < found; ++j) {
            const int id = queue.getIndex(j);
            const double w = std::exp(-queue.getWeight(j) / scale2);
            sum += w * (q - P_.row(id).transpose()).dot(N_.row(id).transpose());
            weights += w;
        }
        return sum / weights;
    }

    Points P_, N_;
    int k_;
    int threads_;
    std::unique_ptr<vcg::KdTree<double>> tree_;
};

} // namespace ib
