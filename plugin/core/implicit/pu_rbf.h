#pragma once
/// \file pu_rbf.h
/// Partition-of-unity RBF implicit function (paper §4), after
/// I. Tobor, P. Reuter, C. Schlick, "Reconstructing multi-scale variational partition of unity
/// implicit surfaces with attributes", Graphical Models 68(1), 2006, and
/// Y. Ohtake, A. Belyaev, M. Alexa, G. Turk, H.-P. Seidel, "Multi-level partition of unity
/// implicits", SIGGRAPH 2003.
///
/// Cells: the leaves of an octree over the samples (point_octree.h), a node split while it holds
/// more than `max_samples` samples, or while its support box holds more than kSplitFactor times
/// `max_fit_samples` (a leaf the surface only grazes). Every leaf holding a sample gets a local
/// function on its support box: a cube centred on the centroid of the leaf's samples, `overlap`
/// times the leaf's side (more if needed to keep the leaf's samples a margin inside), grown
/// further (to the distance of the `min_samples`-th nearest sample from its centre) where the
/// data are sparse, so every local fit sees at least `min_samples` samples (or all of them, if
/// there are fewer), and at most `max_fit_samples` of them (the nearest to the centre; at most
/// `min_samples` if that is more).
///
/// Local function (rbf_local_fit.h, with why this kernel and system):
///     f_c(x) = h [ sum_j l_j |u - u_j|^3 + a_0 + a.u ],  u = (x - centre)/h,
/// the least-squares fit to f = 0 at the samples in the box and f = +-e at the off-surface
/// points of some of them, which are also its centres u_j, under the moment conditions.
///
/// Off-surface distance (off_surface.h): `off_surface` local spacings (spacing.h, or
/// Param::spacing), shortened or dropped where it would cross a thin part.
///
/// Blending: F(x) = sum_c w_c(x) f_c(x) / sum_c w_c(x), with the tensor-product bump
/// w_c(x) = prod_axis (1 - u_a^2)^2 on the support box (C^1, exactly zero outside the box, so a
/// query only visits the few boxes that contain it).
///
/// Far field: where the weights sum below kCoverage (outside every support box, or near the
/// edge of the last one), the missing weight goes to the signed distance to the tangent plane
/// of the nearest sample, (x - p) . n. So F is defined everywhere, continuous where the boxes
/// end, has the right sign far from the samples (for closed, consistently oriented data), and
/// equals the pure partition of unity wherever the boxes cover.
///
/// Sign convention (implicit_function.h): negative inside, positive outside, ~ signed distance
/// near the samples.

#include "implicit_function.h"
#include "off_surface.h"
#include "point_octree.h"
#include "rbf_local_fit.h"
#include "../parallel.h"
#include "../samples.h"

#include <wrap/callback.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace ib {

class PuRbf : public ImplicitFunction
{
public:
    struct Param
    {
        int min_samples = 50;          ///< fewest samples a local fit sees (support grown until)
        int max_samples = 160;         ///< a cell holding more is split
        double overlap = 1.5;          ///< support box side / cell side (advanced): a quarter cell each side
        double off_surface = 1.0;      ///< off-surface distance e, in local sample spacings (advanced)
        double regularization = 3e-7;  ///< ridge, relative to the mean diagonal of M^T M (advanced)
        int max_fit_samples = 400;     ///< cap of the samples in one local fit (piles of duplicates)
        int max_centres = 80;          ///< RBF centres per local function: a third on samples, the rest
                                       ///< their off-surface points (advanced)
        int threads = 0;               ///< 0 = all cores
        /// n local sample spacings, one per row of P, that set the off-surface distances; empty:
        /// measured among all samples. Merged range scans pass the spacing within each sample's
        /// own scan: overlapping scans multiply the density but lie apart by their registration
        /// error, so off-surface points one merged spacing out land on the next scan's sheet.
        Eigen::VectorXd spacing;
        PointOctree::Box root;         ///< the octree's root cube (half 0: the samples' bounding cube)

