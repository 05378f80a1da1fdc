#pragma once
/// \file boundaries.h
/// Boundary loops of an extracted surface: the edges used by exactly one face, grouped into
/// connected components (paper §3.3: "each boundary is a connected component"), each traced
/// as one closed vertex cycle following the faces' orientation.

#include "mesh.h"

#include <algorithm>
#include <map>
#include <unordered_map>
#include <vector>

namespace ib {

/// One boundary of the surface.
struct BoundaryLoop
{
    std::vector<int> vertices;  ///< closed cycle of vertex indices (first not repeated at the end)
    double length = 0;          ///< sum of its edge lengths
    int Edges() const { return int(vertices.size()); }
};

class BoundaryLoops
{
public:
    /// Loops of `mesh` (no deleted elements), longest first by edge count, ties by first vertex.
    /// A loop that touches itself or another loop at a vertex is one component and is traced
    /// as one closed walk (Hierholzer), so every boundary edge appears in exactly one loop.
    static std::vector<BoundaryLoop> Compute(const CoreMesh& mesh)
    {
        // Directed half-edges a->b of each face; a boundary edge has no opposite b->a.
        std::unordered_map<uint64_t, int> halfedges;
        auto key = [](uint64_t a, uint64_t b) { return a << 32 | b; };
        for (const auto& f : mesh.face)
            for (int i = 0; i < 3; ++i)
                ++halfedges[key(vcg::tri::Index(mesh, f.cV(i)), vcg::tri::Index(mesh, f.cV((i + 1) % 3)))];

        // Outgoing boundary edges per vertex, sorted for a deterministic walk.
        std::map<int, std::vector<int>> out;
        for (const auto& [k, count] : halfedges) {
            const int a = int(k >> 32), b = int(k & 0xffffffffu);
            if (!halfedges.count(key(uint64_t(b), uint64_t(a))))
                for (int c = 0; c < count; ++c)
                    out[a].push_back(b);
        }
        for (auto& [v, targets] : out)
            std::sort(targets.begin(), targets.end(), std::greater<int>());

        std::vector<BoundaryLoop> loops;
        for (auto& [start, targets] : out) {
            if (targets.empty())
                continue;
            BoundaryLoop loop;
            loop.vertices = Circuit(start, out);
            const size_t n = loop.vertices.size();
            for (size_t i = 0; i < n; ++i)
                loop.length += vcg::Distance(mesh.vert[loop.vertices[i]].cP(), mesh.vert[loop.vertices[(i + 1) % n]].cP());
            loops.push_back(std::move(loop));
        }
        std::stable_sort(loops.begin(), loops.end(),
                         [](const BoundaryLoop& a, const BoundaryLoop& b) { return a.Edges() > b.Edges(); });
        return loops;
    }

private:
    /// Closed walk using every boundary edge reachable from `start`; consumes them from `out`.
    /// Directed boundary edges of an oriented surface enter and leave each vertex equally often,
    /// so such a walk exists.
    static std::vector<int> Circuit(int start, std::map<int, std::vector<int>>& out)
    {
        std::vector<int> stack{start}, circuit;
        while (!stack.empty()) {
            std::vector<int>& targets = out[stack.back()];
            if (targets.empty()) {
                circuit.push_back(stack.back());
                stack.pop_back();
            } else {
                stack.push_back(targets.back());
                targets.pop_back();
            }
        }
        std::reverse(circuit.begin(), circuit.end());
        circuit.pop_back();  // the walk ends where it started
        return circuit;
    }
};

} // namespace ib
