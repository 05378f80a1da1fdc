#pragma once
/// \file off_surface.h
/// The PU-RBF's off-surface constraints: for each sample, the signed distances along its
/// normal at which its local fits ask for f = +e (outside) and f = -e (inside).
///
/// e_i = `scale` times the local sample spacing at sample i, clamped to [0.5, 2] times the
/// median spacing so isolated samples and piles of duplicates get a sane value. The spacing,
/// not the fit's cell size, sets e because it is the scale of detail the samples resolve, and
/// it does not change with the cells' sample counts. On the tests' sphere and torus, clean or
/// noisy, 0.5 to 2 spacings give the same accuracy within ~25%; one spacing stays above scan
/// noise (a fraction of a spacing) while keeping the points on the right side of thin parts.
/// The standard check (Carr et al., "Reconstruction and representation of 3D objects with
/// radial basis functions", SIGGRAPH 2001): an off-surface point closer to another sample than
/// to its own would cross a thin part or a fold; e is halved up to twice, then the point is
/// dropped.

#include "rbf_local_fit.h"
#include "../parallel.h"
#include "../samples.h"
#include "../spacing.h"

#include <algorithm>
#include <cmath>

namespace ib {

class OffSurface
{
public:
    struct Result
    {
        RbfLocalFit::Offsets e;     ///< n×2: per sample, +e (>= 0) and -e (<= 0); 0: dropped
        double median_spacing = 0;  ///< of `spacing`, or from the bounding box when that is 0
        size_t kept = 0;            ///< off-surface points kept
        size_t dropped = 0;         ///< of samples with a normal, dropped by the check
    };

    /// samples: n positions and their k-d tree; N: n×3 unit normals (zero rows: no points);
    /// spacing: per sample, its local spacing (empty: measured here); scale: e in spacings.
    static Result Compute(const SampleIndex& samples, const Points& N, Eigen::VectorXd spacing, double scale,
                          int threads)
    {
        const Points& P = samples.P();
        if (spacing.size() == 0)
            spacing = SampleSpacing::Local(samples, 1, threads);
        Result r;
        r.median_spacing = SampleSpacing::Median(spacing);
        if (!(r.median_spacing > 0))  // most samples duplicated many times: the area per sample
            r.median_spacing = (P.colwise().maxCoeff() - P.colwise().minCoeff()).norm() / std::sqrt(double(P.rows()));
        const double median = r.median_spacing;
        r.e.resize(P.rows(), 2);
        ParallelFor(size_t(P.rows()), threads, [&](size_t begin, size_t end, int) {
            SampleIndex::Queue queue;
            for (size_t s = begin; s < end; ++s) {
                const Eigen::Index i = Eigen::Index(s);
                const double e0 = scale * std::clamp(spacing[i], 0.5 * median, 2.0 * median);
                for (int side = 0; side < 2; ++side) {
                    double e = N.row(i).squaredNorm() > 0 && e0 > 0 ? e0 : 0;
                    for (int attempt = 0; e > 0; ++attempt, e *= 0.5) {
                        if (attempt == 3) {
                            e = 0;
                            break;
                        }
                        const Eigen::Vector3d o = (P.row(i) + (side == 0 ? e : -e) * N.row(i)).transpose();
                        samples.Nearest(o, 1, queue);
                        if (queue.getWeight(0) >= e * e * (1 - 1e-6))
                            break;  // its own sample is (one of) the nearest
                    }
                    r.e(i, side) = side == 0 ? e : -e;
                }
            }
        }, 256);
        for (Eigen::Index i = 0; i < r.e.rows(); ++i)
            for (int side = 0; side < 2; ++side) {
                const bool kept = r.e(i, side) != 0;
                r.kept += kept;
                r.dropped += !kept && N.row(i).squaredNorm() > 0;
            }
        return r;
    }
};

} // namespace ib
