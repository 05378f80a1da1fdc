#pragma once
// Generated test geometry with known surfaces, and mesh checks shared by the tests.

#include "lattice.h"
#include "mesh.h"
#include "sods.h"
#include "implicit/implicit_function.h"

#include <vcg/complex/algorithms/clean.h>
#include <vcg/complex/algorithms/create/platonic.h>
#include <vcg/complex/algorithms/update/topology.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
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

/// The vertex positions V (n×3) and faces F (m×3 rows of V) of m.
inline void Matrices(const CoreMesh& m, Points& V, Faces& F)
{
    V.resize(Eigen::Index(m.vert.size()), 3);
    for (size_t i = 0; i < m.vert.size(); ++i)
        V.row(Eigen::Index(i)) << m.vert[i].cP()[0], m.vert[i].cP()[1], m.vert[i].cP()[2];
    F.resize(Eigen::Index(m.face.size()), 3);
    for (size_t i = 0; i < m.face.size(); ++i)
        for (int k = 0; k < 3; ++k)
            F(Eigen::Index(i), k) = int(vcg::tri::Index(m, m.face[i].cV(k)));
}

/// The unit square [0, 1]^2 in z = 0 as two triangles, counter-clockwise seen from +z.
inline void UnitSquare(Points& V, Faces& F)
{
    V.resize(4, 3);
    V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
    F.resize(2, 3);
    F << 0, 1, 2, 0, 2, 3;
}

/// An icosphere of radius 1 (VCGlib's, subdivided `levels` times: 4 gives 2562 vertices and
/// 5120 faces), outward-oriented.
inline void Icosphere(Points& V, Faces& F, int levels = 4)
{
    CoreMesh m;
    vcg::tri::Sphere(m, levels);
    Matrices(m, V, F);
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

/// Torus around the z axis (tube centre radius R, tube radius r): samples about uniform in
/// area (rings around the tube get points in proportion to their length), outward normals.
inline void TorusPoints(int rings, double R, double r, Points& P, Points& N)
{
    std::vector<Eigen::Vector3d> ps, ns;
    const int around = int(std::lround(rings * R / r));  // points on the ring of radius R
    for (int j = 0; j < rings; ++j) {
        const double v = 2 * M_PI * (j + 0.5) / rings;
        const int count = std::max(3, int(std::lround(around * (R + r * std::cos(v)) / R)));
        for (int i = 0; i < count; ++i) {
            const double u = 2 * M_PI * (i + 0.37 * j) / count;
            const Eigen::Vector3d n(std::cos(v) * std::cos(u), std::cos(v) * std::sin(u), std::sin(v));
            ps.push_back(Eigen::Vector3d(R * std::cos(u), R * std::sin(u), 0) + r * n);
            ns.push_back(n);
        }
    }
    P.resize(Eigen::Index(ps.size()), 3);
    N.resize(Eigen::Index(ps.size()), 3);
    for (size_t i = 0; i < ps.size(); ++i) {
        P.row(Eigen::Index(i)) = ps[i].transpose();
        N.row(Eigen::Index(i)) = ns[i].transpose();
    }
}

/// A known surface: exact signed distance, and its closest point and normal.
struct Shape
{
    std::function<double(const Eigen::Vector3d&)> distance;
    std::function<Eigen::Vector3d(const Eigen::Vector3d&)> normal;  // of the closest surface point
};

inline Shape Sphere(double radius)
{
    return {[=](const Eigen::Vector3d& x) { return x.norm() - radius; },
            [](const Eigen::Vector3d& x) { return x.normalized(); }};
}

inline Shape Torus(double R, double r)
{
    auto axis = [=](const Eigen::Vector3d& x) {  // closest point on the tube's centre circle
        const Eigen::Vector2d d = x.head<2>().normalized();
        return Eigen::Vector3d(R * d[0], R * d[1], 0);
    };
    return {[=](const Eigen::Vector3d& x) { return (x - axis(x)).norm() - r; },
            [=](const Eigen::Vector3d& x) { return (x - axis(x)).normalized(); }};
}

/// Gaussian noise on the positions with RMS displacement `rms` (deterministic).
inline void AddNoise(Points& P, double rms, unsigned seed = 7)
{
    std::mt19937 rng(seed);
    std::normal_distribution<double> g(0, rms / std::sqrt(3.0));
    for (Eigen::Index i = 0; i < P.rows(); ++i)
        for (int a = 0; a < 3; ++a)
            P(i, a) += g(rng);
}

inline double Diagonal(const Points& P) { return (P.colwise().maxCoeff() - P.colwise().minCoeff()).norm(); }

/// Points on the true surface that are not the samples: the samples of a denser set moved by
/// the shape's own projection.
inline Points OnSurface(const Points& Q, const Shape& s)
{
    Points S = Q;
    for (Eigen::Index i = 0; i < S.rows(); ++i) {
        const Eigen::Vector3d x = S.row(i).transpose();
        S.row(i) = (x - s.distance(x) * s.normal(x)).transpose();
    }
    return S;
}

/// A regular grid of m^3 points covering the samples' bounding box scaled by 2 about its centre.
inline Points GridAround(const Points& P, int m)
{
    const Eigen::Vector3d lo = P.colwise().minCoeff(), hi = P.colwise().maxCoeff();
    const Eigen::Vector3d c = 0.5 * (lo + hi), ext = (hi - lo).cwiseMax(1e-3 * (hi - lo).maxCoeff());
    Points G(Eigen::Index(m) * m * m, 3);
    Eigen::Index k = 0;
    for (int z = 0; z < m; ++z)
        for (int y = 0; y < m; ++y)
            for (int x = 0; x < m; ++x)
                G.row(k++) = (c + ext.cwiseProduct(Eigen::Vector3d(x, y, z) / (m - 1) * 2 - Eigen::Vector3d::Ones()))
                                 .transpose();
    return G;
}

} // namespace ib::test
