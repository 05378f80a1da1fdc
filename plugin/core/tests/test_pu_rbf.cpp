#include "gated_mc.h"
#include "geometry.h"
#include "implicit/hoppe.h"
#include "implicit/pu_rbf.h"
#include "normals.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <functional>
#include <random>

using namespace ib;

namespace {

/// Torus around the z axis (tube centre radius R, tube radius r): samples about uniform in
/// area (rings around the tube get points in proportion to their length), outward normals.
void TorusPoints(int rings, double R, double r, Points& P, Points& N)
{
    std::vector<Eigen::Vector3d> ps, ns;
    const int around = int(std::lround(rings * R / r));  // points on the ring of radius R
    for (int j = 0; j < rings; ++j) {
        const double v = 2 * M_PI * (j + 0.5) / rings;
        const int count = std::max(3, int(std::lround(around * (R + r * std::cos(v)) / R)));
        for (int i = 0; i < count; ++i) {
            const double u = 2 * M_PI * (i + 0.37 * j) / count;
            const Eigen::Vector3d n(std::cos(v) * std::cos(u), std::cos(v) * std::sin(u), std::sin(v));
            ps.push_back(Eigen::Vector3d(R * std::cos(u), R * std::sin(u), 0) + r * n);
            ns.push_back(n);
        }
    }
    P.resize(Eigen::Index(ps.size()), 3);
    N.resize(Eigen::Index(ps.size()), 3);
    for (size_t i = 0; i < ps.size(); ++i) {
        P.row(Eigen::Index(i)) = ps[i].transpose();
        N.row(Eigen::Index(i)) = ns[i].transpose();
    }
}

/// A known surface: exact signed distance, and its closest point and normal.
struct Shape
{
    std::function<double(const Eigen::Vector3d&)> distance;
    std::function<Eigen::Vector3d(const Eigen::Vector3d&)> normal;  // of the closest surface point
};

Shape Sphere(double radius)
{
    return {[=](const Eigen::Vector3d& x) { return x.norm() - radius; },
            [](const Eigen::Vector3d& x) { return x.normalized(); }};
}

Shape Torus(double R, double r)
{
    auto axis = [=](const Eigen::Vector3d& x) {  // closest point on the tube's centre circle
        const Eigen::Vector2d d = x.head<2>().normalized();
        return Eigen::Vector3d(R * d[0], R * d[1], 0);
    };
    return {[=](const Eigen::Vector3d& x) { return (x - axis(x)).norm() - r; },
            [=](const Eigen::Vector3d& x) { return (x - axis(x)).normalized(); }};
}

/// Gaussian noise on the positions with RMS displacement `rms` (deterministic).
void AddNoise(Points& P, double rms, unsigned seed = 7)
{
    std::mt19937 rng(seed);
    std::normal_distribution<double> g(0, rms / std::sqrt(3.0));
    for (Eigen::Index i = 0; i < P.rows(); ++i)
        for (int a = 0; a < 3; ++a)
            P(i, a) += g(rng);
}

double Diagonal(const Points& P) { return (P.colwise().maxCoeff() - P.colwise().minCoeff()).norm(); }

/// Points on the true surface that are not the samples: the samples of a denser set moved by
/// the shape's own projection.
Points OnSurface(const Points& Q, const Shape& s)
{
    Points S = Q;
    for (Eigen::Index i = 0; i < S.rows(); ++i) {
        const Eigen::Vector3d x = S.row(i).transpose();
        S.row(i) = (x - s.distance(x) * s.normal(x)).transpose();
    }
    return S;
}

struct Accuracy
{
    double max_abs = 0, mean_abs = 0;        ///< |f| on the true surface, in spacings
    double max_sd_error = 0;                 ///< |f - signed distance| at +-0.5 spacing, in spacings
    int wrong_sign = 0;                      ///< at +-3 spacings
};

/// Evaluates f on the true surface (at Q projected) and offset along the true normals.
Accuracy Measure(const ImplicitFunction& f, const Points& Q, const Shape& s, double spacing)
{
    const Points S = OnSurface(Q, s);
    Points Nt(S.rows(), 3);
    for (Eigen::Index i = 0; i < S.rows(); ++i)
        Nt.row(i) = s.normal(S.row(i).transpose()).transpose();
    Accuracy a;
    Eigen::VectorXd v(S.rows());
    f.Eval(S, v);
    a.max_abs = v.cwiseAbs().maxCoeff() / spacing;
    a.mean_abs = v.cwiseAbs().mean() / spacing;
    for (double offset : {-3.0, 3.0}) {
        f.Eval(Points(S + offset * spacing * Nt), v);
        for (Eigen::Index i = 0; i < v.size(); ++i)
            a.wrong_sign += (v[i] > 0) != (offset > 0);
    }
    for (double offset : {-0.5, 0.5}) {
        f.Eval(Points(S + offset * spacing * Nt), v);
        a.max_sd_error = std::max(a.max_sd_error, (v.array() - offset * spacing).abs().maxCoeff() / spacing);
    }
    return a;
}

/// A regular grid of m^3 points covering the samples' bounding box scaled by 2 about its centre.
Points GridAround(const Points& P, int m)
{
    const Eigen::Vector3d lo = P.colwise().minCoeff(), hi = P.colwise().maxCoeff();
    const Eigen::Vector3d c = 0.5 * (lo + hi), ext = (hi - lo).cwiseMax(1e-3 * (hi - lo).maxCoeff());
    Points G(Eigen::Index(m) * m * m, 3);
    Eigen::Index k = 0;
    for (int z = 0; z < m; ++z)
        for (int y = 0; y < m; ++y)
            for (int x = 0; x < m; ++x)
                G.row(k++) = (c + ext.cwiseProduct(Eigen::Vector3d(x, y, z) / (m - 1) * 2 - Eigen::Vector3d::Ones()))
                                 .transpose();
    return G;
}

bool AllFiniteOnGrid(const ImplicitFunction& f, const Points& P)
{
    const Points G = GridAround(P, 40);
    Eigen::VectorXd v(G.rows());
    f.Eval(G, v);
    return v.allFinite();
}

void Print(const char* what, const Accuracy& a)
{
    std::printf("[ PU-RBF   ] %-28s |f| on surface: max %.4f mean %.5f spacings; |f - sd| at 0.5 spacing: max %.4f; wrong signs at 3 spacings: %d\n",
                what, a.max_abs, a.mean_abs, a.max_sd_error, a.wrong_sign);
}

/// The accuracy tests' known surfaces: samples P with exact normals N, other points Q of the
/// same surface to measure at, and the sample spacing.
struct Analytic
{
    Points P, N, Q;
    Shape shape;
    double spacing = 0;
};

/// 8000 samples of the unit sphere.
Analytic SphereCase()
{
    Analytic c;
    Points unused;
    test::SpherePoints(8000, 1.0, c.P, c.N);
    test::SpherePoints(5001, 1.0, c.Q, unused);
    c.shape = Sphere(1.0);
    c.spacing = std::sqrt(4 * M_PI / c.P.rows());
    return c;
}

/// 23,130 samples of the torus R = 1, r = 0.35.
Analytic TorusCase()
{
    Analytic c;
    Points unused;
    TorusPoints(90, 1.0, 0.35, c.P, c.N);
    TorusPoints(61, 1.0, 0.35, c.Q, unused);
    c.shape = Torus(1.0, 0.35);
    c.spacing = std::sqrt(4 * M_PI * M_PI * 1.0 * 0.35 / c.P.rows());
    return c;
}

/// The PU-RBF fitted to c's samples with normals N (c.N or estimated ones), measured and
/// printed; what every case must give: no wrong sign 3 spacings off, finite everywhere.
Accuracy FitAndMeasure(const Analytic& c, const Points& N, const char* what)
{
    const PuRbf f(c.P, N);
    const Accuracy a = Measure(f, c.Q, c.shape, c.spacing);
    Print(what, a);
    EXPECT_EQ(a.wrong_sign, 0);
    EXPECT_TRUE(AllFiniteOnGrid(f, c.P));
    EXPECT_EQ(f.Statistics().solver_fallbacks, 0);
    return a;
}

/// The normals the filter estimates for a layer without them (PCA over k neighbours, 15 by
/// default, oriented by propagation, then the neighbour vote).
Points Estimated(const Points& P, PointNormals::Report* report = nullptr, int k = PointNormals::Param{}.neighbours)
{
    PointNormals::Param p;
    p.neighbours = k;
    return PointNormals::Compute(SampleIndex(P), p, report);
}

/// Cosines between estimated normals E and exact ones N, row by row.
Eigen::ArrayXd Cosines(const Points& E, const Points& N) { return (E.array() * N.array()).rowwise().sum(); }

} // namespace

