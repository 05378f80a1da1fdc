// PU-RBF robustness: duplicated and piled-up samples, a lone sample, far-apart clusters, fewer
// samples than a cell's minimum, impossible input, one thread against two, a shared k-d tree,
// progress, two overlapping sheets with their own spacing. Accuracy on known shapes is in test_pu_rbf.cpp.
#include "geometry.h"
#include "implicit/pu_rbf.h"
#include "implicit_accuracy.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>

using namespace ib;

namespace {
using test::Accuracy;
using test::AddNoise;
using test::AllFiniteOnGrid;
using test::GridAround;
using test::Measure;
using test::Print;
using test::Sphere;
using test::TorusPoints;
} // namespace

// A lone sample in its own octree leaf above a dense flat scan: its support box must not grow
// with the leaf's cube over the whole scan (was 17 spacings off the plane below it).
TEST(PuRbf, LoneSampleLeafDoesNotSpanTheScan)
{
    const double spacing = 0.01;
    std::vector<Eigen::RowVector3d> ps;
    for (int i = 0; i <= 200; ++i)
        for (int j = 0; j <= 200; ++j)
            ps.emplace_back(-1 + spacing * i, -1 + spacing * j, 0);
    ps.emplace_back(0.3, 0.3, 0.5);
    Points P(Eigen::Index(ps.size()), 3), N(Eigen::Index(ps.size()), 3);
    for (size_t i = 0; i < ps.size(); ++i) {
        P.row(Eigen::Index(i)) = ps[i];
        N.row(Eigen::Index(i)) << 0, 0, 1;
    }
    const PuRbf f(P, N);
    Eigen::VectorXd value(P.rows() - 1);
    f.Eval(P.topRows(P.rows() - 1), value);
    EXPECT_LT(value.cwiseAbs().maxCoeff(), 0.05 * spacing);
}

TEST(PuRbf, SameValuesForOneAndTwoThreads)
{
    Points P, N;
    TorusPoints(60, 1.0, 0.35, P, N);
    AddNoise(P, 0.002);
    PuRbf::Param one, two;
    one.threads = 1;
    two.threads = 2;
    const PuRbf f1(P, N, one), f2(P, N, two);
    const Points G = GridAround(P, 48);
    Eigen::VectorXd v1(G.rows()), v2(G.rows());
    f1.Eval(G, v1);
    f2.Eval(G, v2);
    EXPECT_EQ(f1.Cells(), f2.Cells());
    EXPECT_EQ(std::memcmp(v1.data(), v2.data(), sizeof(double) * size_t(v1.size())), 0);
}

TEST(PuRbf, DuplicatedSamples)
{
    Points P1, N1, Q, unused;
    test::SpherePoints(3000, 1.0, P1, N1);
    Points P(3 * P1.rows(), 3), N(3 * P1.rows(), 3);  // every sample three times
    P << P1, P1, P1;
    N << N1, N1, N1;
    test::SpherePoints(2001, 1.0, Q, unused);
    const PuRbf f(P, N);
    const Accuracy a = Measure(f, Q, Sphere(1.0), std::sqrt(4 * M_PI / P1.rows()));
    Print("sphere, each sample x3", a);
    EXPECT_LT(a.max_abs, 0.05);
    EXPECT_EQ(a.wrong_sign, 0);
    EXPECT_TRUE(AllFiniteOnGrid(f, P));
}

TEST(PuRbf, PileOfIdenticalSamplesDoesNotBlowUp)
{
    Points P1, N1;
    test::SpherePoints(1000, 1.0, P1, N1);
    Points P(P1.rows() + 2000, 3), N(P1.rows() + 2000, 3);
    P.topRows(P1.rows()) = P1;
    N.topRows(P1.rows()) = N1;
    for (Eigen::Index i = P1.rows(); i < P.rows(); ++i) {  // 2000 copies of the north pole
        P.row(i) << 0, 0, 1;
        N.row(i) << 0, 0, 1;
    }
    const PuRbf f(P, N);
    EXPECT_TRUE(AllFiniteOnGrid(f, P));
    Points q(2, 3);
    q << 0, 0, 0.9, 0, 0, 1.1;
    Eigen::VectorXd v(2);
    f.Eval(q, v);
    EXPECT_LT(v[0], 0);
    EXPECT_GT(v[1], 0);
}

TEST(PuRbf, TwoFarApartClusters)
{
    Points A, NA;
    test::SpherePoints(1500, 1.0, A, NA);
    Points P(2 * A.rows(), 3), N(2 * A.rows(), 3);
    P << A.rowwise() - Eigen::RowVector3d(50, 0, 0), A.rowwise() + Eigen::RowVector3d(50, 0, 0);
    N << NA, NA;
    const PuRbf f(P, N);
    Points q(5, 3);
    q << -50, 0, 0,  50, 0, 0,  0, 0, 0,  -50, 0, 1.2,  50, 0, -0.8;
    Eigen::VectorXd v(5);
    f.Eval(q, v);
    EXPECT_LT(v[0], 0);  // the centres
    EXPECT_LT(v[1], 0);
    EXPECT_GT(v[2], 0);  // half-way: the far field, outside
    EXPECT_NEAR(v[3], 0.2, 0.04);  // ~2 spacings off the surface
    EXPECT_NEAR(v[4], -0.2, 0.04);
    EXPECT_TRUE(AllFiniteOnGrid(f, P));
}

