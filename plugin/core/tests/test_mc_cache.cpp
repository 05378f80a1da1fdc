#include "mc_cache.h"
#include "geometry.h"

#include <vcg/complex/algorithms/create/marching_cubes.h>

#include <gtest/gtest.h>

#include <atomic>
#include <set>
#include <stdexcept>

using namespace ib;

namespace {

/// A sphere's signed distance, counting the points it is asked for.
class CountingSphere : public ImplicitFunction
{
public:
    explicit CountingSphere(double r = 1.0) : r_(r) {}
    void Eval(const Points& Q, Eigen::Ref<Eigen::VectorXd> values) const override
    {
        asked += size_t(Q.rows());
        values = Q.rowwise().norm().array() - r_;
    }
    mutable std::atomic<size_t> asked{0};

private:
    double r_;
};

/// A cell of the lattice that the unit sphere crosses: on the +x axis, at radius 1.
Index3 CellOnTheSphere(const Lattice& l)
{
    const Index3 centre = l.CellOf(Eigen::Vector3d(0, 0, 0));
    Index3 c = centre;
    while (l.Corner(c[0] + 1, c[1], c[2])[0] < 1.0)
        ++c[0];
    return c;
}

/// Extracts the cells in the given order; returns the vertex positions.
std::vector<Eigen::Vector3d> Extract(const Lattice& l, const CornerValues& values, const std::vector<Index3>& cells,
                                     CoreMesh& m)
{
    MarchingCubesWalker walker(l, m, values);
    vcg::tri::MarchingCubes<CoreMesh, MarchingCubesWalker> mc(m, walker);
    mc.Initialize();
    for (const Index3& c : cells)
        mc.ProcessCell(vcg::Point3i(c[0], c[1], c[2]), vcg::Point3i(c[0] + 1, c[1] + 1, c[2] + 1));
    mc.Finalize();
    std::vector<Eigen::Vector3d> out;
    for (const CoreVertex& v : m.vert)
        out.emplace_back(v.cP()[0], v.cP()[1], v.cP()[2]);
    return out;
}

} // namespace

TEST(CornerValues, EachCornerIsEvaluatedOnceAndHoldsTheFunctionsValue)
{
    const Lattice l = Lattice::Fit(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1), 16, 2);
    const CountingSphere f;
    CornerValues values(l, f);
    const Index3 a = CellOnTheSphere(l), b = a + Index3(0, 1, 0);  // neighbours sharing a face
    values.Evaluate({a});
    EXPECT_EQ(values.Count(), 8u);
    values.Evaluate({a, b});  // b adds only the 4 corners it does not share with a
    EXPECT_EQ(values.Count(), 12u);
    EXPECT_EQ(f.asked.load(), 12u);
    EXPECT_EQ(values.CornerCount({a, b}, false), 12u);
    for (int i = 0; i < 8; ++i) {
        const Index3 corner = b + Index3(i & 1, (i >> 1) & 1, i >> 2);
        EXPECT_DOUBLE_EQ(values(PackIndex(corner[0], corner[1], corner[2])),
                         l.Corner(corner[0], corner[1], corner[2]).norm() - 1.0);
    }
}

TEST(CornerValues, CrossedCellsAndFaces)
{
    const Lattice l = Lattice::Fit(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1), 16, 2);
    const CountingSphere f;
    CornerValues values(l, f);
    const Index3 on = CellOnTheSphere(l), inside = l.CellOf(Eigen::Vector3d(0, 0, 0));
    values.Evaluate({on, inside, on + Index3(1, 0, 0)});
    EXPECT_TRUE(values.Crossed(on));
    EXPECT_FALSE(values.Crossed(inside));
    EXPECT_EQ(values.CornerCount({on, inside}, true), 8u);  // only the crossed cell's corners
    // Its faces towards ±y cut through the surface (inside corners at the lower x, outside at the upper).
    EXPECT_TRUE(values.FaceCrossed(on, Index3(0, 1, 0)));
}

