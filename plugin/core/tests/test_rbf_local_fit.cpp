#include "implicit/rbf_local_fit.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <vector>

using namespace ib;

namespace {

/// The samples of one support box: positions, unit normals, off-surface distances.
struct Patch
{
    Points P, N;
    RbfLocalFit::Offsets E;
    std::vector<int> ids;          ///< the samples inside the box
    Eigen::Vector3d centre;
    double half = 0, spacing = 0;
};

/// The samples of P (with normals N) in the box around centre, each with off-surface points
/// one spacing to both sides.
Patch InBox(const Points& P, const Points& N, const Eigen::Vector3d& centre, double half, double spacing)
{
    Patch p;
    p.P = P;
    p.N = N;
    p.centre = centre;
    p.half = half;
    p.spacing = spacing;
    p.E.resize(P.rows(), 2);
    p.E.col(0).setConstant(spacing);
    p.E.col(1).setConstant(-spacing);
    for (Eigen::Index i = 0; i < P.rows(); ++i)
        if (((P.row(i).transpose() - centre).array().abs() <= half).all())
            p.ids.push_back(int(i));
    return p;
}

/// Fit to all the samples in the box, with the centres ChooseCentres picks.
RbfLocalFit FitAll(const Patch& p, const RbfLocalFit::Param& param = {})
{
    std::vector<int> chosen;
    std::vector<double> far;
    RbfLocalFit::ChooseCentres(p.P, p.centre, p.ids, param, chosen, far);
    const size_t centres = RbfLocalFit::CentreCount(chosen, p.E);
    RbfLocalFit::Workspace work(Eigen::Index(p.ids.size() + centres - chosen.size()), Eigen::Index(centres + 4));
    return RbfLocalFit(p.centre, p.half, p.P, p.N, p.E, p.ids, chosen, param, work);
}

/// A grid of m×m samples spacing h apart on the plane through o with unit normal n.
void PlanePoints(const Eigen::Vector3d& o, const Eigen::Vector3d& n, int m, double h, Points& P, Points& N)
{
    const Eigen::Vector3d t = n.unitOrthogonal(), b = n.cross(t);
    P.resize(m * m, 3);
    N.resize(m * m, 3);
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) {
            P.row(i * m + j) = (o + h * (i - 0.5 * (m - 1)) * t + h * (j - 0.5 * (m - 1)) * b).transpose();
            N.row(i * m + j) = n.transpose();
        }
}

/// n samples on the unit sphere (Fibonacci spiral), with outward normals.
void SpherePoints(int n, Points& P, Points& N)
{
    const double golden = M_PI * (3 - std::sqrt(5.0));
    P.resize(n, 3);
    for (int i = 0; i < n; ++i) {
        const double z = 1 - 2 * (i + 0.5) / n, r = std::sqrt(1 - z * z);
        P.row(i) << r * std::cos(golden * i), r * std::sin(golden * i), z;
    }
    N = P;
}

/// Largest |f(x) - distance(x)| over the patch's samples in the inner `inner` fraction of the
/// box (where the blend weighs a fit), moved by `offset` along their normals.
double WorstAlongNormals(const RbfLocalFit& f, const Patch& p, double offset,
                         const std::function<double(const Eigen::Vector3d&)>& distance, double inner = 1)
{
    double worst = 0;
    for (int s : p.ids) {
        if (((p.P.row(s).transpose() - p.centre).array().abs() > inner * p.half).any())
            continue;
        const Eigen::Vector3d x = (p.P.row(s) + offset * p.N.row(s)).transpose();
        worst = std::max(worst, std::abs(f.Eval(x) - distance(x)));
    }
    return worst;
}

} // namespace

