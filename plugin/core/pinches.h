#pragma once
/// \file pinches.h
/// Pinch vertices: where two fans of surface faces meet at a single vertex (cells gated
/// diagonally, a trim meeting itself), the surface is not a 2-manifold and the boundary touches
/// itself. The smaller fans at such a vertex are moved out of the surface (into the holes, so
/// surface + holes stays closed), until none is left.

#include "mesh.h"

#include <algorithm>
#include <functional>
#include <numeric>
#include <vector>

namespace ib {

class Pinches
{
public:
    /// Among the faces f of `mesh` with inSurface[f], removes (sets to 0) the smaller fans at
    /// every pinch vertex, repeating while removals create new pinches (at most `passes`).
    /// With `anchor` (faces kept elsewhere, a 2-manifold already, disjoint from inSurface), the
    /// faces of both are grouped into fans first, and at a vertex the anchor touches, only the
    /// fan holding the anchor's faces keeps its faces: the holes layer then stays a 2-manifold
    /// both alone and welded to the surface (a hole fan that touched the surface only at a
    /// vertex, across an opening of the extraction, made the two meet in a bow-tie).
    /// Returns the number of faces removed. Needs the mesh's face-face adjacency.
    static size_t Resolve(const CoreMesh& mesh, std::vector<char>& inSurface, int passes = 8,
                          const std::vector<char>* anchor = nullptr)
    {
        size_t removed = 0;
        for (int pass = 0; pass < passes; ++pass) {
            // Only a vertex on the surface's boundary can join two fans: the surface and the
            // hole faces together are an edge-manifold, so elsewhere one fan goes all around.
            std::vector<int> slot(mesh.vert.size(), -1);
            int candidates = 0;
            for (size_t f = 0; f < mesh.face.size(); ++f)
                for (int i = 0; inSurface[f] && i < 3; ++i) {
                    const size_t across = vcg::tri::Index(mesh, mesh.face[f].cFFp(i));
                    if (across == f || !inSurface[across])
                        for (int k : {i, (i + 1) % 3}) {
                            int& s = slot[vcg::tri::Index(mesh, mesh.face[f].cV(k))];
                            if (s < 0)
                                s = candidates++;
                        }
                }
            std::vector<std::vector<int>> around(static_cast<size_t>(candidates));
            std::vector<int> vertexOf(static_cast<size_t>(candidates));
            for (size_t f = 0; f < mesh.face.size(); ++f)
                for (int i = 0; i < 3; ++i) {
                    const size_t v = vcg::tri::Index(mesh, mesh.face[f].cV(i));
                    if (slot[v] >= 0) {
                        around[size_t(slot[v])].push_back(int(f));
                        vertexOf[size_t(slot[v])] = int(v);
                    }
                }
            size_t now = 0;
            for (size_t c = 0; c < around.size(); ++c) {
                if (anchor)
                    now += RemoveFansOffAnchor(mesh, vertexOf[c], around[c], inSurface, *anchor);
                now += RemoveSmallerFans(mesh, vertexOf[c], around[c], inSurface);
            }
            removed += now;
            if (now == 0)
                break;
        }
        return removed;
    }

private:
    /// Groups the faces around vertex v that `in` holds into fans (faces sharing an edge
    /// through v). Returns the faces and, per face, a representative of its fan.
    static std::pair<std::vector<int>, std::vector<int>> Fans(const CoreMesh& mesh, int v, const std::vector<int>& faces,
                                                               const std::function<bool(int)>& in)
    {
        std::vector<int> local;
        for (int f : faces)
            if (in(f))
                local.push_back(f);
        std::vector<int> parent(local.size());
        std::iota(parent.begin(), parent.end(), 0);
        auto find = [&](int i) {
            while (parent[size_t(i)] != i)
                i = parent[size_t(i)] = parent[size_t(parent[size_t(i)])];
            return i;
        };
        for (size_t a = 0; a < local.size(); ++a)
            for (size_t b = a + 1; b < local.size(); ++b)
                if (SharedEdgeThrough(mesh, v, local[a], local[b]))
                    parent[size_t(find(int(a)))] = find(int(b));
        std::vector<int> fan(local.size());
        for (size_t i = 0; i < local.size(); ++i)
            fan[i] = find(int(i));
        return {local, fan};
    }

    /// Keeps the largest fan of inSurface faces around vertex v, removes the others. Returns
    /// the faces removed.
    static size_t RemoveSmallerFans(const CoreMesh& mesh, int v, const std::vector<int>& faces, std::vector<char>& inSurface)
    {
        const auto [local, fan] = Fans(mesh, v, faces, [&](int f) { return inSurface[size_t(f)] != 0; });
        if (local.size() < 2)
            return 0;
        std::vector<int> size(local.size(), 0);
        for (int f : fan)
            ++size[size_t(f)];
        const int keep = int(std::max_element(size.begin(), size.end()) - size.begin());
        size_t removed = 0;
        for (size_t i = 0; i < local.size(); ++i)
            if (fan[i] != keep) {
                inSurface[size_t(local[i])] = 0;
                ++removed;
            }
        return removed;
    }

    /// Around vertex v, groups the faces of inSurface and anchor together into fans; when the
    /// anchor has faces there, removes the inSurface faces of every fan without one.
    static size_t RemoveFansOffAnchor(const CoreMesh& mesh, int v, const std::vector<int>& faces,
                                      std::vector<char>& inSurface, const std::vector<char>& anchor)
    {
        const auto [local, fan] =
            Fans(mesh, v, faces, [&](int f) { return inSurface[size_t(f)] != 0 || anchor[size_t(f)] != 0; });
        std::vector<char> anchored(local.size(), 0);
        for (size_t i = 0; i < local.size(); ++i)
            if (anchor[size_t(local[i])])
                anchored[size_t(fan[i])] = 1;
        if (std::find(anchored.begin(), anchored.end(), 1) == anchored.end())
            return 0;
        size_t removed = 0;
        for (size_t i = 0; i < local.size(); ++i)
            if (!anchored[size_t(fan[i])] && inSurface[size_t(local[i])]) {
                inSurface[size_t(local[i])] = 0;
                ++removed;
            }
        return removed;
    }

    static bool SharedEdgeThrough(const CoreMesh& mesh, int v, int fa, int fb)
    {
        for (int i = 0; i < 3; ++i) {
            const int w = int(vcg::tri::Index(mesh, mesh.face[size_t(fa)].cV(i)));
            if (w == v)
                continue;
            for (int j = 0; j < 3; ++j)
                if (int(vcg::tri::Index(mesh, mesh.face[size_t(fb)].cV(j))) == w)
                    return true;
        }
        return false;
    }
};

} // namespace ib