// Estimated normals on clean samples tilt by less than a degree (the curvature over 15
// neighbours): the fit must be as close as with exact ones.
TEST(PuRbf, SphereWithExactAndEstimatedNormals)
{
    const Analytic c = SphereCase();
    const Points E = Estimated(c.P);
    EXPECT_GT(Cosines(E, c.N).minCoeff(), 0.99);
    for (const auto& [N, what] : {std::pair(c.N, "sphere, exact normals"), std::pair(E, "sphere, estimated normals")}) {
        const Accuracy a = FitAndMeasure(c, N, what);
        EXPECT_LT(a.max_abs, 0.02);
        EXPECT_LT(a.mean_abs, 0.01);
        EXPECT_LT(a.max_sd_error, 0.05);
    }
}

TEST(PuRbf, TorusWithExactAndEstimatedNormals)
{
    const Analytic c = TorusCase();
    const Points E = Estimated(c.P);
    EXPECT_GT(Cosines(E, c.N).minCoeff(), 0.99);
    for (const auto& [N, what] : {std::pair(c.N, "torus, exact normals"), std::pair(E, "torus, estimated normals")}) {
        const Accuracy a = FitAndMeasure(c, N, what);
        EXPECT_LT(a.max_abs, 0.05);
        EXPECT_LT(a.mean_abs, 0.01);
        EXPECT_LT(a.max_sd_error, 0.1);
    }
}