TEST(MarchingCubesWalker, EdgeVerticesAreSharedWhateverTheCellOrder)
{
    const Lattice l = Lattice::Fit(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1), 12, 2);
    const double r = 0.93;  // through no lattice corner: no two edges meet the surface at one point
    const CountingSphere f(r);
    CornerValues values(l, f);
    std::vector<Index3> cells;  // a band of crossed cells around the equator
    for (int x = 0; x < l.cells[0]; ++x)
        for (int y = 0; y < l.cells[1]; ++y)
            for (int z = l.cells[2] / 2 - 1; z <= l.cells[2] / 2; ++z)
                cells.emplace_back(x, y, z);
    values.Evaluate(cells);
    cells.erase(std::remove_if(cells.begin(), cells.end(), [&](const Index3& c) { return !values.Crossed(c); }),
                cells.end());
    ASSERT_GT(cells.size(), 20u);
    CoreMesh forward, backward;
    const std::vector<Eigen::Vector3d> a = Extract(l, values, cells, forward);
    std::vector<Index3> reversed(cells.rbegin(), cells.rend());
    const std::vector<Eigen::Vector3d> b = Extract(l, values, reversed, backward);
    EXPECT_EQ(a.size(), b.size());
    EXPECT_EQ(forward.fn, backward.fn);
    auto key = [](const Eigen::Vector3d& p) { return std::array<double, 3>{p[0], p[1], p[2]}; };
    std::set<std::array<double, 3>> sa, sb;
    for (const auto& p : a)
        sa.insert(key(p));
    for (const auto& p : b)
        sb.insert(key(p));
    EXPECT_EQ(sa.size(), a.size());  // welded: no position twice
    EXPECT_EQ(sa, sb);
    // Welded, the band is one oriented 2-manifold strip.
    const auto t = test::Check(forward);
    EXPECT_EQ(t.non_manifold_edges, 0);
    EXPECT_TRUE(t.oriented);
    EXPECT_EQ(forward.vn - (t.border_edges + 3 * forward.fn) / 2 + forward.fn, 0);  // an annulus (unwelded: fn)
    for (const Eigen::Vector3d& p : a)
        EXPECT_LT(std::abs(p.norm() - r), 0.05 * l.cell_size);
}

TEST(KeyTable, KeepsEveryKeysValueAcrossGrowthAndFindsNoOther)
{
    KeyTable<size_t> table;
    EXPECT_EQ(table.Find(PackIndex(0, 0, 0)), KeyTable<size_t>::kNone);  // empty: no slots yet
    // Lattice keys in a slab, far more than the first 1,024 slots: the table grows several times.
    std::vector<uint64_t> keys;
    for (int z = 0; z < 4; ++z)
        for (int y = 0; y < 60; ++y)
            for (int x = 0; x < 60; ++x)
                keys.push_back(PackIndex(x, y, z));
    for (size_t i = 0; i < keys.size(); ++i) {
        bool inserted;
        table.At(table.Insert(keys[i], inserted)) = i;
        EXPECT_TRUE(inserted);
    }
    EXPECT_EQ(table.Size(), keys.size());
    EXPECT_LE(double(table.Size()), 0.7 * double(table.Slots()));
    for (size_t i = 0; i < keys.size(); ++i) {
        bool inserted;
        const size_t s = table.Insert(keys[i], inserted);  // already there: the same slot
        EXPECT_FALSE(inserted);
        EXPECT_EQ(s, table.Find(keys[i]));
        EXPECT_EQ(table.At(s), i);
    }
    EXPECT_EQ(table.Find(PackIndex(60, 0, 0)), KeyTable<size_t>::kNone);
    EXPECT_EQ(table.Find(PackIndex(0, 0, 4)), KeyTable<size_t>::kNone);

    // With room reserved, slots stay where they were given while new keys go in.
    table.Reserve(5000);
    const size_t slots = table.Slots(), first = table.Find(keys[0]);
    for (int x = 0; x < 5000; ++x) {
        bool inserted;
        table.Insert(PackIndex(x, 0, 9), inserted);
    }
    EXPECT_EQ(table.Slots(), slots);
    EXPECT_EQ(table.Find(keys[0]), first);
    EXPECT_EQ(table.Size(), keys.size() + 5000);
}

TEST(CornerValues, ACornerReadBeforeItsEvaluationThrows)
{
    const Lattice l = Lattice::Fit(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1), 16, 2);
    const CountingSphere f;
    CornerValues values(l, f);
    EXPECT_THROW(values(PackIndex(0, 0, 0)), std::logic_error);  // nothing evaluated yet
    values.Evaluate({Index3(0, 0, 0)});
    EXPECT_NO_THROW(values(PackIndex(1, 1, 1)));
    EXPECT_THROW(values(PackIndex(2, 0, 0)), std::logic_error);  // not a corner of that cell
}
