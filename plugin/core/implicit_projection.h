#pragma once
/// \file implicit_projection.h
/// Puts points back onto the zero set of an implicit function: moved mesh vertices, by Newton
/// steps along its gradient (central differences at a tenth of a cell), each step at most a
/// cell; samples, along their normals.

#include "implicit/implicit_function.h"
#include "mesh.h"

#include <cmath>
#include <vector>

namespace ib {

class ImplicitProjection
{
public:
    /// `steps` Newton steps q <- q - f(q) g / |g|^2 on the vertices `moved` of `mesh`, g the
    /// central-difference gradient; one batch evaluation of 7 points per vertex and step.
    static void Compute(CoreMesh& mesh, const std::vector<int>& moved, const ImplicitFunction& f, int steps, double cell_size)
    {
        const double h = 0.1 * cell_size;  // finite-difference step
        Points Q(Eigen::Index(moved.size() * 7), 3);
        Eigen::VectorXd values(Q.rows());
        for (int step = 0; step < steps; ++step) {
            for (size_t i = 0; i < moved.size(); ++i) {
                const Eigen::Vector3d q = PositionOf(mesh, moved[i]);
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
                if (delta.norm() > cell_size)
                    delta *= cell_size / delta.norm();
                MoveVertex(mesh, moved[i], PositionOf(mesh, moved[i]) - delta);
            }
        }
    }
    /// The samples P (n×3) moved along their unit normals N (n×3) onto the zero set of f, by
    /// one Newton step (f being close to a signed distance); n×3. A fitted function (the
    /// PU-RBF) passes up to about a spacing away from samples at sharp or noisy spots.
    static Points OntoZeroSet(const Points& P, const Points& N, const ImplicitFunction& f)
    {
        Eigen::VectorXd value(P.rows());
        f.Eval(P, value);
        return (P.array() - N.array().colwise() * value.array()).matrix();
    }
};


} // namespace ib
