#pragma once
/// \file fold_guard.h
/// Keeps vertex moves from folding the mesh: a move that turns an adjacent face's normal by
/// more than 90 degrees (the face flipped over), or flattens it to a sliver, is halved, up to
/// three times, then undone.
/// Used by the boundary steps that move boundary vertices (boundary_fit.h, boundary_smoothing.h).

#include "mesh.h"

#include <Eigen/Core>

#include <vector>

namespace ib {

class FoldGuard
{
public:
    /// `moved`: vertex indices of `mesh` already at their new positions; `start`: their
    /// positions before the move (same order). Pulls back the moves that flip a face.
    /// Returns the number of vertices not left at their new position.
    static size_t Restore(CoreMesh& mesh, const std::vector<int>& moved, const std::vector<Eigen::Vector3d>& start)
    {
        std::vector<int> slot(mesh.vert.size(), -1);
        for (size_t i = 0; i < moved.size(); ++i)
            slot[size_t(moved[i])] = int(i);
        std::vector<std::vector<int>> faces(moved.size());
        for (size_t f = 0; f < mesh.face.size(); ++f)
            for (int i = 0; i < 3; ++i)
                if (const int s = slot[vcg::tri::Index(mesh, mesh.face[f].cV(i))]; s >= 0)
                    faces[size_t(s)].push_back(int(f));
        std::vector<Eigen::Vector3d> target(moved.size());
        for (size_t i = 0; i < moved.size(); ++i)
            target[i] = PositionOf(mesh, moved[i]);

        // Normals of the faces around moved vertices, before any move.
        for (size_t i = 0; i < moved.size(); ++i)
            MoveVertex(mesh, moved[i], start[i]);
        std::vector<std::vector<vcg::Point3d>> before(moved.size());
        for (size_t i = 0; i < moved.size(); ++i)
            for (int f : faces[i])
                before[i].push_back(vcg::TriangleNormal(mesh.face[size_t(f)]));
        for (size_t i = 0; i < moved.size(); ++i)
            MoveVertex(mesh, moved[i], target[i]);

        std::vector<char> pulled(moved.size(), 0);
        // Halving three times, then undoing: an undone move can fold a face of a neighbour that
        // was fine, so passes go on until none changes (each undo is final, so they end).
        for (int attempt = 0;; ++attempt) {
            bool changed = false;
            for (size_t i = 0; i < moved.size(); ++i) {
                bool bad = false;
                for (size_t j = 0; j < faces[i].size() && !bad; ++j)
                    bad = Collapsed(vcg::TriangleNormal(mesh.face[size_t(faces[i][j])]), before[i][j]);
                const Eigen::Vector3d p = PositionOf(mesh, moved[i]);
                if (!bad || p == start[i])
                    continue;
                MoveVertex(mesh, moved[i], attempt < 3 ? Eigen::Vector3d(0.5 * (p + start[i])) : start[i]);
                pulled[i] = 1;
                changed = true;
            }
            if (!changed)
                break;
        }
        return size_t(std::count(pulled.begin(), pulled.end(), 1));
    }

    /// True when a face whose (area-weighted) normal was `before` now has normal `after` turned
    /// by more than 90 degrees (folded over), or its area shrank under 1% (a collinearity
    /// move lines up all three corners of a face along the boundary). Faces that had no area
    /// to start with do not count.
    static bool Collapsed(const vcg::Point3d& after, const vcg::Point3d& before)
    {
        return before.SquaredNorm() > 0 && after.dot(before) <= 0.01 * before.SquaredNorm();
    }
};

} // namespace ib
