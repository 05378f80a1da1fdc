#include "implicit/point_octree.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

using namespace ib;

namespace {

/// An uneven cloud: 3000 points on the unit sphere, a dense clump of 2000 near one pole, and a
/// pile of 300 copies of one point (deterministic).
Points UnevenCloud()
{
    std::mt19937 rng(11);
    std::normal_distribution<double> g(0, 1);
    Points P(5300, 3);
    for (Eigen::Index i = 0; i < 3000; ++i) {
        const Eigen::Vector3d d(g(rng), g(rng), g(rng));
        P.row(i) = d.normalized().transpose();
    }
    for (Eigen::Index i = 3000; i < 5000; ++i)
        P.row(i) << 0.01 * g(rng), 0.01 * g(rng), 1 + 0.01 * g(rng);
    for (Eigen::Index i = 5000; i < 5300; ++i)
        P.row(i) << 0.3, -0.4, 0.2;
    return P;
}

PointOctree::Param SmallLeaves()
{
    PointOctree::Param p;
    p.max_samples = 40;
    p.overlap = 1.5;
    p.max_support_samples = 400;
    return p;
}

bool InClosedBox(const Eigen::Vector3d& p, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi)
{
    return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
}

std::vector<int> BruteForceInBox(const Points& P, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi)
{
    std::vector<int> ids;
    for (Eigen::Index i = 0; i < P.rows(); ++i)
        if (InClosedBox(P.row(i).transpose(), lo, hi))
            ids.push_back(int(i));
    return ids;
}

} // namespace

TEST(PointOctree, EverySampleLiesInExactlyOneLeafWithinItsCube)
{
    const Points P = UnevenCloud();
    const PointOctree::Param param = SmallLeaves();
    const PointOctree tree(P, param);
    const auto& nodes = tree.Nodes();
    ASSERT_GT(nodes.size(), 8u);
    std::vector<int> sorted = tree.Order();
    std::sort(sorted.begin(), sorted.end());
    for (int i = 0; i < int(sorted.size()); ++i)
        ASSERT_EQ(sorted[size_t(i)], i);  // a permutation of the samples

    std::vector<int> leaves_of(size_t(P.rows()), 0);
    int deepest = 0;
    const double tolerance = 1e-12 * nodes[0].half;  // the children's cubes are rounded
    for (const PointOctree::Node& nd : nodes) {
        if (nd.child >= 0)
            continue;
        deepest = std::max(deepest, nd.depth);
        // A leaf holds at most max_samples, unless it could not be split further.
        EXPECT_TRUE(nd.end - nd.begin <= param.max_samples || nd.depth == PointOctree::kMaxDepth);
        for (int k = nd.begin; k < nd.end; ++k) {
            const int s = tree.Order()[size_t(k)];
            ++leaves_of[size_t(s)];
            EXPECT_TRUE(InClosedBox(P.row(s).transpose(), nd.centre.array() - nd.half - tolerance,
                                    nd.centre.array() + nd.half + tolerance));
        }
    }
    for (int count : leaves_of)
        EXPECT_EQ(count, 1);
    // The pile of 300 identical samples is split until the maximum depth, no further.
    EXPECT_EQ(deepest, PointOctree::kMaxDepth);
}

TEST(PointOctree, ChildrenAreTheEightOctantsOfTheirParent)
{
    const Points P = UnevenCloud();
    const PointOctree tree(P, SmallLeaves());
    const auto& nodes = tree.Nodes();
    EXPECT_EQ(nodes[0].begin, 0);
    EXPECT_EQ(nodes[0].end, int(P.rows()));
    for (const PointOctree::Node& nd : nodes) {
        if (nd.child < 0)
            continue;
        ASSERT_LE(size_t(nd.child + 8), nodes.size());
        int next = nd.begin;  // the children's slices tile the parent's, in octant order
        for (int o = 0; o < 8; ++o) {
            const PointOctree::Node& c = nodes[size_t(nd.child + o)];
            EXPECT_EQ(c.depth, nd.depth + 1);
            EXPECT_EQ(c.half, 0.5 * nd.half);
            for (int a = 0; a < 3; ++a)
                EXPECT_EQ(c.centre[a] > nd.centre[a], bool(o & (1 << a)));
            EXPECT_EQ(c.begin, next);
            next = c.end;
        }
        EXPECT_EQ(next, nd.end);
    }
}