TEST(RbfLocalFit, ChooseCentresSpreadsAThirdOfTheCentresOverTheSamples)
{
    Points P, N;
    PlanePoints(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 20, 0.05, P, N);
    const Patch p = InBox(P, N, Eigen::Vector3d(0.1, 0.05, 0), 1.0, 0.05);
    ASSERT_EQ(p.ids.size(), 400u);
    RbfLocalFit::Param param;  // 80 centres: 27 samples and their off-surface points
    std::vector<int> chosen;
    std::vector<double> far;
    RbfLocalFit::ChooseCentres(P, p.centre, p.ids, param, chosen, far);
    ASSERT_EQ(chosen.size(), 27u);
    EXPECT_TRUE(std::is_sorted(chosen.begin(), chosen.end()));
    EXPECT_EQ(std::adjacent_find(chosen.begin(), chosen.end()), chosen.end());
    EXPECT_EQ(RbfLocalFit::CentreCount(chosen, p.E), 81u);
    // The first is the sample nearest the centre.
    int nearest = 0;
    for (int s = 1; s < P.rows(); ++s)
        if ((P.row(s).transpose() - p.centre).norm() < (P.row(nearest).transpose() - p.centre).norm())
            nearest = s;
    EXPECT_TRUE(std::binary_search(chosen.begin(), chosen.end(), nearest));
    // Farthest-point sampling: no two chosen samples are closer than the farthest any sample
    // is from the chosen ones, and that is about the spread of 27 points over the square.
    double cover = 0, closest = std::numeric_limits<double>::infinity();
    for (int s : p.ids) {
        double d = std::numeric_limits<double>::infinity();
        for (int c : chosen)
            d = std::min(d, (P.row(s) - P.row(c)).norm());
        cover = std::max(cover, d);
    }
    for (size_t a = 0; a < chosen.size(); ++a)
        for (size_t b = a + 1; b < chosen.size(); ++b)
            closest = std::min(closest, (P.row(chosen[a]) - P.row(chosen[b])).norm());
    EXPECT_GE(closest, cover);
    EXPECT_LT(cover, 0.95 / std::sqrt(27.0) * 1.5);

    // Fewer samples than centres: all of them, ascending.
    const std::vector<int> few = {9, 3, 7};
    RbfLocalFit::ChooseCentres(P, p.centre, few, param, chosen, far);
    EXPECT_EQ(chosen, (std::vector<int>{3, 7, 9}));
}

TEST(RbfLocalFit, PlaneIsItsSignedDistanceInTheWholeBox)
{
    const Eigen::Vector3d o(0.2, -0.1, 0.3), n = Eigen::Vector3d(1, 2, 3).normalized();
    Points P, N;
    PlanePoints(o, n, 24, 0.04, P, N);
    const Patch p = InBox(P, N, o + Eigen::Vector3d(0.03, -0.02, 0.01), 0.4, 0.04);
    ASSERT_GT(p.ids.size(), 200u);
    const RbfLocalFit f = FitAll(p);
    EXPECT_FALSE(f.FellBack());
    auto distance = [&](const Eigen::Vector3d& x) { return (x - o).dot(n); };
    EXPECT_LT(WorstAlongNormals(f, p, 0, distance), 1e-6 * p.spacing);
    // The linear part reproduces the plane: the signed distance anywhere in the box, corners too.
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> in(-1, 1);
    double worst = 0;
    for (int trial = 0; trial < 1000; ++trial) {
        const Eigen::Vector3d x = p.centre + p.half * Eigen::Vector3d(in(rng), in(rng), in(rng));
        worst = std::max(worst, std::abs(f.Eval(x) - distance(x)));
    }
    std::printf("[ RBF fit  ] plane: max |f - signed distance| in the box %.2e spacings\n", worst / p.spacing);
    EXPECT_LT(worst, 1e-6 * p.spacing);  // measured 1.9e-7; 7.5e-6 without the moment conditions
}

