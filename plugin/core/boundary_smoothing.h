#pragma once
/// \file boundary_smoothing.h
/// Boundary smoothing (paper §3.3): marching cubes boundaries are jagged because the gate is
/// a cell test. Each vertex of a loop is moved in turn onto the line through its two loop
/// neighbours (the paper's collinearity moves), for a few iterations; unlike the paper, the
/// moved vertices are then projected back onto the implicit surface (a few Newton steps along
/// the function's gradient), and a move that would flip an adjacent face is pulled back
/// (fold_guard.h), so no fold-over appears next to the boundary.

#include "boundaries.h"
#include "fold_guard.h"
#include "implicit_projection.h"
#include "implicit/implicit_function.h"
#include "mesh.h"

#include <vector>

namespace ib {

class BoundarySmoothing
{
public:
    struct Param
    {
        int iterations = 4;         ///< passes of collinearity moves (paper: 4 to 6)
        int newton_steps = 2;       ///< projection steps onto the implicit surface (0 = off)
        double cell_size = 0;       ///< lattice cell: a projection moves a vertex by at most one
    };

    /// Smooths the `loops` of `mesh` in place. f may be null (no projection).
    static void Compute(CoreMesh& mesh, const std::vector<BoundaryLoop>& loops, const ImplicitFunction* f, const Param& p)
    {
        const std::vector<int> uses = BoundaryLoops::Uses(mesh, loops);
        std::vector<int> moved;
        for (size_t v = 0; v < uses.size(); ++v)
            if (uses[v] == 1)
                moved.push_back(int(v));
        if (moved.empty() || p.iterations <= 0)
            return;

        std::vector<Eigen::Vector3d> start(moved.size());
        for (size_t i = 0; i < moved.size(); ++i)
            start[i] = PositionOf(mesh, moved[i]);

        for (int it = 0; it < p.iterations; ++it)
            for (const auto& loop : loops) {
                const size_t n = loop.vertices.size();
                for (size_t i = 0; i < n && n >= 3; ++i) {
                    const int v = loop.vertices[i];
                    if (uses[size_t(v)] != 1)
                        continue;
                    const Eigen::Vector3d a = PositionOf(mesh, loop.vertices[(i + n - 1) % n]);
                    const Eigen::Vector3d b = PositionOf(mesh, loop.vertices[(i + 1) % n]);
                    const Eigen::Vector3d d = b - a;
                    const double t = d.squaredNorm() > 0 ? std::clamp((PositionOf(mesh, v) - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.5;
                    MoveVertex(mesh, v, a + t * d);
                }
            }

        if (f && p.newton_steps > 0 && p.cell_size > 0)
            ImplicitProjection::Compute(mesh, moved, *f, p.newton_steps, p.cell_size);
        FoldGuard::Restore(mesh, moved, start);
    }
};

} // namespace ib
