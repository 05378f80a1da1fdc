#pragma once
/// \file sods.h
/// Spatial occupancy data structure (SODS) of the implemented paper (README, "The method"),
/// §3.1 "Initializing the SODS". In the paper a cell is occupied when it holds a sample, and
/// the occupancy is dilated by the 26-neighbourhood so that the implicit surface may pass
/// through cells next to the samples. We also offer tangent-disk occupancy (FromDisks), which
/// covers sparse regions without growing the occupancy across real holes. Stored sparsely as 8×8×8 bit bricks in a hash map, so memory grows with
/// the occupied cells, not with the lattice volume.

#include "lattice.h"
#include "parallel.h"

#include <algorithm>
#include <array>
#include <unordered_map>
#include <vector>

namespace ib {

class Sods
{
public:
    explicit Sods(const Index3& cells) : cells_(cells) {}

    /// Occupancy of the cells holding the n×3 samples P (the paper's SODS before dilation).
    static Sods FromSamples(const Lattice& lattice, const Points& P)
    {
        Sods s(lattice.cells);
        for (Eigen::Index i = 0; i < P.rows(); ++i)
            s.Insert(lattice.CellOf(P.row(i).transpose()));
        return s;
    }

    /// Occupancy of the cells that the samples' tangent disks pass through: sample i with unit
    /// normal N.row(i) covers the disk of radius radius[i] around it in its tangent plane,
    /// thickened by `slack` (world units) on each side along the normal, plus thickness[i] when
    /// given (empty: none; e.g. half the distance to the other side at a thin part's rim, where
    /// the surface turns between two sheets of flat disks). A cell counts when its centre lies
    /// within that slab widened by the cell's half extent along the normal, and within the
    /// radius plus half a cell diagonal along the plane. Disk i is at least minSlab[i] thick on
    /// each side (when given), and where the lattice is finer than reachCell it keeps the reach
    /// it has on cells of reachCell. With radii from the local sample spacing, sparse regions
    /// stay covered while gaps wider than two radii stay open. Where open.row(i) is a nonzero unit
    /// vector in the tangent plane (open: n×3, or empty for none; OpenSides), the sampling ends
    /// that way and disk i covers only its half behind its sample (cells whose centre lies at
    /// most half a cell diagonal ahead).
    static Sods FromDisks(const Lattice& lattice, const Points& P, const Points& N, const Eigen::VectorXd& radius,
                          double slack, int threads = 0, const Eigen::VectorXd& thickness = Eigen::VectorXd(),
                          const Eigen::VectorXd& minSlab = Eigen::VectorXd(), double reachCell = 0,
                          const Points& open = Points())
    {
        // One occupancy per block of samples, OR-ed together: the result does not depend on
        // the thread count.
        std::vector<Sods> parts;
        const int blocks = std::max(1, std::min(threads > 0 ? threads : DefaultThreads(), int(P.rows() / 4096)));
        parts.assign(size_t(blocks), Sods(lattice.cells));
        const Eigen::Index per = (P.rows() + blocks - 1) / blocks;
        ParallelFor(size_t(blocks), blocks, [&](size_t begin, size_t end, int) {
            for (size_t b = begin; b < end; ++b)
                for (Eigen::Index i = Eigen::Index(b) * per; i < std::min(P.rows(), Eigen::Index(b + 1) * per); ++i)
                    parts[b].InsertDisk(lattice, P.row(i).transpose(), N.row(i).transpose(), radius[i],
                                        slack, thickness.size() ? thickness[i] : 0.0,
                                        minSlab.size() ? minSlab[i] : 0.0, reachCell,
                                        open.rows() ? Eigen::Vector3d(open.row(i).transpose()) : Eigen::Vector3d::Zero());
        }, 1);
        for (size_t b = 1; b < parts.size(); ++b)
            parts[0].Merge(parts[b]);
        return std::move(parts[0]);
    }

    void Insert(const Index3& c) { Set(bricks_[BrickKey(c)], c); }

    bool Contains(const Index3& c) const
    {
        if ((c.array() < 0).any() || (c.array() >= cells_.array()).any())
            return false;
        auto it = bricks_.find(BrickKey(c));
        if (it == bricks_.end())
            return false;
        const int bit = BitOf(c);
        return it->second[bit >> 6] & (uint64_t(1) << (bit & 63));
    }

