#pragma once
/// \file boundary_smoothing.h
/// Boundary smoothing (paper §3.3): marching cubes boundaries are jagged because the gate is
/// a cell test. Each vertex of a loop is moved in turn onto the line through its two loop
/// neighbours (the paper's collinearity moves), for a few iterations; unlike the paper, the
/// moved vertices are then projected back onto the implicit surface (a few Newton steps along
/// the function's gradient), and a move that would flip an adjacent face is halved, then
/// dropped, so no fold-over appears next to the boundary.

#include "boundaries.h"
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
        // Vertices on more than one loop position are pinch points: moving them would tear.
        std::vector<int> uses(mesh.vert.size(), 0);
        for (const auto& loop : loops)
            for (int v : loop.vertices)
                ++uses[size_t(v)];
        std::vector<int> moved;
        for (size_t v = 0; v < uses.size(); ++v)
            if (uses[v] == 1)
                moved.push_back(int(v));
        if (moved.empty() || p.iterations <= 0)
            return;

        std::vector<Eigen::Vector3d> start(moved.size());
        for (size_t i = 0; i < moved.size(); ++i)
            start[i] = Position(mesh, moved[i]);

        for (int it = 0; it < p.iterations; ++it)
            for (const auto& loop : loops) {
                const size_t n = loop.vertices.size();
                for (size_t i = 0; i < n && n >= 3; ++i) {
                    const int v = loop.vertices[i];
                    if (uses[size_t(v)] != 1)
                        continue;
                    const Eigen::Vector3d a = Position(mesh, loop.vertices[(i + n - 1) % n]);
                    const Eigen::Vector3d b = Position(mesh, loop.vertices[(i + 1) % n]);
                    const Eigen::Vector3d d = b - a;
                    const double t = d.squaredNorm() > 0 ? std::clamp((Position(mesh, v) - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.5;
                    SetPosition(mesh, v, a + t * d);
                }
            }

        if (f && p.newton_steps > 0 && p.cell_size > 0)
            Project(mesh, moved, *f, p);
        KeepOrientation(mesh, moved, start);
    }

private:
    static Eigen::Vector3d Position(const CoreMesh& m, int v)
    {
        const auto& q = m.vert[size_t(v)].cP();
        return Eigen::Vector3d(q[0], q[1], q[2]);
    }

    static void SetPosition(CoreMesh& m, int v, const Eigen::Vector3d& p)
    {
        m.vert[size_t(v)].P() = vcg::Point3d(p[0], p[1], p[2]);
    }

    /// Newton steps q <- q - f(q) g / |g|^2 with g the central-difference gradient; one batch
    /// evaluation of 7 points per vertex and step.
    static void Project(CoreMesh& mesh, const std::vector<int>& moved, const ImplicitFunction& f, const Param& p)
    {
        const double h = 0.1 * p.cell_size;  // finite-difference step
        Points Q(Eigen::Index(moved.size() * 7), 3);
        Eigen::VectorXd values(Q.rows());
        for (int step = 0; step < p.newton_steps; ++step) {
            for (size_t i = 0; i < moved.size(); ++i) {
                const Eigen::Vector3d q = Position(mesh, moved[i]);
                Q.row(Eigen::Index(7 * i)) = q.transpose();
                for (int a = 0; a < 3; ++a) {
                    Q.row(Eigen::Index(7 * i + 1 + 2 * a)) = (q + h * Eigen::Vector3d::Unit(a)).transpose();
                    Q.row(Eigen::Index(7 * i + 2 + 2 * a)) = (q - h * Eigen::Vector3d::Unit(a)).transpose();
                }
            }
            f.Eval(Q, values);
            for (size_t i = 0; i < moved.size(); ++i) {
                const Eigen::Index b = Eigen::Index(7 * i);
                Eigen::Vector3d g;
                for (int a = 0; a < 3; ++a)
                    g[a] = (values[b + 1 + 2 * a] - values[b + 2 + 2 * a]) / (2 * h);
                if (!(g.squaredNorm() > 0) || !std::isfinite(values[b]))
                    continue;
                Eigen::Vector3d delta = values[b] * g / g.squaredNorm();
                if (delta.norm() > p.cell_size)
                    delta *= p.cell_size / delta.norm();
                SetPosition(mesh, moved[i], Position(mesh, moved[i]) - delta);
            }
        }
    }

    /// Halves (up to three times), then undoes, the move of any vertex next to a face whose
    /// normal turned by more than 90 degrees.
    static void KeepOrientation(CoreMesh& mesh, const std::vector<int>& moved, const std::vector<Eigen::Vector3d>& start)
    {
        std::vector<std::vector<int>> faces(mesh.vert.size());
        for (size_t f = 0; f < mesh.face.size(); ++f)
            for (int i = 0; i < 3; ++i)
                faces[vcg::tri::Index(mesh, mesh.face[f].cV(i))].push_back(int(f));
        std::vector<Eigen::Vector3d> target(moved.size());
        for (size_t i = 0; i < moved.size(); ++i)
            target[i] = Position(mesh, moved[i]);

        // Normals of the faces around moved vertices, before any move.
        for (size_t i = 0; i < moved.size(); ++i)
            SetPosition(mesh, moved[i], start[i]);
        std::vector<std::vector<vcg::Point3d>> before(moved.size());
        for (size_t i = 0; i < moved.size(); ++i)
            for (int f : faces[size_t(moved[i])])
                before[i].push_back(vcg::TriangleNormal(mesh.face[size_t(f)]));
        for (size_t i = 0; i < moved.size(); ++i)
            SetPosition(mesh, moved[i], target[i]);

        for (int attempt = 0; attempt <= 3; ++attempt) {
            bool changed = false;
            for (size_t i = 0; i < moved.size(); ++i) {
                const auto& around = faces[size_t(moved[i])];
                bool flipped = false;
                for (size_t j = 0; j < around.size() && !flipped; ++j)
                    flipped = vcg::TriangleNormal(mesh.face[size_t(around[j])]).dot(before[i][j]) < 0;
                if (!flipped)
                    continue;
                const Eigen::Vector3d p = Position(mesh, moved[i]);
                SetPosition(mesh, moved[i], attempt < 3 ? 0.5 * (p + start[i]) : start[i]);
                changed = true;
            }
            if (!changed)
                break;
        }
    }
};

} // namespace ib