// 0.5%-diagonal noise is 0.44 (sphere) to 0.8 (torus) spacings RMS: on average the fit must be
// well below it, and nowhere above it by much.
TEST(PuRbf, SphereWithNoise)
{
    Analytic c = SphereCase();
    AddNoise(c.P, 0.005 * Diagonal(c.P));
    const Accuracy a = FitAndMeasure(c, c.N, "sphere, 0.5% diagonal noise");
    EXPECT_LT(a.mean_abs, 0.1);
    EXPECT_LT(a.max_abs, 0.75);
}

TEST(PuRbf, TorusWithNoise)
{
    Analytic c = TorusCase();
    AddNoise(c.P, 0.005 * Diagonal(c.P));
    const Accuracy a = FitAndMeasure(c, c.N, "torus, 0.5% diagonal noise");
    EXPECT_LT(a.mean_abs, 0.1);
    EXPECT_LT(a.max_abs, 0.75);
}

// The scanner's case: noisy samples and no normals.
TEST(PuRbf, SphereWithNoiseAndEstimatedNormals)
{
    Analytic c = SphereCase();
    AddNoise(c.P, 0.005 * Diagonal(c.P));
    const Accuracy a = FitAndMeasure(c, Estimated(c.P), "sphere, noise, estimated");
    EXPECT_LT(a.mean_abs, 0.1);
    EXPECT_LT(a.max_abs, 0.75);
}

TEST(PuRbf, TorusWithNoiseAndEstimatedNormals)
{
    Analytic c = TorusCase();
    AddNoise(c.P, 0.005 * Diagonal(c.P));
    // With 10 neighbours (MeshLab's usual count, our default before) and noise of 0.6
    // spacings, PCA tilts a few normals past 90 degrees and propagation passes a wrong
    // orientation on now and then; the neighbour vote turns the isolated ones. What is left
    // (13 of the 23,130 normals facing away from the true ones, 3 by more than 120 degrees)
    // must not bend the fit.
    PointNormals::Report report;
    const Points E = Estimated(c.P, &report, 10);
    EXPECT_GT(report.turned, 0u);
    EXPECT_LT((Cosines(E, c.N) < 0).count(), c.P.rows() / 1000);
    const Accuracy a = FitAndMeasure(c, E, "torus, noise, estimated");
    // The default 15 neighbours average the noise better: every normal within 70 degrees.
    EXPECT_GT(Cosines(Estimated(c.P), c.N).minCoeff(), 0.3);
    EXPECT_LT(a.mean_abs, 0.1);
    EXPECT_LT(a.max_abs, 0.75);
}

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

