#pragma once
/// \file mesh_holes.h
/// Holes of an input mesh kept open. From its samples alone a small hole cannot be told from
/// undersampling: pymeshlab's bunny has two holes 1.03 and 1.27 spacings deep, no deeper than
/// the largest gaps between its own vertices (BENCHMARKS, "Small real holes"), and the tangent
/// disks close them. When the input is a triangle mesh (a triangulated range scan, a mesh
/// being remeshed), its triangles record where the surface was seen, so a hole of the
/// triangulation is a hole: the extracted surface is cut where it passes over none of the
/// input's triangles. The hole rule of point clouds still applies to what the cut opens: an
/// opening whose loop has fewer than min_boundary_edges edges is undersampling, and stays
/// closed. The other way round, a hole the gate opened where the triangles cover the surface
/// (the implicit surface bulging past a thin part's samples, a sparse occluded region) is no
/// hole of the scan, and is filled whatever its size (Covered), with the implicit surface's hole
/// faces when they stay near the triangles; where they balloon away from them (a thin flap of
/// large triangles, which the implicit surface closes as a ball), the hole is left open here,
/// and CoveredOpenings, testing the finished surface's openings against the triangles, spans
/// it by a patch of its loop.

#include "implicit/mesh_distance.h"
#include "mesh.h"
#include "samples.h"

#include <vector>

namespace ib {

class MeshHoles
{
public:
    /// A face is over the input mesh when its centre lies at most this many cells past the
    /// mesh's border: marching cubes faces lie within a cell, so a face crossing the border
    /// has its centre within half a cell of it.
    static constexpr double kPastBorderCells = 0.5;
    /// A hole region with a face farther than this many local spacings (of the sample nearest
    /// the face) from the triangles is not filled with its hole faces: no face of the surface
    /// should stray farther from the true one (docs/yardsticks.md, farthest face). Measured on
    /// every input given as a mesh (bench/corpus.py and bench/held_out.py, --conditions mesh):
    /// the only hole regions over the triangles, four on a cut cow, reach 1.18, 1.48 and 2.31
    /// spacings from them, and 9.01 where the implicit surface closed its ear, a flap a
    /// triangle thick, as a ball.
    static constexpr double kNearTriangles = 2.0;

    /// Per hole region of `all` with regions[r] set (its hole faces are all.face[surfaceFaces +
    /// i] with faceRegion[i] == r), 1 if the centre of each of its faces lies over `input` (at
    /// most kPastBorderCells × cellSize past its border) and, with `samples` (and `spacing`,
    /// their local spacings), within kNearTriangles local spacings of it (`threads`: 0 = all cores).
    static std::vector<char> Covered(const CoreMesh& all, size_t surfaceFaces, const std::vector<int>& faceRegion,
                                     const std::vector<char>& regions, const MeshDistance& input, double cellSize,
                                     const SampleIndex* samples = nullptr, const Eigen::VectorXd* spacing = nullptr,
                                     int threads = 0)
    {
        std::vector<size_t> faces;
        for (size_t i = 0; i < faceRegion.size(); ++i)
            if (regions[size_t(faceRegion[i])])
                faces.push_back(i);
        Points centres(Eigen::Index(faces.size()), 3);
        for (size_t k = 0; k < faces.size(); ++k) {
            const vcg::Point3d c = vcg::Barycenter(all.face[surfaceFaces + faces[k]]);
            centres.row(Eigen::Index(k)) << c[0], c[1], c[2];
        }
        const Eigen::VectorXd past = input.PastBorder(centres);
        std::vector<char> covered(regions);
        for (size_t k = 0; k < faces.size(); ++k)
            if (past[Eigen::Index(k)] > kPastBorderCells * cellSize)
                covered[size_t(faceRegion[faces[k]])] = 0;
        if (samples && spacing) {
            // Only the faces of regions still covered: a region's outer faces past the border
            // (a scan's unseen surround) would cost most of the closest-point queries.
            std::vector<size_t> left;
            for (size_t k = 0; k < faces.size(); ++k)
                if (covered[size_t(faceRegion[faces[k]])])
                    left.push_back(k);
            const Points near = centres(left, Eigen::all);
            Eigen::VectorXd distance(near.rows());
            input.Eval(near, distance);
            std::vector<char> far(left.size(), 0);
            ParallelFor(left.size(), threads, [&](size_t begin, size_t end, int) {
                SampleIndex::Queue queue;
                for (size_t j = begin; j < end; ++j) {
                    samples->Nearest(near.row(Eigen::Index(j)).transpose(), 1, queue);
                    far[j] = std::abs(distance[Eigen::Index(j)]) > kNearTriangles * (*spacing)[queue.getIndex(0)];
                }
            }, 256);
            for (size_t j = 0; j < left.size(); ++j)
                if (far[j])
                    covered[size_t(faceRegion[faces[left[j]]])] = 0;
        }
        return covered;
    }

    /// Removes from the surface (inSurface[f] = 1; face-face adjacency of `all` up to date)
    /// the faces whose centre lies more than kPastBorderCells × cellSize past the border of
    /// `input` (MeshDistance::PastBorder), except the openings inside the surface whose loop
    /// would have fewer than minEdges edges (0: none kept closed). Returns the faces removed.
    static size_t Cut(const CoreMesh& all, const MeshDistance& input, double cellSize, int minEdges,
                      std::vector<char>& inSurface)
    {
        std::vector<size_t> surface;
        for (size_t f = 0; f < all.face.size(); ++f)
            if (inSurface[f])
                surface.push_back(f);
        Points centres(Eigen::Index(surface.size()), 3);
        for (size_t k = 0; k < surface.size(); ++k) {
            const vcg::Point3d c = vcg::Barycenter(all.face[surface[k]]);
            centres.row(Eigen::Index(k)) << c[0], c[1], c[2];
        }
        const Eigen::VectorXd past = input.PastBorder(centres);
        std::vector<char> over(all.face.size(), 0);  // 1: past the border
        for (size_t k = 0; k < surface.size(); ++k)
            over[surface[k]] = past[Eigen::Index(k)] > kPastBorderCells * cellSize;

        // Each connected piece of faces past the border: cut, unless it lies inside the surface
        // and its rim would be a loop of fewer than minEdges edges.
        size_t removed = 0;
        std::vector<char> seen(all.face.size(), 0);
        std::vector<size_t> piece, stack;
        for (size_t start : surface) {
            if (!over[start] || seen[start])
                continue;
            piece.clear();
            stack.assign(1, start);
            seen[start] = 1;
            bool atBoundary = false;
            int rim = 0;
            while (!stack.empty()) {
                const size_t f = stack.back();
                stack.pop_back();
                piece.push_back(f);
                for (int i = 0; i < 3; ++i) {
                    const size_t g = vcg::tri::Index(all, all.face[f].cFFp(i));
                    if (g == f || !inSurface[g]) {
                        atBoundary = true;
                    } else if (!over[g]) {
                        ++rim;
                    } else if (!seen[g]) {
                        seen[g] = 1;
                        stack.push_back(g);
                    }
                }
            }
            if (!atBoundary && rim < minEdges)
                continue;
            for (size_t f : piece)
                inSurface[f] = 0;
            removed += piece.size();
        }
        return removed;
    }
};

} // namespace ib
