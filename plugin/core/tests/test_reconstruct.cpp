#include "geometry.h"
#include "reconstruct.h"

#include <gtest/gtest.h>

using namespace ib;

TEST(Reconstruction, ClosedSphereHasNoBoundary)
{
    Points P, N;
    test::SpherePoints(4000, 1.0, P, N);
    CoreMesh m;
    auto r = Reconstruction::Compute(P, N, {}, m);
    EXPECT_TRUE(r.resolution_automatic);
    EXPECT_TRUE(r.loops.empty());
    const auto t = test::Check(m);
    EXPECT_EQ(t.border_edges, 0);
    EXPECT_EQ(t.non_manifold_edges, 0);
    EXPECT_TRUE(t.oriented);
    double worst = 0;
    for (const auto& v : m.vert)
        worst = std::max(worst, std::abs(v.cP().Norm() - 1.0));
    EXPECT_LT(worst, 0.25 * r.cell_size);
    EXPECT_LT(double(r.implicit_evaluations), 0.5 * r.full_lattice_evaluations);
}

TEST(Reconstruction, HemisphereHasExactlyOneBoundaryLoopAtItsRim)
{
    Points P, N;
    test::SpherePoints(6000, 1.0, P, N, 0.0);
    // The scan's last samples lie on its edge: a ring on the equator, a spacing apart.
    const int ring = int(std::ceil(2 * M_PI / std::sqrt(4 * M_PI / 6000)));
    const Eigen::Index n = P.rows();
    P.conservativeResize(n + ring, 3);
    N.conservativeResize(n + ring, 3);
    for (int i = 0; i < ring; ++i) {
        P.row(n + i) << std::cos(2 * M_PI * i / ring), std::sin(2 * M_PI * i / ring), 0;
        N.row(n + i) = P.row(n + i);
    }
    Reconstruction::Param p;
    p.resolution = 40;
    CoreMesh m;
    auto r = Reconstruction::Compute(P, N, p, m);
    ASSERT_EQ(r.loops.size(), 1u);
    // Every boundary vertex within a cell of the rim (the circle z = 0), on average within a
    // third of one: the trim took off the SODS margin past the rim, the fit put the boundary on
    // the last samples.
    double sum = 0;
    for (int v : r.loops[0].vertices) {
        const auto& q = m.vert[size_t(v)].cP();
        const double d = std::hypot(q[2], std::hypot(q[0], q[1]) - 1);
        EXPECT_LT(d, r.cell_size);
        sum += d;
    }
    EXPECT_LT(sum / r.loops[0].Edges(), r.cell_size / 3);
    EXPECT_GT(r.boundary.faces_trimmed, 0u);
    EXPECT_NEAR(r.loops[0].length, 2 * M_PI, 0.15 * 2 * M_PI);  // smoothed: 1.8 times as long unsmoothed
    const auto t = test::Check(m);
    EXPECT_EQ(t.non_manifold_edges, 0);
    EXPECT_TRUE(t.oriented);
}

TEST(Reconstruction, EstimatesNormalsWhenThereAreNone)
{
    Points P, N;
    test::SpherePoints(3000, 1.0, P, N);
    CoreMesh m;
    auto r = Reconstruction::Compute(P, Points(), {}, m);
    EXPECT_TRUE(r.normals_estimated);
    EXPECT_TRUE(r.loops.empty());
    int outward = 0;
    for (auto& f : m.face)
        outward += vcg::TriangleNormal(f).dot(vcg::Barycenter(f)) > 0;
    EXPECT_GT(outward, 0.99 * m.fn);
}

