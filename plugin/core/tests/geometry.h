#pragma once
// Generated test geometry with known surfaces, and mesh checks shared by the tests.

#include "lattice.h"
#include "mesh.h"
#include "sods.h"
#include "implicit/implicit_function.h"

#include <vcg/complex/algorithms/clean.h>
#include <vcg/complex/algorithms/update/topology.h>

#include <cmath>

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
