#include "geometry.h"
#include "open_sides.h"
#include "spacing.h"

#include <gtest/gtest.h>

using namespace ib;

namespace {
Points Rows(const std::vector<Eigen::Vector3d>& v)
{
    Points M(Eigen::Index(v.size()), 3);
    for (size_t i = 0; i < v.size(); ++i)
        M.row(Eigen::Index(i)) = v[i].transpose();
    return M;
}

/// An open tube along z over [0, length], `ring` samples around each ring `step` apart along
/// z (the stub of a countersunk hole: rings closer along than apart), normals into the tube,
/// leaning `lean` radians towards +z (as PCA planes lean at its end).
void Tube(double radius, int ring, double step, double length, double lean, Points& P, Points& N)
{
    std::vector<Eigen::Vector3d> ps, ns;
    for (int k = 0; k * step <= length + 1e-9; ++k)
        for (int i = 0; i < ring; ++i) {
            const double a = 2 * M_PI * i / ring;
            const Eigen::Vector3d radial(std::cos(a), std::sin(a), 0);
            ps.push_back(radius * radial + Eigen::Vector3d(0, 0, k * step));
            ns.push_back(-std::cos(lean) * radial + std::sin(lean) * Eigen::Vector3d::UnitZ());
        }
    P = Rows(ps);
    N = Rows(ns);
}

/// A closed plate: the flattened ellipsoid x² + y² + (z / c)² = 1 sampled on both sides over a
/// square grid of spacing s in x and y, outward normals.
void Plate(double c, double s, Points& P, Points& N)
{
    std::vector<Eigen::Vector3d> ps, ns;
    for (double x = -1; x <= 1; x += s)
        for (double y = -1; y <= 1; y += s) {
            const double r2 = x * x + y * y;
            if (r2 >= 1 - 1e-9)
                continue;
            for (int side : {-1, 1}) {
                const Eigen::Vector3d p(x, y, side * c * std::sqrt(1 - r2));
                ps.push_back(p);
                ns.push_back(Eigen::Vector3d(x, y, p.z() / (c * c)).normalized());
            }
        }
    P = Rows(ps);
    N = Rows(ns);
}
} // namespace

TEST(OpenSides, AFlatScanOpensAtItsEdgesOutwards)
{
    Points P, N;
    test::FlatScan(0.02, P, N);
    const SampleIndex samples(P);
    const Points open = OpenSides::Compute(samples, N, 1.25 * SampleSpacing::Local(samples, 1, 0, &N));
    int interiorOpen = 0, edgeOpen = 0, edges = 0;
    for (Eigen::Index i = 0; i < P.rows(); ++i) {
        const double x = P(i, 0), y = P(i, 1);
        const bool onEdge = x < 1e-9 || y < 1e-9 || x > 1 - 1e-9 || y > 1 - 1e-9;
        const bool isOpen = open.row(i).squaredNorm() > 0;
        if (!onEdge) {
            // More than two spacings in: its neighbours surround it.
            if (std::min({x, y, 1 - x, 1 - y}) > 0.04)
                interiorOpen += isOpen;
            continue;
        }
        ++edges;
        edgeOpen += isOpen;
        if (isOpen && x > 0.1 && x < 0.9 && y < 1e-9) {  // the bottom edge, away from the corners
            EXPECT_LT(open(i, 1), -0.9) << "at x = " << x;
        }
        if (isOpen) {
            EXPECT_NEAR(open.row(i).norm(), 1.0, 1e-9);
        }
    }
    EXPECT_EQ(interiorOpen, 0);
    EXPECT_EQ(edgeOpen, edges);
}

TEST(OpenSides, AThinTubeOpensAtItsEndsEvenWithLeaningNormals)
{
    // Two spacings across (the rings 0.2 apart around, 0.85 along, radius 0.57): the other
    // wall faces away 1.14 from the end's samples, within their neighbourhood.
    for (double lean : {0.0, 0.5}) {
        Points P, N;
        Tube(0.57, 16, 0.85, 3 * 0.85, lean, P, N);
        const SampleIndex samples(P);
        const Points open = OpenSides::Compute(samples, N, 1.25 * SampleSpacing::Local(samples, 1, 0, &N));
        for (Eigen::Index i = 0; i < P.rows(); ++i) {
            const bool end = P(i, 2) < 1e-9;
            if (end) {
                EXPECT_GT(open.row(i).squaredNorm(), 0) << "lean " << lean << ", sample " << i;
                EXPECT_LT(open(i, 2), -0.8) << "lean " << lean;
            } else if (P(i, 2) > 0.5 && P(i, 2) < 2) {
                EXPECT_EQ(open.row(i).squaredNorm(), 0) << "lean " << lean << ", inner ring sample " << i;
            }
        }
    }
}

TEST(OpenSides, AClosedPlateDoesNotOpenAtItsRim)
{
    // Two sides 1.5 spacings apart in the middle, meeting at a sharp rim: past the rim the
    // other side goes on, nearly in the sheet's plane.
    Points P, N;
    Plate(0.015, 0.02, P, N);
    const SampleIndex samples(P);
    const Points open = OpenSides::Compute(samples, N, 1.25 * SampleSpacing::Local(samples, 1, 0, &N));
    int opened = 0;
    for (Eigen::Index i = 0; i < P.rows(); ++i)
        opened += open.row(i).squaredNorm() > 0;
    EXPECT_EQ(opened, 0);
}

TEST(OpenSides, ARoundedRimDoesNotOpen)
{
    // A fin 3 spacings thick: two sheets z = ±R for x <= 0 joined by a half cylinder of
    // radius R around the y axis, sampled s apart along the surface. The sheets' last samples
    // see the rim's samples turning into their gap.
    const double s = 0.02, R = 1.5 * s;
    std::vector<Eigen::Vector3d> ps, ns;
    for (double y = 0; y <= 1 + 1e-9; y += s) {
        for (int side : {-1, 1})
            for (double x = -1; x <= 1e-9; x += s) {
                ps.emplace_back(x, y, side * R);
                ns.emplace_back(0, 0, side);
            }
        const int arc = int(std::round(M_PI * R / s));
        for (int k = 1; k < arc; ++k) {
            const double a = M_PI / 2 - M_PI * k / arc;
            ps.emplace_back(R * std::cos(a), y, R * std::sin(a));
            ns.emplace_back(std::cos(a), 0, std::sin(a));
        }
    }
    const Points P = Rows(ps), N = Rows(ns);
    const SampleIndex samples(P);
    const Points open = OpenSides::Compute(samples, N, 1.25 * SampleSpacing::Local(samples, 1, 0, &N));
    for (Eigen::Index i = 0; i < P.rows(); ++i)
        if (P(i, 0) > -0.9 && P(i, 1) > 0.1 && P(i, 1) < 0.9) {
            EXPECT_EQ(open.row(i).squaredNorm(), 0) << "sample at " << P.row(i);
        }
}