        /// Fits of 20-60 samples per cell instead of the paper's 50-160, whose smoother fits cut
        /// across concave creases and thin parts, away from the samples (BENCHMARKS.md, "Smaller
        /// local fits by default"): the reconstruction's default.
        static Param Local()
        {
            Param f;
            f.min_samples = 20;
            f.max_samples = 60;
            return f;
        }

        /// The same fits per sheet where `sheets` scans overlap (SampleSpacing::Overlap), so a fit
        /// sees every sheet, not one sheet's registration error against the next. Capped.
        Param PerSheet(double sheets) const
        {
            Param f = *this;
            f.min_samples = std::min(2000, int(std::lround(sheets * min_samples)));
            f.max_samples = std::min(5000, int(std::lround(sheets * max_samples)));
            return f;
        }
    };

    struct Stats
    {
        int octree_nodes = 0, leaves = 0, cells = 0;  ///< cells: leaves with a local function
        size_t centres = 0;                            ///< RBF centres over all cells
        size_t off_surface_points = 0, off_surface_dropped = 0;
        int solver_fallbacks = 0;                      ///< cells whose solve failed: reduced to their plane
        double median_spacing = 0, fit_seconds = 0;
    };

    /// Weight sum under which the nearest tangent plane fills in (see the file comment).
    static constexpr double kCoverage = 1e-3;
    /// Deepest octree level: bounds the split of piles of identical samples.
    static constexpr int kMaxDepth = PointOctree::kMaxDepth;
    /// A leaf whose support box holds more than this many times max_fit_samples is split.
    /// Where the surface only crosses a corner of a large leaf, the box of its few samples (1.5
    /// times the leaf) spans far more surface than the leaf: on the closed bunny a depth-2 leaf
    /// of 124 samples had 3271 in its box, fit only the nearest 400 and left the rest unfit but
    /// weighted: the zero set strayed up to 5.3 spacings from the samples (p99 1.4). Splitting
    /// them: max 0.32, p99 0.17. A leaf of one sample too: a lone sample in the corner of a
    /// large cube (one in a few million random scan samples lands so) otherwise got a box 1.5
    /// times the cube, fit only its 400 nearest of the 100,000 samples inside and blended that
    /// fit over all of them: the zero set strayed 3 spacings off a 5M-sample scan there, 17 off
    /// a plane in the core test. Not a factor 1: sparse leaves next to dense regions then split
    /// into leaves of one or two samples whose grown boxes cover the sparse part badly (0.3
    /// sparse spacings off on the tests' half-sparse sphere, instead of 0.03).
    static constexpr size_t kSplitFactor = 3;

    /// P, N: n×3 samples and unit outward normals (rows). Both are copied, and P gets its own
    /// k-d tree. Fits all local functions; cb (may be null) goes from 0 to 100. Throws
    /// std::invalid_argument for no samples, mismatched shapes, non-finite positions, samples
    /// that all coincide, or parameters out of range.
    PuRbf(const Points& P, const Points& N, const Param& param, vcg::CallBackPos* cb = nullptr)
        : PuRbf(std::make_unique<Owned>(Check(P, N)), nullptr, N, param, cb)
    {
    }

    /// The same over the samples of `samples` and their k-d tree, shared, not copied (they must
    /// outlive this function): a large scan's positions and tree are the biggest per-sample
    /// parts of the run's memory after the lattice.
    PuRbf(const SampleIndex& samples, const Points& N, const Param& param, vcg::CallBackPos* cb = nullptr)
        : PuRbf(nullptr, &samples, (Check(samples.P(), N), N), param, cb)
    {
    }

    PuRbf(const Points& P, const Points& N) : PuRbf(P, N, Param()) {}  ///< with the default Param
    PuRbf(const PuRbf&) = delete;  // index_ and octree_ refer to P_
    PuRbf& operator=(const PuRbf&) = delete;