TEST(PointOctree, SupportBoxesAroundTheirLeafScaledByTheOverlap)
{
    const Points P = UnevenCloud();
    for (double overlap : {1.0, 1.5, 2.0}) {
        PointOctree::Param param = SmallLeaves();
        param.overlap = overlap;
        const PointOctree tree(P, param);
        int checked = 0;
        for (const PointOctree::Node& nd : tree.Nodes()) {
            if (nd.child >= 0 || nd.end == nd.begin)
                continue;
            const PointOctree::Box b = tree.SupportBox(nd);
            Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
            for (int k = nd.begin; k < nd.end; ++k)
                centroid += P.row(tree.Order()[size_t(k)]).transpose();
            centroid /= nd.end - nd.begin;
            EXPECT_LT((b.centre - centroid).norm(), 1e-12);
            // At least the leaf's side times the overlap ...
            EXPECT_GE(b.half, overlap * nd.half);
            // ... and every sample of the leaf (overlap - 1) leaf half-sides inside its border.
            const double margin = (overlap - 1) * nd.half - 1e-12;  // the box's bounds are rounded
            for (int k = nd.begin; k < nd.end; ++k)
                EXPECT_TRUE(InClosedBox(P.row(tree.Order()[size_t(k)]).transpose(), b.centre.array() - b.half + margin,
                                        b.centre.array() + b.half - margin));
            ++checked;
        }
        EXPECT_GT(checked, 20);
    }
}

TEST(PointOctree, LeavesAreSplitUntilTheirSupportBoxHoldsFewEnoughSamples)
{
    // A dense flat scan and one sample far above it: by count alone the lone sample's leaf
    // would be a large cube whose support box covers much of the scan.
    std::vector<Eigen::RowVector3d> ps;
    for (int i = 0; i <= 100; ++i)
        for (int j = 0; j <= 100; ++j)
            ps.emplace_back(-1 + 0.02 * i, -1 + 0.02 * j, 0);
    ps.emplace_back(0.3, 0.3, 0.5);
    Points P(Eigen::Index(ps.size()), 3);
    for (size_t i = 0; i < ps.size(); ++i)
        P.row(Eigen::Index(i)) = ps[i];
    PointOctree::Param param;  // the defaults: 160 per leaf, 1200 per support box
    const PointOctree tree(P, param);
    const size_t limit = param.max_support_samples;
    size_t lone_box_samples = 0;
    for (const PointOctree::Node& nd : tree.Nodes()) {
        if (nd.child >= 0 || nd.end == nd.begin)
            continue;
        const PointOctree::Box b = tree.SupportBox(nd);
        EXPECT_LE(tree.CountInBox(b, limit), limit);
        if (std::find(tree.Order().begin() + nd.begin, tree.Order().begin() + nd.end, int(P.rows() - 1)) !=
            tree.Order().begin() + nd.end)
            lone_box_samples = tree.CountInBox(b, limit);
    }
    EXPECT_EQ(lone_box_samples, 1u);  // its box stays clear of the scan
}

TEST(PointOctree, CountAndGatherMatchABruteForceScan)
{
    const Points P = UnevenCloud();
    const PointOctree tree(P, SmallLeaves());
    std::vector<int> position(size_t(P.rows()));  // of each sample in Order()
    for (size_t k = 0; k < tree.Order().size(); ++k)
        position[size_t(tree.Order()[k])] = int(k);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> at(-1.3, 1.3), size(0.0, 0.8);
    std::vector<int> ids, stack;
    for (int trial = 0; trial < 200; ++trial) {
        PointOctree::Box b;
        b.centre = Eigen::Vector3d(at(rng), at(rng), at(rng));
        b.half = trial % 10 == 0 ? 0.0 : size(rng);
        if (trial % 7 == 0)
            b.centre = P.row(trial).transpose();  // a box on samples, up to their piles
        const Eigen::Vector3d lo = b.centre.array() - b.half, hi = b.centre.array() + b.half;
        const std::vector<int> expected = BruteForceInBox(P, lo, hi);

        tree.Gather(lo, hi, ids, stack);
        for (size_t i = 1; i < ids.size(); ++i)
            EXPECT_LT(position[size_t(ids[i - 1])], position[size_t(ids[i])]);  // in Order() order
        std::sort(ids.begin(), ids.end());
        EXPECT_EQ(ids, expected);

        EXPECT_EQ(tree.CountInBox(b, P.rows()), expected.size());
        const size_t limit = 25;  // counted up to just past the limit
        const size_t capped = tree.CountInBox(b, limit);
        if (expected.size() <= limit)
            EXPECT_EQ(capped, expected.size());
        else
            EXPECT_GT(capped, limit);
    }
}

TEST(PointOctree, NearestMatchesABruteForceScan)
{
    const Points P = UnevenCloud();
    const PointOctree tree(P, SmallLeaves());
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> near(-1.5, 1.5), far(-40, 40);
    for (int trial = 0; trial < 500; ++trial) {
        std::uniform_real_distribution<double>& d = trial % 5 == 0 ? far : near;
        Eigen::Vector3d q(d(rng), d(rng), d(rng));
        if (trial % 11 == 0)
            q = P.row(trial * 7).transpose();  // on a sample
        double best = std::numeric_limits<double>::infinity();
        for (Eigen::Index i = 0; i < P.rows(); ++i)
            best = std::min(best, (P.row(i).transpose() - q).squaredNorm());
        const int s = tree.Nearest(q);
        ASSERT_GE(s, 0);
        ASSERT_LT(s, P.rows());
        EXPECT_EQ((P.row(s).transpose() - q).squaredNorm(), best);
    }
}
