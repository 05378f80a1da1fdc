// The sample index: k nearest samples against a brute-force scan; scans of samples.
#include "samples.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

using namespace ib;

TEST(SampleIndex, NearestMatchesABruteForceScan)
{
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1, 1);
    Points P(500, 3);
    for (Eigen::Index i = 0; i < P.rows(); ++i)
        P.row(i) << u(rng), u(rng), 0.3 * u(rng);
    const SampleIndex index(P);
    EXPECT_EQ(&index.P(), &P);
    EXPECT_EQ(index.Size(), 500);
    SampleIndex::Queue queue;
    for (int q = 0; q < 50; ++q) {
        const Eigen::Vector3d x(1.5 * u(rng), 1.5 * u(rng), u(rng));
        for (int k : {1, 7, 20}) {
            std::vector<std::pair<double, int>> all;
            for (Eigen::Index i = 0; i < P.rows(); ++i)
                all.emplace_back((P.row(i).transpose() - x).squaredNorm(), int(i));
            std::sort(all.begin(), all.end());
            index.Nearest(x, k, queue);
            ASSERT_EQ(queue.getNofElements(), k);
            std::vector<std::pair<double, int>> found;
            for (int j = 0; j < k; ++j)
                found.emplace_back(queue.getWeight(j), queue.getIndex(j));
            std::sort(found.begin(), found.end());
            for (int j = 0; j < k; ++j) {
                EXPECT_EQ(found[size_t(j)].second, all[size_t(j)].second) << q << " " << k << " " << j;
                EXPECT_NEAR(found[size_t(j)].first, all[size_t(j)].first, 1e-12);
            }
            EXPECT_NEAR(queue.getTopWeight(), all[size_t(k - 1)].first, 1e-12);  // the farthest of the k
        }
    }
}

TEST(SampleIndex, ScanOfSamplesFollowsTheScansSizes)
{
    EXPECT_TRUE(ScanOfSamples({}, 5, {0, 1, 2}).empty());
    EXPECT_TRUE(ScanOfSamples({5}, 5, {0, 1, 2}).empty());  // one scan: no scan indices
    EXPECT_EQ(ScanOfSamples({3, 2}, 5, {0, 2, 3, 4}), (std::vector<int>{0, 0, 1, 1}));
    EXPECT_EQ(ScanOfSamples({1, 0, 2, 2}, 5, {4, 0, 2}), (std::vector<int>{3, 0, 2}));
}

TEST(SampleIndex, RowsOfScansListsEachScansSamplesInOrder)
{
    const std::vector<std::vector<Eigen::Index>> rows = RowsOfScans({1, 0, 1, 2, 0, 2, 2});
    ASSERT_EQ(rows.size(), 3u);
    EXPECT_EQ(rows[0], (std::vector<Eigen::Index>{1, 4}));
    EXPECT_EQ(rows[1], (std::vector<Eigen::Index>{0, 2}));
    EXPECT_EQ(rows[2], (std::vector<Eigen::Index>{3, 5, 6}));
}