    void Eval(const Points& Q, Eigen::Ref<Eigen::VectorXd> values) const override
    {
        ParallelFor(size_t(Q.rows()), param_.threads, [&](size_t begin, size_t end, int) {
            for (size_t i = begin; i < end; ++i)
                values[Eigen::Index(i)] = EvalOne(Q.row(Eigen::Index(i)).transpose());
        });
    }

    const Stats& Statistics() const { return stats_; }
    int Cells() const { return stats_.cells; }
    double FitSeconds() const { return stats_.fit_seconds; }

private:
    /// The samples' own copy and k-d tree, when they are not shared.
    struct Owned
    {
        explicit Owned(const Points& P) : P(P), index(this->P) {}
        Points P;
        SampleIndex index;
    };

    PuRbf(std::unique_ptr<Owned> owned, const SampleIndex* shared, const Points& N, const Param& param,
          vcg::CallBackPos* cb)
        : owned_(std::move(owned)), index_(owned_ ? owned_->index : *shared), P_(index_.P()), N_(Normalised(N)),
          param_(param)
    {
        if (!(param.min_samples >= 1 && param.max_samples >= 1 && param.overlap >= 1 && param.off_surface > 0 &&
              param.max_fit_samples >= 1 && param.max_centres >= 1))
            throw std::invalid_argument("PuRbf: min_samples, max_samples, max_fit_samples and max_centres must be "
                                        ">= 1, overlap >= 1 and off_surface > 0");
        if (param.spacing.size() != 0 && param.spacing.size() != P_.rows())
            throw std::invalid_argument("PuRbf: one spacing per sample, or none");
        const auto start = std::chrono::steady_clock::now();
        auto progress = [&](int percent, const char* what) { if (cb) cb(percent, what); };
        progress(0, "PU-RBF: octree");
        PointOctree::Param octree;
        octree.max_samples = param.max_samples;
        octree.overlap = param.overlap;
        octree.max_support_samples = kSplitFactor * size_t(param.max_fit_samples);
        octree.root = param.root;
        octree_ = PointOctree(P_, octree);
        std::vector<PointOctree::Box> boxes = LeafBoxes();
        progress(5, "PU-RBF: off-surface points");
        OffSurface::Result off = OffSurface::Compute(index_, N_, param_.spacing, param_.off_surface, param_.threads);
        eps_ = std::move(off.e);
        stats_.median_spacing = off.median_spacing;
        stats_.off_surface_points = off.kept;
        stats_.off_surface_dropped = off.dropped;
        progress(10, "PU-RBF: fitting local functions");
        Fit(boxes, cb);
        Bound();
        stats_.fit_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        progress(100, "PU-RBF: done");
    }

    /// A node of the tree the blend descends: an octree node with the bounds of the support
    /// boxes below it, so a query skips the subtrees whose boxes all miss it.
    struct BoxNode
    {
        Eigen::Vector3d lo, hi;          ///< union of the support boxes below (empty: lo > hi)
        int child = -1;                  ///< as in the octree
        int cell = -1;                   ///< a leaf's local function, -1 if it has none
    };

    static const Points& Check(const Points& P, const Points& N)
    {
        if (P.rows() == 0)
            throw std::invalid_argument("PuRbf: no samples");
        if (N.rows() != P.rows())
            throw std::invalid_argument("PuRbf: " + std::to_string(N.rows()) + " normals for " +
                                        std::to_string(P.rows()) + " samples");
        if (!P.allFinite())
            throw std::invalid_argument("PuRbf: non-finite sample positions");
        if ((P.colwise().maxCoeff() - P.colwise().minCoeff()).maxCoeff() <= 0)
            throw std::invalid_argument("PuRbf: all samples coincide; a surface needs distinct positions");
        return P;
    }

