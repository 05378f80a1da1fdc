#pragma once
/// \file lattice.h
/// The regular cubic lattice shared by the SODS and marching cubes (paper §3: the SODS
/// resolution matches the lattice resolution). Cells are indexed by their minimum corner.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>

namespace ib {

/// n×3 point set, one point per row (rows are contiguous, so rows can be viewed as vcg::Point3d).
using Points = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// m×3 vertex indices (rows of a Points) of triangles, one row per face.
using Faces = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;

/// Integer cell or corner coordinates.
using Index3 = Eigen::Vector3i;

/// Packs lattice coordinates (each in [0, 2^20)) into one 60-bit key; keys sort by (z, y, x)
/// and leave 4 bits free for edge keys.
inline uint64_t PackIndex(int x, int y, int z)
{
    return (uint64_t(uint32_t(z)) << 40) | (uint64_t(uint32_t(y)) << 20) | uint64_t(uint32_t(x));
}

inline Index3 UnpackIndex(uint64_t key)
{
    const uint64_t mask = (uint64_t(1) << 20) - 1;
    return Index3(int(key & mask), int((key >> 20) & mask), int(key >> 40));
}

/// A cubic lattice: `cells` cells per axis of side `cell_size`, cut from the grid of corners
/// origin + cell_size*(i,j,k) from grid index `first` on. Corner (i,j,k) of the lattice sits at
/// origin + cell_size*(first + (i,j,k)); cell (i,j,k) spans corners (i,j,k)..(i+1,j+1,k+1).
struct Lattice
{
    /// Largest number of cells per axis (the packed keys hold 20 bits per axis).
    static constexpr int kMaxCells = (1 << 20) - 2;

    Eigen::Vector3d origin = Eigen::Vector3d::Zero();
    double cell_size = 1;
    Index3 cells = Index3::Zero();
    /// Grid index of corner (0,0,0): 0 for a lattice fitted to its samples; a tile's lattice
    /// (tiling.h) is cut from the whole scan's grid, so the corners two tiles share are
    /// computed from the same numbers.
    Index3 first = Index3::Zero();

    /// Lattice with `resolution` cells along the longest side of [lo, hi], padded by `pad`
    /// cells on every side so that dilated cells and their corners stay inside.
    static Lattice Fit(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int resolution, int pad)
    {
        Lattice l;
        const Eigen::Vector3d extent = hi - lo;
        l.cell_size = extent.maxCoeff() / resolution;
        for (int a = 0; a < 3; ++a)
            l.cells[a] = std::max(1, int(std::ceil(extent[a] / l.cell_size))) + 2 * pad;
        // Centre the samples in the padded lattice.
        l.origin = lo - 0.5 * (l.cells.cast<double>() * l.cell_size - extent);
        return l;
    }

    /// The cells of the grid of corners origin + cell*(i,j,k) that cover [lo, hi], padded by
    /// `pad` cells on every side.
    static Lattice OnGrid(const Eigen::Vector3d& origin, double cell, const Eigen::Vector3d& lo,
                          const Eigen::Vector3d& hi, int pad)
    {
        Lattice l;
        l.origin = origin;
        l.cell_size = cell;
        for (int a = 0; a < 3; ++a) {
            l.first[a] = int(std::floor((lo[a] - origin[a]) / cell)) - pad;
            l.cells[a] = int(std::floor((hi[a] - origin[a]) / cell)) + 1 + pad - l.first[a];
        }
        return l;
    }

    Eigen::Vector3d Corner(int x, int y, int z) const
    {
        return origin + cell_size * Eigen::Vector3d(first[0] + x, first[1] + y, first[2] + z);
    }

    /// Cell holding point p, clamped into the lattice.
    Index3 CellOf(const Eigen::Vector3d& p) const
    {
        Index3 c;
        for (int a = 0; a < 3; ++a)
            c[a] = std::min(cells[a] - 1,
                            std::max(0, int(std::floor((p[a] - origin[a]) / cell_size)) - first[a]));
        return c;
    }

    bool ContainsCell(const Index3& c) const
    {
        return (c.array() >= 0).all() && (c.array() < cells.array()).all();
    }

    /// Number of lattice corners, (cells+1)^3: what a full-lattice marching cubes evaluates.
    double CornerCount() const
    {
        return double(cells[0] + 1) * double(cells[1] + 1) * double(cells[2] + 1);
    }
};

} // namespace ib