TEST(PuRbf, SparseRegionNextToADenseOne)
{
    // The upper hemisphere dense, the lower one 16 times sparser: the lower cells hold fewer
    // than min_samples and grow their support boxes.
    Points D, ND;
    test::SpherePoints(16000, 1.0, D, ND);
    std::vector<Eigen::Index> keep;
    for (Eigen::Index i = 0; i < D.rows(); ++i)
        if (D(i, 2) >= 0 || i % 16 == 0)
            keep.push_back(i);
    Points P(Eigen::Index(keep.size()), 3), N(Eigen::Index(keep.size()), 3);
    for (size_t j = 0; j < keep.size(); ++j) {
        P.row(Eigen::Index(j)) = D.row(keep[j]);
        N.row(Eigen::Index(j)) = ND.row(keep[j]);
    }
    const PuRbf f(P, N);
    Points Q, unused;
    test::SpherePoints(3001, 1.0, Q, unused, -2);
    Points lower = Q.topRows(0);
    for (Eigen::Index i = 0; i < Q.rows(); ++i)
        if (Q(i, 2) < -0.1) {
            lower.conservativeResize(lower.rows() + 1, 3);
            lower.row(lower.rows() - 1) = Q.row(i);
        }
    const double sparse = std::sqrt(4 * M_PI / 1000);  // the lower half's spacing
    const Accuracy a = Measure(f, lower, Sphere(1.0), sparse);
    Print("sphere, sparse lower half", a);
    EXPECT_LT(a.max_abs, 0.05);
    EXPECT_EQ(a.wrong_sign, 0);
    EXPECT_TRUE(AllFiniteOnGrid(f, P));
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

TEST(PuRbf, FlatPatchIsTheSignedDistanceToItsPlane)
{
    const int m = 60;
    const double h = 1.0 / (m - 1);
    Points P(m * m, 3), N(m * m, 3);
    for (int y = 0; y < m; ++y)
        for (int x = 0; x < m; ++x) {
            P.row(y * m + x) << x * h, y * h, 0.25;
            N.row(y * m + x) << 0, 0, 1;
        }
    const PuRbf f(P, N);
    // Queries over the inner part of the patch, within 3 spacings of its plane.
    Points Q(21 * 21 * 7, 3);
    Eigen::Index k = 0;
    for (int z = -3; z <= 3; ++z)
        for (int y = 0; y <= 20; ++y)
            for (int x = 0; x <= 20; ++x)
                Q.row(k++) << 0.1 + 0.04 * x + 0.0123, 0.1 + 0.04 * y + 0.0071, 0.25 + z * h;
    Eigen::VectorXd v(Q.rows());
    f.Eval(Q, v);
    const double worst = (v.array() - (Q.col(2).array() - 0.25)).abs().maxCoeff();
    std::printf("[ PU-RBF   ] flat patch: max |f - signed distance| %.2e spacings\n", worst / h);
    EXPECT_LT(worst, 1e-3 * h);
    EXPECT_TRUE(AllFiniteOnGrid(f, P));
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

TEST(PuRbf, MarchingCubesExtractsTheSphere)
{
    Points P, N;
    test::SpherePoints(8000, 1.0, P, N);
    const PuRbf f(P, N);
    const Lattice l = Lattice::Fit(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1), 48, 2);
    CoreMesh m;
    GatedMarchingCubes::Param noHoles;
    noHoles.holes = false;
    GatedMarchingCubes::Compute(l, test::AllCells(l), f, m, noHoles);
    ASSERT_GT(m.fn, 1000);
    double worst = 0, sum = 0;
    for (const auto& v : m.vert) {
        const double d = std::abs(v.cP().Norm() - 1.0);
        worst = std::max(worst, d);
        sum += d;
    }
    std::printf("[ PU-RBF   ] marching cubes on the sphere: vertex distance max %.4f mean %.4f cells\n",
                worst / l.cell_size, sum / m.vn / l.cell_size);
    EXPECT_LT(worst, 0.1 * l.cell_size);  // measured: max 0.014, mean 0.0025 cells
    const auto t = test::Check(m);
    EXPECT_EQ(t.border_edges, 0);
    EXPECT_EQ(t.non_manifold_edges, 0);
    EXPECT_TRUE(t.oriented);
}

TEST(PuRbf, MarchingCubesExtractsTheNoisyTorusWithoutSpuriousSheets)
{
    Points P, N;
    TorusPoints(90, 1.0, 0.35, P, N);
    AddNoise(P, 0.005 * Diagonal(P));
    const PuRbf f(P, N);
    // The whole lattice, far field included: any sheet away from the samples would show.
    const Lattice l = Lattice::Fit(Eigen::Vector3d(-1.35, -1.35, -0.35), Eigen::Vector3d(1.35, 1.35, 0.35), 64, 3);
    CoreMesh m;
    GatedMarchingCubes::Param noHoles;
    noHoles.holes = false;
    GatedMarchingCubes::Compute(l, test::AllCells(l), f, m, noHoles);
    ASSERT_GT(m.fn, 1000);
    const Shape torus = Torus(1.0, 0.35);
    const SampleIndex samples(P);
    SampleIndex::Queue queue;
    double worst = 0, sum = 0, farthest = 0;
    for (const auto& v : m.vert) {
        const Eigen::Vector3d x(v.cP()[0], v.cP()[1], v.cP()[2]);
        const double d = std::abs(torus.distance(x));
        worst = std::max(worst, d);
        sum += d;
        samples.Nearest(x, 1, queue);
        farthest = std::max(farthest, std::sqrt(queue.getWeight(0)));
    }
    std::printf("[ PU-RBF   ] marching cubes on the noisy torus: vertex distance to the torus max %.3f mean %.3f cells, "
                "to the nearest sample max %.3f cells\n",
                worst / l.cell_size, sum / m.vn / l.cell_size, farthest / l.cell_size);
    // Measured: max 0.53, mean 0.070 cells from the torus; at most 0.82 cells from a sample.
    EXPECT_LT(sum / m.vn, 0.15 * l.cell_size);
    EXPECT_LT(worst, 0.75 * l.cell_size);
    EXPECT_LT(farthest, 2 * l.cell_size);
    const auto t = test::Check(m);
    EXPECT_EQ(t.border_edges, 0);
    EXPECT_EQ(t.non_manifold_edges, 0);
    EXPECT_TRUE(t.oriented);
    EXPECT_EQ(m.vn - (3 * m.fn) / 2 + m.fn, 0);  // Euler characteristic of a torus
}

// Not a test of speed (nothing asserted on time): prints fit and evaluation cost next to
// HoppeDistance's, on ~35k samples, for the benchmark notes.
TEST(PuRbf, SpeedReport)
{
    Points P, N;
    TorusPoints(112, 1.0, 0.35, P, N);  // ~36k samples
    AddNoise(P, 0.001);
    using Clock = std::chrono::steady_clock;
    auto seconds = [](Clock::time_point a) { return std::chrono::duration<double>(Clock::now() - a).count(); };
    // Queries: a shell of lattice corners near the surface, as marching cubes would ask.
    Points Q = OnSurface(GridAround(P, 80), Torus(1.0, 0.35));
    Q += 0.02 * Points::Random(Q.rows(), 3);
    Eigen::VectorXd v(Q.rows());
    for (int threads : {1, 2}) {
        PuRbf::Param p;
        p.threads = threads;
        auto t0 = Clock::now();
        const PuRbf f(P, N, p);
        const double fit = seconds(t0);
        t0 = Clock::now();
        f.Eval(Q, v);
        const double eval = seconds(t0);
        EXPECT_TRUE(v.allFinite());

        t0 = Clock::now();
        const SampleIndex index(P);
        const HoppeDistance h(index, N, 8, threads);
        const double hfit = seconds(t0);
        t0 = Clock::now();
        h.Eval(Q, v);
        const double heval = seconds(t0);
        const auto& s = f.Statistics();
        std::printf("[ PU-RBF   ] %ld samples, %d thread(s): PU-RBF fit %.3f s (%d cells, %.0f centres/cell, %zu of %zu "
                    "off-surface points dropped), eval %.3f us/query (wall); Hoppe index %.3f s, eval %.3f us/query (%ld queries)\n",
                    long(P.rows()), threads, fit, s.cells, double(s.centres) / s.cells, s.off_surface_dropped,
                    s.off_surface_points + s.off_surface_dropped, 1e6 * eval / Q.rows(), hfit, 1e6 * heval / Q.rows(),
                    long(Q.rows()));
    }
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