    /// Adds the cells of one tangent disk (see FromDisks; `open` zero: the whole disk).
    void InsertDisk(const Lattice& lattice, const Eigen::Vector3d& p, const Eigen::Vector3d& n, double r, double slack,
                    double thickness = 0, double minSlab = 0, double reachCell = 0,
                    const Eigen::Vector3d& open = Eigen::Vector3d::Zero())
    {
        const double a = 0.5 * lattice.cell_size;
        const double wider = std::max(1.0, reachCell / lattice.cell_size);
        const double slab = std::max(a * n.cwiseAbs().sum() + slack, minSlab) + thickness;
        const double reach = r + wider * a * std::sqrt(3.0);
        const double openReach = open.isZero() ? reach : wider * a * std::sqrt(3.0);
        const Eigen::Vector3d box =
            Eigen::Vector3d::Constant(std::max(r + (wider - 1) * a * std::sqrt(3.0), std::max(slack, minSlab) + thickness));
        const Index3 lo = lattice.CellOf(p - box), hi = lattice.CellOf(p + box);
        // Neighbouring cells mostly share a brick: keep the last one instead of hashing each
        // cell (map elements do not move when the map grows).
        uint64_t lastKey = ~uint64_t(0);
        Brick* brick = nullptr;
        for (int z = lo[2]; z <= hi[2]; ++z)
            for (int y = lo[1]; y <= hi[1]; ++y)
                for (int x = lo[0]; x <= hi[0]; ++x) {
                    const Eigen::Vector3d d = lattice.Corner(x, y, z) + Eigen::Vector3d::Constant(a) - p;
                    const double h = n.dot(d);
                    if (std::abs(h) <= slab && (d - h * n).norm() <= reach && d.dot(open) <= openReach) {
                        const Index3 c(x, y, z);
                        if (BrickKey(c) != lastKey) {
                            lastKey = BrickKey(c);
                            brick = &bricks_[lastKey];
                        }
                        Set(*brick, c);
                    }
                }
        Insert(lattice.CellOf(p));
    }

    /// Adds every cell of `other` (same lattice).
    void Merge(const Sods& other)
    {
        for (const auto& [key, brick] : other.bricks_) {
            Brick& b = bricks_[key];
            for (size_t w = 0; w < b.size(); ++w) {
                count_ += size_t(__builtin_popcountll(brick[w] & ~b[w]));
                b[w] |= brick[w];
            }
        }
    }

    /// Number of occupied cells.
    size_t Count() const { return count_; }

    /// The occupancy grown by one ring of 26-neighbours, clipped to the lattice.
    Sods Dilated() const
    {
        Sods out(cells_);
        ForEach([&](const Index3& c) {
            for (int dz = -1; dz <= 1; ++dz)
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const Index3 n = c + Index3(dx, dy, dz);
                        if ((n.array() >= 0).all() && (n.array() < cells_.array()).all())
                            out.Insert(n);
                    }
        });
        return out;
    }

    /// Occupied cells sorted by (z, y, x): a deterministic order independent of hashing.
    std::vector<Index3> Cells() const
    {
        std::vector<uint64_t> keys;
        keys.reserve(count_);
        ForEach([&](const Index3& c) { keys.push_back(PackIndex(c[0], c[1], c[2])); });
        std::sort(keys.begin(), keys.end());
        std::vector<Index3> out(keys.size());
        std::transform(keys.begin(), keys.end(), out.begin(), UnpackIndex);
        return out;
    }

    /// Calls f(cell) for each occupied cell, in no particular order.
    template <class F>
    void ForEach(F&& f) const
    {
        for (const auto& [key, brick] : bricks_) {
            const Index3 base = UnpackIndex(key) * kBrick;
            for (int w = 0; w < int(brick.size()); ++w)
                for (uint64_t bits = brick[w]; bits; bits &= bits - 1) {
                    const int bit = w * 64 + __builtin_ctzll(bits);
                    f(Index3(base[0] + (bit & 7), base[1] + ((bit >> 3) & 7), base[2] + (bit >> 6)));
                }
        }
    }

private:
    static constexpr int kBrick = 8;
    using Brick = std::array<uint64_t, kBrick * kBrick * kBrick / 64>;

    /// Marks cell c in its brick b.
    void Set(Brick& b, const Index3& c)
    {
        const int bit = BitOf(c);
        if (!(b[bit >> 6] & (uint64_t(1) << (bit & 63)))) {
            b[bit >> 6] |= uint64_t(1) << (bit & 63);
            ++count_;
        }
    }

    static uint64_t BrickKey(const Index3& c) { return PackIndex(c[0] >> 3, c[1] >> 3, c[2] >> 3); }
    static int BitOf(const Index3& c) { return (c[0] & 7) | ((c[1] & 7) << 3) | ((c[2] & 7) << 6); }

    Index3 cells_;
    std::unordered_map<uint64_t, Brick> bricks_;
    size_t count_ = 0;
};

} // namespace ib