    /// Unit normals; zero or non-finite ones become zero (such samples get no off-surface points).
    static Points Normalised(const Points& N)
    {
        Points U = N;
        for (Eigen::Index i = 0; i < U.rows(); ++i) {
            const double l = U.row(i).norm();
            if (std::isfinite(l) && l > 1e-12)
                U.row(i) /= l;
            else
                U.row(i).setZero();
        }
        return U;
    }

    /// The support boxes of the octree's leaves that hold samples, one per cell in node order;
    /// numbers the cells in tree_.
    std::vector<PointOctree::Box> LeafBoxes()
    {
        const std::vector<PointOctree::Node>& nodes = octree_.Nodes();
        tree_.resize(nodes.size());
        std::vector<PointOctree::Box> boxes;
        for (size_t i = 0; i < nodes.size(); ++i) {
            tree_[i].child = nodes[i].child;
            if (nodes[i].child < 0) {
                ++stats_.leaves;
                if (nodes[i].end > nodes[i].begin) {
                    tree_[i].cell = int(boxes.size());
                    boxes.push_back(octree_.SupportBox(nodes[i]));
                }
            }
        }
        stats_.octree_nodes = int(nodes.size());
        stats_.cells = int(boxes.size());
        return boxes;
    }

    /// The samples of every cell (its support box's, grown where sparse, capped), its centres,
    /// then its local fit.
    void Fit(std::vector<PointOctree::Box>& boxes, vcg::CallBackPos* cb)
    {
        const int ncells = int(boxes.size());
        std::vector<std::vector<int>> local(static_cast<size_t>(ncells)), chosen(static_cast<size_t>(ncells));
        const int k = std::min<int>(param_.min_samples, int(P_.rows()));
        const size_t cap = size_t(std::max(param_.max_fit_samples, param_.min_samples));
        RbfLocalFit::Param fit;
        fit.max_centres = param_.max_centres;
        fit.regularization = param_.regularization;
        ParallelFor(size_t(ncells), param_.threads, [&](size_t begin, size_t end, int) {
            std::vector<int> stack;
            std::vector<double> far;
            SampleIndex::Queue queue;
            for (size_t ci = begin; ci < end; ++ci) {
                PointOctree::Box& c = boxes[ci];
                std::vector<int>& ids = local[ci];
                octree_.Gather(c.centre.array() - c.half, c.centre.array() + c.half, ids, stack);
                if (int(ids.size()) < k) {  // sparse: grow the box to the k-th nearest sample
                    index_.Nearest(c.centre, k, queue);
                    c.half = std::max(c.half, std::sqrt(queue.getTopWeight()) * (1 + 1e-9));
                    octree_.Gather(c.centre.array() - c.half, c.centre.array() + c.half, ids, stack);
                }
                if (ids.size() > cap) {  // keep the nearest (L-inf) to the centre
                    auto linf = [&](int s) { return (P_.row(s).transpose() - c.centre).cwiseAbs().maxCoeff(); };
                    std::nth_element(ids.begin(), ids.begin() + Eigen::Index(cap) - 1, ids.end(), [&](int a, int b) {
                        const double da = linf(a), db = linf(b);
                        return da < db || (da == db && a < b);
                    });
                    ids.resize(cap);
                    std::sort(ids.begin(), ids.end());
                }
                RbfLocalFit::ChooseCentres(P_, c.centre, ids, fit, chosen[ci], far);
            }
        }, 16);

        // The largest system: a constraint per sample and per off-surface centre, an unknown
        // per centre and 4 for the linear polynomial.
        size_t rows = 0, cols = 0;
        for (size_t ci = 0; ci < size_t(ncells); ++ci) {
            const size_t centres = RbfLocalFit::CentreCount(chosen[ci], eps_);
            stats_.centres += centres;
            rows = std::max(rows, local[ci].size() + centres - chosen[ci].size());
            cols = std::max(cols, centres + 4);
        }

        cells_.resize(size_t(ncells));
        std::atomic<int> done{0};
        int reported = 10;
        ParallelFor(size_t(ncells), param_.threads, [&](size_t begin, size_t end, int thread) {
            RbfLocalFit::Workspace work{Eigen::Index(rows), Eigen::Index(cols)};
            for (size_t ci = begin; ci < end; ++ci) {
                cells_[ci] = RbfLocalFit(boxes[ci].centre, boxes[ci].half, P_, N_, eps_, local[ci], chosen[ci], fit, work);
                const int d = ++done;
                // Only the calling thread reports, so the callback needs no locking and is monotone.
                if (cb && thread == 0) {
                    const int percent = 10 + int(89.0 * d / ncells);
                    if (percent > reported)
                        cb(reported = percent, "PU-RBF: fitting local functions");
                }
            }
        }, 4);
        for (const RbfLocalFit& c : cells_)
            stats_.solver_fallbacks += c.FellBack();
    }

