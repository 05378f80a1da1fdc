#pragma once
/// \file boundaries.h
/// Boundary loops of an extracted surface (paper §3.3): edges used by one surface face, each
/// connected component traced as one closed vertex cycle following the faces' orientation.
/// With hole triangles present, a boundary edge is one shared by a surface face and a hole
/// face, and each loop knows the hole faces across it.

#include "mesh.h"
#include "samples.h"

#include <algorithm>
#include <map>
#include <vector>

namespace ib {

/// One boundary of the surface.
struct BoundaryLoop
{
    std::vector<int> vertices;  ///< closed cycle of vertex indices (first not repeated at the end)
    std::vector<int> across;    ///< per edge vertices[i] -> vertices[i+1]: the face beyond it, or -1
    double length = 0;          ///< sum of its edge lengths
    int Edges() const { return int(vertices.size()); }
};

class BoundaryLoops
{
public:
    /// Loops of the faces f of `mesh` with surface[f] != 0 (every face when `surface` is empty),
    /// largest first by edge count. Needs the mesh's face-face adjacency (vcg::tri::
    /// UpdateTopology::FaceFace): an edge is a boundary when the face across it is itself (the
    /// mesh's border) or not in the surface. A loop that touches itself or another loop at a
    /// vertex is one component and is traced as one closed walk (Hierholzer), so every
    /// boundary edge is in exactly one loop.
    static std::vector<BoundaryLoop> Compute(const CoreMesh& mesh, const std::vector<char>& surface = {})
    {
        auto inSurface = [&](size_t f) { return surface.empty() || surface[f]; };
        // Outgoing boundary edges per vertex (target, face across), sorted for a deterministic walk.
        std::map<int, std::vector<std::pair<int, int>>> out;
        for (size_t f = 0; f < mesh.face.size(); ++f) {
            if (!inSurface(f))
                continue;
            const CoreFace& face = mesh.face[f];
            for (int i = 0; i < 3; ++i) {
                const size_t across = vcg::tri::Index(mesh, face.cFFp(i));
                if (across != f && inSurface(across))
                    continue;
                const int a = int(vcg::tri::Index(mesh, face.cV(i)));
                const int b = int(vcg::tri::Index(mesh, face.cV((i + 1) % 3)));
                out[a].emplace_back(b, across == f ? -1 : int(across));
            }
        }
        for (auto& [v, targets] : out)
            std::sort(targets.begin(), targets.end(), std::greater<>());

        std::vector<BoundaryLoop> loops;
        for (auto& [start, targets] : out) {
            if (targets.empty())
                continue;
            BoundaryLoop loop = Circuit(start, out);
            loop.length = Length(mesh, loop);
            loops.push_back(std::move(loop));
        }
        std::stable_sort(loops.begin(), loops.end(),
                         [](const BoundaryLoop& a, const BoundaryLoop& b) { return a.Edges() > b.Edges(); });
        return loops;
    }

    /// Per vertex of `mesh`: how many times the `loops` pass through it. Vertices passed more
    /// than once are pinch points, where moving the vertex would tear the surface.
    static std::vector<int> Uses(const CoreMesh& mesh, const std::vector<BoundaryLoop>& loops)
    {
        std::vector<int> uses(mesh.vert.size(), 0);
        for (const auto& loop : loops)
            for (int v : loop.vertices)
                ++uses[size_t(v)];
        return uses;
    }

    /// The median, over the vertices of `loop` (of `mesh`), of the local spacing (`spacing`,
    /// per sample) of their nearest sample: the sampling's scale around the loop (0 for a loop
    /// without vertices).
    static double SpacingAround(const CoreMesh& mesh, const BoundaryLoop& loop, const SampleIndex& samples,
                                const Eigen::VectorXd& spacing)
    {
        std::vector<double> around;
        SampleIndex::Queue queue;
        for (int v : loop.vertices) {
            samples.Nearest(PositionOf(mesh, v), 1, queue);
            around.push_back(spacing[Eigen::Index(queue.getIndex(0))]);
        }
        if (around.empty())
            return 0;
        std::nth_element(around.begin(), around.begin() + long(around.size() / 2), around.end());
        return around[around.size() / 2];
    }

    /// Sum of the edge lengths of `loop` in `mesh`.
    static double Length(const CoreMesh& mesh, const BoundaryLoop& loop)
    {
        double length = 0;
        const size_t n = loop.vertices.size();
        for (size_t i = 0; i < n; ++i)
            length += vcg::Distance(mesh.vert[size_t(loop.vertices[i])].cP(), mesh.vert[size_t(loop.vertices[(i + 1) % n])].cP());
        return length;
    }

private:
    /// Closed walk using every boundary edge reachable from `start`; consumes them from `out`.
    /// Directed boundary edges of an oriented surface enter and leave each vertex equally often,
    /// so such a walk exists.
    static BoundaryLoop Circuit(int start, std::map<int, std::vector<std::pair<int, int>>>& out)
    {
        std::vector<std::pair<int, int>> stack{{start, -1}}, circuit;  // (vertex, face across the edge into it)
        while (!stack.empty()) {
            auto& targets = out[stack.back().first];
            if (targets.empty()) {
                circuit.push_back(stack.back());
                stack.pop_back();
            } else {
                stack.push_back(targets.back());
                targets.pop_back();
            }
        }
        // circuit is the walk backwards: circuit[i] was entered from circuit[i+1] across circuit[i].second.
        std::reverse(circuit.begin(), circuit.end());
        BoundaryLoop loop;
        for (size_t i = 0; i + 1 < circuit.size(); ++i) {
            loop.vertices.push_back(circuit[i].first);
            loop.across.push_back(circuit[i + 1].second);
        }
        return loop;
    }
};

} // namespace ib
