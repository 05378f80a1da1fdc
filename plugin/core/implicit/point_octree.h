#pragma once
/// \file point_octree.h
/// Adaptive octree over a point set, for the partition of unity (pu_rbf.h): its leaves are the
/// cells, each with a support box around its samples that overlaps the neighbours' boxes.
///
/// The root is the bounding cube of the samples (or Param::root); a node is split into 8 equal octants while it
/// holds more than `max_samples` samples, or while its support box (SupportBox) holds more than
/// `max_support_samples`, down to depth kMaxDepth (piles of identical samples cannot be split).
/// Each node owns a contiguous range of Order(), so a subtree's samples are one slice of it.
/// Queries (counting and gathering the samples in a box, the nearest sample) descend the tree
/// with pruning by the nodes' cubes.

#include "../lattice.h"  // Points

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <limits>
#include <vector>

namespace ib {

class PointOctree
{
public:
    /// An axis-aligned cube: [centre - half, centre + half] on every axis.
    struct Box
    {
        Eigen::Vector3d centre = Eigen::Vector3d::Zero();
        double half = 0;
    };

    struct Param
    {
        int max_samples = 160;               ///< a node holding more samples is split (>= 1)
        double overlap = 1.5;                ///< support box side / leaf side (>= 1)
        size_t max_support_samples = 1200;   ///< a node whose support box holds more is split
        /// The root's cube; half 0: the samples' bounding cube. A tile of a scan (tiling.h)
        /// roots its octree at the whole scan's, so its cells are the whole scan's cells.
        Box root;
    };

    struct Node
    {
        Eigen::Vector3d centre;
        double half = 0;                 ///< half side of the node's cube
        int begin = 0, end = 0;          ///< its samples: Order()[begin, end)
        int depth = 0;                   ///< 0 at the root
        int child = -1;                  ///< first of 8 consecutive children; -1 for a leaf
    };

    /// Deepest level: bounds the split of piles of identical samples.
    static constexpr int kMaxDepth = 20;
    /// Size of a stack that descends the tree depth first, pushing the 8 children of a node at
    /// a time: at most 7 wait on each level above the current node, and 8 below it.
    static constexpr size_t kStackSize = 7 * kMaxDepth + 8;

    /// An empty octree, to assign a built one to.
    PointOctree() = default;

    /// P: n×3 samples (rows), n >= 1, not all identical; kept by reference, so P must outlive
    /// the octree. Nodes are laid out breadth first: Nodes()[0] is the root, and the 8 children
    /// of a node are consecutive, in octant order (bit a of the octant set: above the centre on
    /// axis a).
    PointOctree(const Points& P, const Param& param) : P_(&P), param_(param) { Build(); }

    const std::vector<Node>& Nodes() const { return nodes_; }
    /// n sample ids (rows of P), each node's slice in octant order.
    const std::vector<int>& Order() const { return order_; }

    /// The support box of the node nd: a cube centred on the centroid of its samples (nd must
    /// hold one), where a local fit is best (its weight peaks there, not in a corner of the node
    /// with no data). It keeps the node's samples `overlap - 1` node half-sides inside its
    /// border, and its half side is at least `overlap` times the node's.
    Box SupportBox(const Node& nd) const
    {
        Box b;
        for (int k = nd.begin; k < nd.end; ++k)
            b.centre += Sample(k);
        b.centre /= nd.end - nd.begin;
        double spread = 0;
        for (int k = nd.begin; k < nd.end; ++k)
            spread = std::max(spread, (Sample(k) - b.centre).cwiseAbs().maxCoeff());
        const double overlap = param_.overlap;
        b.half = std::max(overlap * nd.half, spread + (overlap - 1) * nd.half);
        return b;
    }

    /// Number of samples in the closed box b, counted only up to just past `limit` (the answer
    /// is exact when at most limit, and some value > limit otherwise).
    size_t CountInBox(const Box& b, size_t limit) const
    {
        const Eigen::Array3d lo = b.centre.array() - b.half, hi = b.centre.array() + b.half;
        size_t count = 0;
        std::vector<int> stack(1, 0);
        while (!stack.empty() && count <= limit) {
            const Node& nd = nodes_[size_t(stack.back())];
            stack.pop_back();
            if (nd.end == nd.begin || ((nd.centre.array() + nd.half) < lo).any() || ((nd.centre.array() - nd.half) > hi).any())
                continue;
            if (nd.child >= 0) {
                for (int o = 0; o < 8; ++o)
                    stack.push_back(nd.child + o);
                continue;
            }
            for (int k = nd.begin; k < nd.end; ++k) {
                const Eigen::Array3d p = Sample(k);
                count += (p >= lo).all() && (p <= hi).all();
            }
        }
        return count;
    }

