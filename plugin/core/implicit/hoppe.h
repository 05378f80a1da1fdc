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
#include "../samples.h"

namespace ib {

class HoppeDistance : public ImplicitFunction
{
public:
    /// samples: the sample positions; N: n×3 unit outward normals (rows), kept by reference.
    /// k: planes blended per query.
    HoppeDistance(const SampleIndex& samples, const Points& N, int k = 8, int threads = 0)
        : samples_(samples), N_(N), k_(std::max(1, std::min<int>(k, int(samples.Size())))), threads_(threads)
    {
    }

    void Eval(const Points& Q, Eigen::Ref<Eigen::VectorXd> values) const override
    {
        ParallelFor(size_t(Q.rows()), threads_, [&](size_t begin, size_t end, int) {
            SampleIndex::Queue queue;
            for (size_t i = begin; i < end; ++i)
                values[Eigen::Index(i)] = EvalOne(Q.row(Eigen::Index(i)).transpose(), queue);
        });
    }

private:
    double EvalOne(const Eigen::Vector3d& q, SampleIndex::Queue& queue) const
    {
        samples_.Nearest(q, k_, queue);
        const int found = queue.getNofElements();
        // The queue is a max-heap on squared distance: its top is the farthest neighbour.
        const double scale2 = std::max(queue.getTopWeight(), 1e-300);
        double sum = 0, weights = 0;
        for (int j = 0; j < found; ++j) {
            const int id = queue.getIndex(j);
            const double w = std::exp(-queue.getWeight(j) / scale2);
            sum += w * (q - samples_.P().row(id).transpose()).dot(N_.row(id).transpose());
            weights += w;
        }
        return sum / weights;
    }

    const SampleIndex& samples_;
    const Points& N_;
    int k_;
    int threads_;
};

} // namespace ib
