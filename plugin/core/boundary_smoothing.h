#pragma once
/// \file boundary_smoothing.h
/// Boundary smoothing (paper §3.3): marching cubes boundaries are jagged because the gate is
/// a cell test. Each vertex of a loop is moved in turn onto the line through its two loop
/// neighbours (the paper's collinearity moves), for a few iterations; unlike the paper, the
/// moved vertices are then projected back onto the implicit surface (a few Newton steps along
/// the function's gradient), and a move that would flip an adjacent face is pulled back
/// (fold_guard.h), so no fold-over appears next to the boundary.
///
/// A sweep that moves each vertex after the one before it depends on where it starts. Loops
/// are therefore swept in runs that start at anchors, vertices picked by a hash of their
/// position on the lattice; a run's first vertex takes the vertex before it as the pass found
/// it. A vertex's result then depends on the loop near it only, not on where the loop was
/// entered, so a tile of a tiled run, which enters a loop elsewhere or sees it cut at its
/// halo, smooths the vertices of its block as one run does.

#include "boundaries.h"
#include "fold_guard.h"
#include "implicit_projection.h"
#include "implicit/implicit_function.h"
#include "mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
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

        std::vector<std::vector<char>> anchor(loops.size());
        for (size_t l = 0; l < loops.size(); ++l)
            anchor[l] = Anchors(mesh, loops[l], p.cell_size);
        for (int it = 0; it < p.iterations; ++it)
            for (size_t l = 0; l < loops.size(); ++l) {
                const std::vector<int>& loop = loops[l].vertices;
                const size_t n = loop.size();
                if (n < 3)
                    continue;
                const size_t first = size_t(std::find(anchor[l].begin(), anchor[l].end(), 1) - anchor[l].begin());
                // The vertices before and after a run's first vertex, as the pass found them.
                Eigen::Vector3d previous = PositionOf(mesh, loop[(first + n - 1) % n]);
                const Eigen::Vector3d firstFound = PositionOf(mesh, loop[first]);
                for (size_t k = 0; k < n; ++k) {
                    const size_t i = (first + k) % n;
                    const int v = loop[i];
                    const Eigen::Vector3d a = anchor[l][i] ? previous : PositionOf(mesh, loop[(i + n - 1) % n]);
                    previous = PositionOf(mesh, v);
                    if (uses[size_t(v)] != 1)
                        continue;
                    const size_t next = (i + 1) % n;
                    const Eigen::Vector3d d = (next == first ? firstFound : PositionOf(mesh, loop[next])) - a;
                    const double t = d.squaredNorm() > 0 ? std::clamp((previous - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.5;
                    MoveVertex(mesh, v, a + t * d);
                }
            }

        if (f && p.newton_steps > 0 && p.cell_size > 0)
            ImplicitProjection::Compute(mesh, moved, *f, p.newton_steps, p.cell_size);
        FoldGuard::Restore(mesh, moved, start);
    }

private:
    /// About one loop vertex in kRun starts a run: few enough that the sweep runs on as it
    /// would from one start, enough that every loop longer than a few dozen vertices has some.
    static constexpr uint64_t kRun = 64;

    /// Per vertex of `loop`: 1 where a run starts, from a hash of the vertex's position rounded
    /// to 1/64 cell (so from the lattice, not from the loop's order); a loop with no such
    /// vertex gets one run, from its vertex of least hash.
    static std::vector<char> Anchors(const CoreMesh& mesh, const BoundaryLoop& loop, double cell)
    {
        const size_t n = loop.vertices.size();
        std::vector<char> anchor(n, 0);
        std::vector<uint64_t> hash(n);
        const double scale = cell > 0 ? 64 / cell : 1;
        for (size_t i = 0; i < n; ++i) {
            const Eigen::Vector3d q = PositionOf(mesh, loop.vertices[i]) * scale;
            uint64_t h = 0;
            for (int a = 0; a < 3; ++a) {  // splitmix64's finaliser on each coordinate in turn
                h ^= uint64_t(std::llround(q[a])) + 0x9e3779b97f4a7c15ull;
                h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ull;
                h = (h ^ (h >> 27)) * 0x94d049bb133111ebull;
                h ^= h >> 31;
            }
            hash[i] = h;
            anchor[i] = char(h % kRun == 0);
        }
        if (n && std::find(anchor.begin(), anchor.end(), 1) == anchor.end())
            anchor[size_t(std::min_element(hash.begin(), hash.end()) - hash.begin())] = 1;
        return anchor;
    }
};

} // namespace ib