TEST(RbfLocalFit, SphereIsItsSignedDistanceNearItsSamples)
{
    Points P, N;
    SpherePoints(20000, P, N);
    const double spacing = std::sqrt(4 * M_PI / 20000);
    const Patch p = InBox(P, N, Eigen::Vector3d(0.05, -0.03, 0.99), 0.3, spacing);
    ASSERT_GT(p.ids.size(), 300u);
    const RbfLocalFit f = FitAll(p);
    EXPECT_FALSE(f.FellBack());
    auto distance = [](const Eigen::Vector3d& x) { return x.norm() - 1; };
    // Least squares through ~450 samples with 27 centres: a residual of about a hundredth of
    // a spacing, the least in the inner half of the box, where the blend weighs the fit most.
    for (double inner : {1.0, 0.5}) {
        const double at_samples = WorstAlongNormals(f, p, 0, distance, inner) / spacing;
        const double half_spacing = std::max(WorstAlongNormals(f, p, 0.5 * spacing, distance, inner),
                                             WorstAlongNormals(f, p, -0.5 * spacing, distance, inner)) / spacing;
        std::printf("[ RBF fit  ] sphere cap, samples within %.1f of the box: max |f| at them %.4f, |f - signed "
                    "distance| at 0.5 spacing %.4f spacings\n", inner, at_samples, half_spacing);
        EXPECT_LT(at_samples, inner < 1 ? 0.02 : 0.05);  // measured 0.0086 inner, 0.026 all
        EXPECT_LT(half_spacing, inner < 1 ? 0.02 : 0.05);  // 0.0072, 0.028
    }
    // Outside along the normals, inside against them.
    for (int s : p.ids)
        for (double offset : {-2.0, 2.0}) {
            const Eigen::Vector3d x = (p.P.row(s) + offset * spacing * p.N.row(s)).transpose();
            EXPECT_EQ(f.Eval(x) > 0, offset > 0);
        }
}

TEST(RbfLocalFit, FarCornersOfTheBoxKeepTheSignOfTheirSide)
{
    // The moment conditions keep the r^3 terms from growing off the data. On noisy samples in a
    // small box, without them the corners were 1.5 h off the signed distance, with the wrong
    // sign; with them 0.15 h: the four upper corners outside the sphere, the four lower inside.
    Points P, N;
    SpherePoints(20000, P, N);
    const double spacing = std::sqrt(4 * M_PI / 20000);
    std::mt19937 rng(2);
    std::normal_distribution<double> noise(0, 0.3 * spacing);
    for (Eigen::Index i = 0; i < P.rows(); ++i)
        for (int a = 0; a < 3; ++a)
            P(i, a) += noise(rng);
    const Patch p = InBox(P, N, Eigen::Vector3d(0.05, 0.02, 0.98), 0.15, spacing);
    ASSERT_GT(p.ids.size(), 100u);
    const RbfLocalFit f = FitAll(p);
    for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3d x = p.centre + p.half * Eigen::Vector3d(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1, corner & 4 ? 1 : -1);
        EXPECT_EQ(f.Eval(x) > 0, x.norm() > 1) << "corner " << corner;
        EXPECT_NEAR(f.Eval(x), x.norm() - 1, 0.3 * p.half) << "corner " << corner;
    }
}

TEST(RbfLocalFit, DuplicateAndCollinearSamplesGiveAFiniteFunction)
{
    // Each sample of a plane three times (identical columns in the system), and a single row of
    // samples (a polynomial undetermined across it): the ridge keeps both solvable.
    Points P1, N1;
    PlanePoints(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 12, 0.05, P1, N1);
    Points P(3 * P1.rows(), 3), N(3 * P1.rows(), 3);
    P << P1, P1, P1;
    N << N1, N1, N1;
    Points L(30, 3), LN(30, 3);
    for (int i = 0; i < 30; ++i) {
        L.row(i) << 0.02 * (i - 15), 0, 0;
        LN.row(i) << 0, 0, 1;
    }
    for (const Patch& p : {InBox(P, N, Eigen::Vector3d::Zero(), 0.4, 0.05), InBox(L, LN, Eigen::Vector3d::Zero(), 0.4, 0.02)}) {
        const RbfLocalFit f = FitAll(p);
        EXPECT_FALSE(f.FellBack());
        for (int s : p.ids)
            for (double offset : {-1.0, 0.0, 1.0}) {
                const Eigen::Vector3d x = (p.P.row(s) + offset * p.spacing * p.N.row(s)).transpose();
                const double v = f.Eval(x);
                ASSERT_TRUE(std::isfinite(v));
                EXPECT_NEAR(v, offset * p.spacing, 1e-3 * p.spacing);
            }
    }
}