TEST(PuRbf, FewerSamplesThanTheMinimum)
{
    Points P, N;
    test::SpherePoints(20, 1.0, P, N);
    const PuRbf f(P, N);
    EXPECT_EQ(f.Cells(), 1);
    Points q(3, 3);
    q << 0, 0, 0,  0, 0, 2,  3, 3, 3;
    Eigen::VectorXd v(3);
    f.Eval(q, v);
    EXPECT_LT(v[0], 0);
    EXPECT_GT(v[1], 0);
    EXPECT_GT(v[2], 0);
    EXPECT_TRUE(AllFiniteOnGrid(f, P));

    // Down to two samples: still a defined function.
    const PuRbf two(P.topRows(2), N.topRows(2));
    EXPECT_TRUE(AllFiniteOnGrid(two, P.topRows(2)));
}

// Over a shared k-d tree (the reconstruction's) the function is the one over its own copy of
// the samples, bit for bit; mismatched normals are refused the same way.
TEST(PuRbf, SharedSamplesGiveTheSameFunction)
{
    Points P, N;
    TorusPoints(40, 1.0, 0.35, P, N);
    const SampleIndex samples(P);
    const PuRbf own(P, N, PuRbf::Param()), shared(samples, N, PuRbf::Param());
    const Points G = GridAround(P, 32);
    Eigen::VectorXd a(G.rows()), b(G.rows());
    own.Eval(G, a);
    shared.Eval(G, b);
    EXPECT_EQ(own.Cells(), shared.Cells());
    EXPECT_EQ(std::memcmp(a.data(), b.data(), sizeof(double) * size_t(a.size())), 0);
    EXPECT_THROW(PuRbf(samples, N.topRows(10), PuRbf::Param()), std::invalid_argument);
}

TEST(PuRbf, RejectsImpossibleInput)
{
    Points P, N;
    test::SpherePoints(100, 1.0, P, N);
    EXPECT_THROW(PuRbf(Points(0, 3), Points(0, 3)), std::invalid_argument);
    EXPECT_THROW(PuRbf(P, N.topRows(50)), std::invalid_argument);
    Points same = Points::Ones(30, 3);
    EXPECT_THROW(PuRbf(same, N.topRows(30)), std::invalid_argument);
    PuRbf::Param bad;
    bad.overlap = 0.5;
    EXPECT_THROW(PuRbf(P, N, bad), std::invalid_argument);
    P(3, 1) = std::nan("");
    EXPECT_THROW(PuRbf(P, N), std::invalid_argument);
}

namespace {
std::vector<int> progress;
bool Record(const int pos, const char*)
{
    progress.push_back(pos);
    return true;
}
} // namespace

TEST(PuRbf, ProgressIsMonotoneFromZeroToHundred)
{
    Points P, N;
    test::SpherePoints(20000, 1.0, P, N);
    progress.clear();
    PuRbf::Param p;
    p.threads = 2;
    const PuRbf f(P, N, p, &Record);
    ASSERT_GE(progress.size(), 5u);
    EXPECT_EQ(progress.front(), 0);
    EXPECT_EQ(progress.back(), 100);
    EXPECT_TRUE(std::is_sorted(progress.begin(), progress.end()));
}

TEST(PuRbf, TwoOverlappingSheetsWithTheirOwnSpacingGiveOneZeroCrossing)
{
    // Two scans of the plane z = 0, each a jittered grid of spacing h, the second 0.6 h higher
    // (a registration error). Merged, the samples are twice as dense: off-surface points one
    // merged spacing out land next to the other sheet. With each scan's own spacing they clear
    // it, and every vertical line crosses zero once, between the sheets.
    const double h = 0.05, lift = 0.6 * h;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> jitter(-0.2 * h, 0.2 * h);
    std::vector<Eigen::Vector3d> ps;
    for (int sheet = 0; sheet < 2; ++sheet)
        for (int i = 0; i < 40; ++i)
            for (int j = 0; j < 40; ++j)
                ps.emplace_back((i + 0.5 * sheet) * h + jitter(rng), (j + 0.5 * sheet) * h + jitter(rng), sheet * lift);
    Points P(Eigen::Index(ps.size()), 3);
    for (size_t i = 0; i < ps.size(); ++i)
        P.row(Eigen::Index(i)) = ps[i];
    const Points N = Points::Zero(P.rows(), 3).rowwise() + Eigen::RowVector3d(0, 0, 1);
    PuRbf::Param own;
    own.spacing = Eigen::VectorXd::Constant(P.rows(), h);
    const PuRbf f(P, N, own);
    EXPECT_DOUBLE_EQ(f.Statistics().median_spacing, h);
    int lines = 0, single = 0;
    for (double x = 0.5; x < 1.5; x += 0.1)
        for (double y = 0.5; y < 1.5; y += 0.1, ++lines) {
            Points Q(81, 3);
            for (int k = 0; k < 81; ++k)
                Q.row(k) << x, y, -2 * h + 4 * h * k / 80.0;
            Eigen::VectorXd v(81);
            f.Eval(Q, v);
            int crossings = 0;
            for (int k = 1; k < 81; ++k)
                crossings += (v[k - 1] < 0) != (v[k] < 0);
            single += crossings == 1 && v[0] < 0 && v[80] > 0;
        }
    EXPECT_EQ(single, lines);
    PuRbf::Param wrong;
    wrong.spacing = Eigen::VectorXd::Constant(10, h);
    EXPECT_THROW(PuRbf(P, N, wrong), std::invalid_argument);
}