    /// The ids of the samples inside the closed box [lo, hi] into `out` (replaced), in Order()
    /// order. stack: scratch, reused between calls to spare an allocation per query.
    void Gather(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, std::vector<int>& out, std::vector<int>& stack) const
    {
        out.clear();
        stack.assign(1, 0);
        while (!stack.empty()) {
            const Node& nd = nodes_[size_t(stack.back())];
            stack.pop_back();
            if (nd.end == nd.begin || ((nd.centre.array() + nd.half) < lo.array()).any() ||
                ((nd.centre.array() - nd.half) > hi.array()).any())
                continue;
            if (nd.child >= 0) {
                for (int o = 7; o >= 0; --o)
                    stack.push_back(nd.child + o);
                continue;
            }
            for (int k = nd.begin; k < nd.end; ++k) {
                const int s = order_[size_t(k)];
                const auto p = P_->row(s).transpose().array();
                if ((p >= lo.array()).all() && (p <= hi.array()).all())
                    out.push_back(s);
            }
        }
    }

    /// The id of the sample nearest to q (of the nearest, the first one met), by branch and
    /// bound with a fixed stack: VCG's k-d tree query allocates its stack on every call.
    int Nearest(const Eigen::Vector3d& q) const
    {
        std::array<int, kStackSize> stack;
        int top = 0, best = -1;
        double best_d2 = std::numeric_limits<double>::infinity();
        stack[size_t(top++)] = 0;
        while (top > 0) {
            const Node& nd = nodes_[size_t(stack[size_t(--top)])];
            const Eigen::Array3d gap = ((q - nd.centre).array().abs() - nd.half).max(0.0);
            if (nd.end == nd.begin || gap.square().sum() >= best_d2)
                continue;
            if (nd.child >= 0) {
                // q's own octant last, so it is searched first and prunes the others.
                const int own = int(q[0] >= nd.centre[0]) | int(q[1] >= nd.centre[1]) << 1 | int(q[2] >= nd.centre[2]) << 2;
                for (int o = 7; o >= 0; --o)
                    stack[size_t(top++)] = nd.child + (o ^ own);
                continue;
            }
            for (int k = nd.begin; k < nd.end; ++k) {
                const int s = order_[size_t(k)];
                const double d2 = (P_->row(s).transpose() - q).squaredNorm();
                if (d2 < best_d2) {
                    best_d2 = d2;
                    best = s;
                }
            }
        }
        return best;
    }

private:
    Eigen::Vector3d Sample(int k) const { return P_->row(order_[size_t(k)]).transpose(); }

    void Build()
    {
        const Points& P = *P_;
        const Eigen::Index n = P.rows();
        order_.resize(size_t(n));
        for (Eigen::Index i = 0; i < n; ++i)
            order_[size_t(i)] = int(i);
        const Eigen::Vector3d lo = P.colwise().minCoeff(), hi = P.colwise().maxCoeff();
        Node root;
        const Box& given = param_.root;
        root.centre = given.half > 0 ? given.centre : Eigen::Vector3d(0.5 * (lo + hi));
        root.half = given.half > 0 ? given.half : 0.5 * (hi - lo).maxCoeff() * (1 + 1e-9);
        root.end = int(n);
        nodes_.push_back(root);
        std::vector<int> scratch;
        const size_t limit = param_.max_support_samples;
        // Breadth first: the 8 children of a node are consecutive, and nodes_ grows behind i.
        for (size_t i = 0; i < nodes_.size(); ++i) {
            const Node nd = nodes_[i];
            if (nd.depth >= kMaxDepth || nd.end == nd.begin)
                continue;
            // A node is split also when its support box holds too many samples (pu_rbf.h says
            // why), even a node of one sample: a lone sample in the corner of a large cube gets
            // a box over far more data than its own.
            if (nd.end - nd.begin <= param_.max_samples && CountInBox(SupportBox(nd), limit) <= limit)
                continue;
            // Counting sort of the node's samples by octant; stable, so deterministic.
            std::array<int, 9> start{};
            auto octant = [&](int s) {
                const auto p = P.row(s);
                return int(p[0] >= nd.centre[0]) | int(p[1] >= nd.centre[1]) << 1 | int(p[2] >= nd.centre[2]) << 2;
            };
            for (int k = nd.begin; k < nd.end; ++k)
                ++start[size_t(octant(order_[size_t(k)]) + 1)];
            for (int o = 0; o < 8; ++o)
                start[size_t(o + 1)] += start[size_t(o)];
            scratch.resize(size_t(nd.end - nd.begin));
            std::array<int, 9> fill = start;
            for (int k = nd.begin; k < nd.end; ++k) {
                const int s = order_[size_t(k)];
                scratch[size_t(fill[size_t(octant(s))]++)] = s;
            }
            std::copy(scratch.begin(), scratch.end(), order_.begin() + nd.begin);
            nodes_[i].child = int(nodes_.size());
            for (int o = 0; o < 8; ++o) {
                Node c;
                c.half = 0.5 * nd.half;
                c.centre = nd.centre + c.half * Eigen::Vector3d(o & 1 ? 1 : -1, o & 2 ? 1 : -1, o & 4 ? 1 : -1);
                c.begin = nd.begin + start[size_t(o)];
                c.end = nd.begin + start[size_t(o + 1)];
                c.depth = nd.depth + 1;
                nodes_.push_back(c);
            }
        }
    }

    const Points* P_ = nullptr;
    Param param_;
    std::vector<int> order_;
    std::vector<Node> nodes_;
};

} // namespace ib
