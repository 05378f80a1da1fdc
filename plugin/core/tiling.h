#pragma once
/// \file tiling.h
/// One tile of a scan reconstructed tile by tile (the Python package's `tiled` schedules the
/// tiles on Dask). A tile runs the whole pipeline on the samples of its block plus a halo, on
/// the lattice of the whole scan (cell and origin fixed, so neighbouring tiles compute the
/// corners they share from the same numbers), with the PU-RBF's octree rooted at the whole
/// scan's cube (so its cells are the cells a single run would make, wherever the halo holds
/// all their samples), and the whole scan's median spacing; it keeps the faces whose centre
/// lies in its block. Faces of neighbouring blocks then meet at shared lattice-edge vertices.

#include "implicit/point_octree.h"
#include "input_check.h"
#include "lattice.h"
#include "mesh.h"

#include <Eigen/Geometry>
#include <vcg/complex/algorithms/clean.h>

#include <cmath>
#include <string>
#include <vector>

namespace ib {

struct Tile
{
    double cell = 0;  ///< lattice cell of the whole scan; 0: not a tile (the lattice fits the samples)
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< corner (0,0,0) of the whole scan's lattice
    Eigen::Vector3d end = Eigen::Vector3d::Zero();     ///< its far corner; every sample lies in [origin, end]
    double spacing = 0;          ///< the whole scan's median sample spacing; 0: this tile's own
    Eigen::AlignedBox3d block;   ///< faces kept: centre in [min, max) on every axis; empty: all

    bool Fixed() const { return cell > 0; }

    /// The octree root of the whole scan: the cube on [origin, end] (half 0 when not Fixed: the
    /// samples' own bounding cube).
    PointOctree::Box Root() const
    {
        PointOctree::Box b;
        if (Fixed()) {
            b.centre = 0.5 * (origin + end);
            b.half = 0.5 * (end - origin).maxCoeff() * (1 + 1e-9);
        }
        return b;
    }

    /// The cells of the whole scan's lattice that cover [lo, hi], padded by `pad` cells.
    Lattice Over(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int pad) const
    {
        return Lattice::OnGrid(origin, cell, lo, hi, pad);
    }

    /// Throws InputError when the lattice or block is unusable for the n×3 samples P.
    void Check(const Points& P) const
    {
        if (!Fixed()) {
            if (!(cell == 0))
                throw InputError("The lattice cell must be positive (0: the lattice fits the samples).");
            if (!block.isEmpty())
                throw InputError("A block to keep needs the fixed lattice it is cut from: set the lattice cell, "
                                 "origin and end too.");
            return;
        }
        if (!std::isfinite(cell) || !origin.allFinite() || !end.allFinite() || !((end - origin).array() > 0).all())
            throw InputError("The fixed lattice needs a finite cell and an end above its origin on every axis.");
        const double cells = ((end - origin) / cell).maxCoeff();
        if (cells > Lattice::kMaxCells)
            throw InputError("The fixed lattice has " + std::to_string(long(cells)) + " cells along an axis; at most " +
                             std::to_string(Lattice::kMaxCells) + " fit: use a larger cell.");
        for (Eigen::Index i = 0; i < P.rows(); ++i)
            if (((P.row(i).transpose() - origin).array() < 0).any() || ((end - P.row(i).transpose()).array() < 0).any())
                throw InputError("Some samples lie outside the fixed lattice: its origin and end must contain every "
                                 "sample (a tiled run's lattice covers the whole scan).");
        if (!block.isEmpty() && !((block.max() - block.min()).array() > 0).all())
            throw InputError("The block to keep is flat: give a minimum corner below its maximum on every axis, or "
                             "equal corners to keep everything.");
    }

    /// Keeps the faces of `mesh` whose centre lies in [block.min, block.max) (all when the
    /// block is empty): half-open, so each face of a tiled scan belongs to exactly one block.
    /// Face-face adjacency is rebuilt.
    void Clip(CoreMesh& mesh) const
    {
        if (block.isEmpty())
            return;
        for (CoreFace& face : mesh.face) {
            const vcg::Point3d c = (face.cP(0) + face.cP(1) + face.cP(2)) / 3.0;
            const Eigen::Vector3d centre(c[0], c[1], c[2]);
            if (!((centre.array() >= block.min().array()).all() && (centre.array() < block.max().array()).all()))
                vcg::tri::Allocator<CoreMesh>::DeleteFace(mesh, face);
        }
        vcg::tri::Clean<CoreMesh>::RemoveUnreferencedVertex(mesh);
        vcg::tri::Allocator<CoreMesh>::CompactEveryVector(mesh);
        UpdateFaceFace(mesh);
    }
};

} // namespace ib