    /// Subtree bounds of the support boxes, children before parents (they come later in tree_).
    void Bound()
    {
        for (size_t i = tree_.size(); i-- > 0;) {
            BoxNode& nd = tree_[i];
            nd.lo.setConstant(std::numeric_limits<double>::infinity());
            nd.hi.setConstant(-std::numeric_limits<double>::infinity());
            if (nd.cell >= 0) {
                const RbfLocalFit& c = cells_[size_t(nd.cell)];
                nd.lo = c.Centre().array() - c.Half();
                nd.hi = c.Centre().array() + c.Half();
            }
            if (nd.child >= 0)
                for (int o = 0; o < 8; ++o) {
                    nd.lo = nd.lo.cwiseMin(tree_[size_t(nd.child + o)].lo);
                    nd.hi = nd.hi.cwiseMax(tree_[size_t(nd.child + o)].hi);
                }
        }
    }

    double EvalOne(const Eigen::Vector3d& q) const
    {
        // Depth-first over the boxes containing q; children in a fixed order, so the sum is
        // the same whichever thread evaluates q. A fixed stack: no allocation per query.
        std::array<int, PointOctree::kStackSize> stack;
        int top = 0;
        stack[size_t(top++)] = 0;
        double weights = 0, sum = 0;
        while (top > 0) {
            const BoxNode& nd = tree_[size_t(stack[size_t(--top)])];
            if ((q.array() < nd.lo.array()).any() || (q.array() > nd.hi.array()).any())
                continue;
            if (nd.child >= 0) {
                for (int o = 7; o >= 0; --o)
                    stack[size_t(top++)] = nd.child + o;
                continue;
            }
            const RbfLocalFit& c = cells_[size_t(nd.cell)];
            const Eigen::Array3d u = (q - c.Centre()).array() * c.InvHalf();
            const Eigen::Array3d t = (1 - u.square()).max(0.0);
            const double w = (t * t).prod();
            if (w <= 0)
                continue;
            const double local = c.Local(u);
            weights += w;
            sum += w * c.Half() * local;
        }
        if (weights >= kCoverage)
            return sum / weights;
        const int s = octree_.Nearest(q);
        const double plane = (q - P_.row(s).transpose()).dot(N_.row(s).transpose());
        return (sum + (kCoverage - weights) * plane) / kCoverage;
    }

    std::unique_ptr<Owned> owned_;     ///< null when the samples and their tree are shared
    const SampleIndex& index_;
    const Points& P_;                  ///< index_'s samples
    Points N_;
    Param param_;
    Stats stats_;
    PointOctree octree_;               ///< over P_
    std::vector<BoxNode> tree_;        ///< octree_'s nodes (same indices) with their boxes' bounds
    std::vector<RbfLocalFit> cells_;   ///< the local functions, a leaf holding samples each
    RbfLocalFit::Offsets eps_;         ///< signed off-surface distance per sample and side
};

} // namespace ib
