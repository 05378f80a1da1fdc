#pragma once
/// \file boundary_trim.h
/// Peels off the rim of surface that the SODS lets past the last samples. Tangent disks (or
/// the paper's dilation) extend the occupancy beyond a scan's boundary by their radius, and
/// the implicit surface fills that margin; the faces there are farther from every sample than
/// the sampling's own gaps. Starting at the boundary, faces whose centroid is farther from its
/// nearest sample than that sample's `reach` are removed, then their neighbours in turn, so
/// interior gaps (enclosed by supported faces) are never touched.

#include "mesh.h"
#include "parallel.h"
#include "samples.h"

#include <deque>
#include <unordered_map>
#include <vector>

namespace ib {

class BoundaryTrim
{
public:
    /// Among the faces f of `mesh` with inSurface[f], removes (sets inSurface[f] = 0) those
    /// reachable from the boundary through unsupported faces. reach: per sample, the largest
    /// supported distance. Returns the number of faces removed.
    static size_t Compute(const CoreMesh& mesh, const SampleIndex& samples, const Eigen::VectorXd& reach,
                          std::vector<char>& inSurface, int threads = 0)
    {
        const size_t n = mesh.face.size();
        std::vector<char> unsupported(n, 0);
        ParallelFor(n, threads, [&](size_t begin, size_t end, int) {
            SampleIndex::Queue queue;
            for (size_t f = begin; f < end; ++f) {
                if (!inSurface[f])
                    continue;
                const vcg::Point3d c = vcg::Barycenter(mesh.face[f]);
                samples.Nearest(Eigen::Vector3d(c[0], c[1], c[2]), 1, queue);
                unsupported[f] = std::sqrt(queue.getWeight(0)) > reach[queue.getIndex(0)];
            }
        });

        const std::vector<std::array<int, 3>> across = Neighbours(mesh, inSurface);
        std::deque<int> queue;
        for (size_t f = 0; f < n; ++f)
            if (inSurface[f] && unsupported[f] && std::count(across[f].begin(), across[f].end(), -1) > 0)
                queue.push_back(int(f));
        size_t removed = 0;
        while (!queue.empty()) {
            const int f = queue.front();
            queue.pop_front();
            if (!inSurface[size_t(f)] || !unsupported[size_t(f)])
                continue;
            inSurface[size_t(f)] = 0;
            ++removed;
            for (int g : across[size_t(f)])
                if (g >= 0)
                    queue.push_back(g);
        }
        return removed;
    }

private:
    /// Per face in the surface: the surface face across each edge, or -1.
    static std::vector<std::array<int, 3>> Neighbours(const CoreMesh& mesh, const std::vector<char>& inSurface)
    {
        std::unordered_map<uint64_t, int> owner;  // directed half-edge a->b -> face
        auto key = [&](const CoreFace& f, int i) {
            return uint64_t(vcg::tri::Index(mesh, f.cV(i))) << 32 | uint64_t(vcg::tri::Index(mesh, f.cV((i + 1) % 3)));
        };
        auto twin = [](uint64_t k) { return k << 32 | k >> 32; };
        for (size_t f = 0; f < mesh.face.size(); ++f)
            if (inSurface[f])
                for (int i = 0; i < 3; ++i)
                    owner.emplace(key(mesh.face[f], i), int(f));
        std::vector<std::array<int, 3>> across(mesh.face.size(), {-1, -1, -1});
        for (size_t f = 0; f < mesh.face.size(); ++f)
            if (inSurface[f])
                for (int i = 0; i < 3; ++i) {
                    auto it = owner.find(twin(key(mesh.face[f], i)));
                    across[f][size_t(i)] = it == owner.end() ? -1 : it->second;
                }
        return across;
    }
};

} // namespace ib
