#pragma once
// Generated test geometry with known surfaces, and mesh checks shared by the tests.

#include "lattice.h"
#include "mesh.h"
#include "sods.h"
#include "implicit/implicit_function.h"

#include <vcg/complex/algorithms/clean.h>
#include <vcg/complex/algorithms/update/topology.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace ib::test {

/// n samples on the sphere of the given radius around the origin (Fibonacci spiral: uniform,
/// deterministic), with outward normals. Only those with z >= zmin (unit-sphere z) are kept.
inline void SpherePoints(int n, double radius, Points& P, Points& N, double zmin = -2)
{
    std::vector<Eigen::Vector3d> ps, ns;
    const double golden = M_PI * (3 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {
        const double z = 1 - 2 * (i + 0.5) / n, r = std::sqrt(1 - z * z), phi = golden * i;
        const Eigen::Vector3d d(r * std::cos(phi), r * std::sin(phi), z);
        if (z >= zmin) {
            ps.push_back(radius * d);
            ns.push_back(d);
        }
    }
    P.resize(Eigen::Index(ps.size()), 3);
    N.resize(Eigen::Index(ps.size()), 3);
    for (size_t i = 0; i < ps.size(); ++i) {
        P.row(Eigen::Index(i)) = ps[i].transpose();
        N.row(Eigen::Index(i)) = ns[i].transpose();
    }
}

/// A flat square scan: samples on a staggered grid of spacing s over [0, 1]^2 at z = 0.
inline void FlatScan(double s, Points& P, Points& N)
{
    std::vector<Eigen::Vector3d> pts;
    const int n = int(std::round(1 / s));
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i)
            pts.emplace_back(std::min(1.0, (i + 0.5 * (j % 2)) * s), j * s, 0.0);
    P.resize(Eigen::Index(pts.size()), 3);
    N.resize(Eigen::Index(pts.size()), 3);
    for (size_t i = 0; i < pts.size(); ++i) {
        P.row(Eigen::Index(i)) = pts[i].transpose();
        N.row(Eigen::Index(i)) << 0, 0, 1;
    }
}

/// Adds the triangle a, b, c to m (new vertices; weld with Clean::RemoveDuplicateVertex).
inline void AddTriangle(CoreMesh& m, const vcg::Point3d& a, const vcg::Point3d& b, const vcg::Point3d& c)
{
    vcg::tri::Allocator<CoreMesh>::AddFace(m, a, b, c);
}

/// Welds the duplicate vertices of a mesh made of AddTriangle calls, compacts it and builds
/// its face-face adjacency.
inline void Weld(CoreMesh& m)
{
    vcg::tri::Clean<CoreMesh>::RemoveDuplicateVertex(m);
    vcg::tri::Allocator<CoreMesh>::CompactEveryVector(m);
    vcg::tri::UpdateTopology<CoreMesh>::FaceFace(m);
}

/// A flat triangulated grid of n × n squares of side h in the plane z = 0, from the origin,
/// each square split along its diagonal; faces counter-clockwise seen from +z. Vertex (i, j)
/// has index j (n + 1) + i.
inline void Grid(int n, double h, CoreMesh& m)
{
    auto v = vcg::tri::Allocator<CoreMesh>::AddVertices(m, size_t((n + 1) * (n + 1)));
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i, ++v)
            v->P() = vcg::Point3d(i * h, j * h, 0);
    auto at = [&](int i, int j) { return &m.vert[size_t(j * (n + 1) + i)]; };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            vcg::tri::Allocator<CoreMesh>::AddFace(m, at(i, j), at(i + 1, j), at(i + 1, j + 1));
            vcg::tri::Allocator<CoreMesh>::AddFace(m, at(i, j), at(i + 1, j + 1), at(i, j + 1));
        }
    vcg::tri::UpdateTopology<CoreMesh>::FaceFace(m);
}

/// Exact signed distance to a sphere (negative inside).
class SphereDistance : public ImplicitFunction
{
public:
    explicit SphereDistance(double r) : r_(r) {}
    void Eval(const Points& Q, Eigen::Ref<Eigen::VectorXd> values) const override
    {
        values = Q.rowwise().norm().array() - r_;
    }

private:
    double r_;
};

/// A SODS covering every cell of l: gated extraction then equals plain marching cubes.
inline Sods AllCells(const Lattice& l)
{
    Sods s(l.cells);
    for (int z = 0; z < l.cells[2]; ++z)
        for (int y = 0; y < l.cells[1]; ++y)
            for (int x = 0; x < l.cells[0]; ++x)
                s.Insert(Index3(x, y, z));
    return s;
}

struct Topology
{
    int non_manifold_edges = 0, non_manifold_vertices = 0, border_edges = 0;
    bool oriented = false;
};

inline Topology Check(CoreMesh& m)
{
    vcg::tri::UpdateTopology<CoreMesh>::FaceFace(m);
    Topology t;
    t.non_manifold_edges = vcg::tri::Clean<CoreMesh>::CountNonManifoldEdgeFF(m);
    t.non_manifold_vertices = vcg::tri::Clean<CoreMesh>::CountNonManifoldVertexFF(m, false);
    int total = 0, nonManifold = 0;
    vcg::tri::Clean<CoreMesh>::CountEdgeNum(m, total, t.border_edges, nonManifold);
    t.oriented = vcg::tri::Clean<CoreMesh>::IsCoherentlyOrientedMesh(m);
    return t;
}

} // namespace ib::test