TEST(Reconstruction, RejectsBadInputWithClearMessages)
{
    Points P, N;
    test::SpherePoints(100, 1.0, P, N);
    auto message = [](const Points& P, const Points& N, Reconstruction::Param p) {
        try {
            CoreMesh m;
            Reconstruction::Compute(P, N, p, m);
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(message(Points(0, 3), Points(), {}).find("no vertices"), std::string::npos);
    EXPECT_NE(message(P.topRows(3), N.topRows(3), {}).find("only 3 vertices"), std::string::npos);
    Points nan = P;
    nan(5, 1) = std::numeric_limits<double>::quiet_NaN();
    EXPECT_NE(message(nan, N, {}).find("NaN"), std::string::npos);
    Reconstruction::Param p;
    p.resolution = -4;
    EXPECT_NE(message(P, N, p).find("out of range"), std::string::npos);
    p.resolution = 100000;
    EXPECT_NE(message(P, N, p).find("out of range"), std::string::npos);
    Points same = Points::Ones(20, 3);
    EXPECT_NE(message(same, Points(), {}).find("same position"), std::string::npos);
}

TEST(Reconstruction, FillsMissingNormalsAndKeepsTheGivenOnes)
{
    // A sphere whose given normals point inward (the layer's own orientation, which estimation
    // by propagation would turn outward), with a patch of 30 zero and one NaN normal: the
    // missing ones are estimated facing the way their neighbours face, and the sphere comes
    // out closed and inside out, as the given normals say.
    Points P, N;
    test::SpherePoints(3000, 1.0, P, N);
    N = -N;
    std::vector<Eigen::Index> patch;
    for (Eigen::Index i = 0; i < P.rows(); ++i)
        if ((P.row(i) - Eigen::RowVector3d(0, 0, 1)).norm() < 0.2)
            patch.push_back(i);
    ASSERT_GE(patch.size(), 20u);
    for (Eigen::Index i : patch)
        N.row(i).setZero();
    N(P.rows() - 1, 0) = std::numeric_limits<double>::quiet_NaN();  // the south pole
    CoreMesh m;
    const auto r = Reconstruction::Compute(P, N, {}, m);
    EXPECT_EQ(r.normals_filled, patch.size() + 1);
    EXPECT_FALSE(r.normals_estimated);
    EXPECT_TRUE(r.loops.empty());
    size_t inward = 0;
    for (const CoreFace& f : m.face)
        inward += vcg::TriangleNormal(f).dot(vcg::Barycenter(f)) < 0;
    EXPECT_EQ(inward, m.face.size());
}

TEST(Reconstruction, EstimatedNormalsFaceTheGivenDirections)
{
    // Normals estimated on a sphere, the upper half's samples told to face the centre (as if
    // scanned from inside: a scanner's position or its range grid's triangles), the lower
    // half told nothing: every normal faces inward, the lower half's by following its
    // neighbours; propagation alone turns them all outward. A facing matrix of the wrong size
    // is refused.
    Points P, N;
    test::SpherePoints(3000, 1.0, P, N);
    Reconstruction::Param p;
    p.normals = Reconstruction::NormalSource::Estimate;
    for (const bool facing : {false, true}) {
        p.facing = facing ? Points(-P) : Points();
        if (facing)
            for (Eigen::Index i = 0; i < P.rows(); ++i)
                if (P(i, 2) < 0)
                    p.facing.row(i).setZero();
        CoreMesh m;
        const auto r = Reconstruction::Compute(P, Points(), p, m);
        EXPECT_TRUE(r.normals_estimated);
        EXPECT_TRUE(r.loops.empty());
        size_t inward = 0;
        for (const CoreFace& f : m.face)
            inward += vcg::TriangleNormal(f).dot(vcg::Barycenter(f)) < 0;
        EXPECT_EQ(inward, facing ? m.face.size() : 0u) << (facing ? "facing the centre" : "propagated");
    }
    p.facing = Points::Zero(10, 3);
    CoreMesh m;
    EXPECT_THROW(Reconstruction::Compute(P, Points(), p, m), InputError);
}

TEST(Reconstruction, SameOutputOnOneAndTwoThreads)
{
    Points P, N;
    test::SpherePoints(4000, 1.0, P, N, -0.3);  // open: holes, trim and smoothing all run
    for (auto implicit : {Reconstruction::Implicit::Hoppe, Reconstruction::Implicit::PuRbf}) {
        Reconstruction::Param one, two;
        one.implicit = two.implicit = implicit;
        one.threads = 1;
        two.threads = 2;
        CoreMesh m1, m2;
        const auto r1 = Reconstruction::Compute(P, N, one, m1);
        const auto r2 = Reconstruction::Compute(P, N, two, m2);
        ASSERT_GT(m1.face.size(), 0u);
        ASSERT_EQ(m1.vert.size(), m2.vert.size());
        ASSERT_EQ(m1.face.size(), m2.face.size());
        for (size_t i = 0; i < m1.vert.size(); ++i)
            ASSERT_EQ(m1.vert[i].cP(), m2.vert[i].cP()) << i;  // bit for bit, same order
        for (size_t i = 0; i < m1.face.size(); ++i)
            for (int k = 0; k < 3; ++k)
                ASSERT_EQ(vcg::tri::Index(m1, m1.face[i].cV(k)), vcg::tri::Index(m2, m2.face[i].cV(k)));
        ASSERT_EQ(r1.loops.size(), r2.loops.size());
        for (size_t i = 0; i < r1.loops.size(); ++i)
            EXPECT_EQ(r1.loops[i].vertices, r2.loops[i].vertices) << i;
    }
}

TEST(Reconstruction, FullLatticeExtractionsMatchTheSodsDrivenOne)
{
    Points P, N;
    test::SpherePoints(3000, 1.0, P, N, -0.3);
    Reconstruction::Param sparse, full, plain;
    full.extraction = GatedMarchingCubes::Extraction::FullLatticeGated;
    plain.extraction = GatedMarchingCubes::Extraction::Plain;
    CoreMesh ms, mf, mp;
    const auto rs = Reconstruction::Compute(P, N, sparse, ms);
    const auto rf = Reconstruction::Compute(P, N, full, mf);
    const auto rp = Reconstruction::Compute(P, N, plain, mp);
    EXPECT_EQ(rf.implicit_evaluations, size_t(rf.full_lattice_evaluations));
    EXPECT_LT(rs.implicit_evaluations, rf.implicit_evaluations / 4);
    ASSERT_EQ(ms.vert.size(), mf.vert.size());
    for (size_t i = 0; i < ms.vert.size(); ++i)
        ASSERT_EQ(ms.vert[i].cP(), mf.vert[i].cP()) << i;
    ASSERT_EQ(rs.loops.size(), 1u);
    ASSERT_EQ(rf.loops.size(), 1u);
    // No gate: the tangent planes of the rim carry the surface on to the lattice's border,
    // where its only boundary is.
    EXPECT_GT(mp.fn, ms.fn);
    vcg::tri::UpdateBounding<CoreMesh>::Box(mp);
    ASSERT_FALSE(rp.loops.empty());
    for (const auto& loop : rp.loops)
        for (int v : loop.vertices) {
            const vcg::Point3d q = mp.vert[size_t(v)].cP();
            double toBorder = 1e9;
            for (int a = 0; a < 3; ++a)
                toBorder = std::min({toBorder, q[a] - mp.bbox.min[a], mp.bbox.max[a] - q[a]});
            EXPECT_LT(toBorder, rp.cell_size) << v;
        }
}

TEST(Reconstruction, RefusesRunsOverTheMemoryLimit)
{
    Points P, N;
    test::SpherePoints(2000, 1.0, P, N);
    Reconstruction::Param p;
    p.resolution = 400;
    p.memory_limit = 50e6;  // 50 MB: too little for 400 cells per side
    CoreMesh m;
    try {
        Reconstruction::Compute(P, N, p, m);
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("over the limit of 0.05 GB"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("lower the resolution"), std::string::npos);
    }
    p.resolution = 40;  // fits the same limit sparsely, but not as a full lattice of that size
    EXPECT_NO_THROW(Reconstruction::Compute(P, N, p, m));
    p.extraction = GatedMarchingCubes::Extraction::FullLatticeGated;
    p.resolution = 200;
    p.memory_limit = 40e6;
    try {
        Reconstruction::Compute(P, N, p, m);
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("lattice corners"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("SODS-driven"), std::string::npos);
    }
}

TEST(Reconstruction, RefusesSamplesThatAloneExceedTheMemoryLimit)
{
    // Whatever the lattice, 20,000 samples need more than this limit: a coarser one would not help.
    Points P, N;
    test::SpherePoints(20000, 1.0, P, N);
    Reconstruction::Param p;
    p.resolution = 16;
    p.memory_limit = 0.6 * MemoryBudget::PeakBytes(20000, 0, 0);
    CoreMesh m;
    try {
        Reconstruction::Compute(P, N, p, m);
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("20000 samples"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("the samples alone need"), std::string::npos) << e.what();
    }
    EXPECT_EQ(m.VN(), 0);
    p.memory_limit = 0;  // the default: fits, and the estimate is reported
    const Reconstruction::Result r = Reconstruction::Compute(P, N, p, m);
    EXPECT_GE(r.memory_estimate, MemoryBudget::PeakBytes(20000, double(r.sods_cells), 0));
}


namespace {
int g_calls = 0, g_allowed = 0;
bool CountCalls(int, const char*)
{
    ++g_calls;
    return true;
}
bool StopAfterAllowed(int, const char*)
{
    return g_allowed-- > 0;
}
} // namespace

TEST(Reconstruction, CancelStopsAtEveryStageAndLeavesNothing)
{
    Points P, N;
    test::SpherePoints(4000, 1.0, P, N, 0.0);  // a hemisphere: every stage, boundaries included, runs
    for (auto implicit : {Reconstruction::Implicit::Hoppe, Reconstruction::Implicit::PuRbf}) {
        Reconstruction::Param p;
        p.implicit = implicit;
        p.normals = Reconstruction::NormalSource::Estimate;  // the normals stage reports too
        p.threads = 2;
        CoreMesh m, h;
        g_calls = 0;
        Reconstruction::Compute(P, N, p, m, &h, &CountCalls);
        const int total = g_calls;
        ASSERT_GT(total, 5);
        // With 2 threads the fit reports a varying number of times (only the calling thread
        // reports, as far as it has come): a run may make fewer calls than the counted one, and
        // then must finish. Any call answered "stop" must cancel the run.
        int cancelled = 0, tries = 0;
        for (int k = 0; k < total; k += std::max(1, total / 10), ++tries) {
            g_allowed = k;  // the callback says stop at its (k+1)-th call
            CoreMesh surface, holes;
            bool stopped = false;
            try {
                Reconstruction::Compute(P, N, p, surface, &holes, &StopAfterAllowed);
            } catch (const Cancelled&) {
                stopped = true;
            }
            EXPECT_EQ(stopped, g_allowed < 0) << k;  // g_allowed < 0: some call answered "stop"
            if (stopped) {
                EXPECT_TRUE(surface.vert.empty() && surface.face.empty() && holes.face.empty()) << k;
            }
            cancelled += stopped;
        }
        EXPECT_GE(cancelled, tries - 2);
        CoreMesh again, holes;  // nothing left over from the cancelled runs
        const auto r = Reconstruction::Compute(P, N, p, again, &holes, &CountCalls);
        EXPECT_EQ(r.loops.size(), 1u);
        EXPECT_EQ(again.face.size(), m.face.size());
    }
}
