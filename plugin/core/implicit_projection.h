#pragma once
/// \file implicit_projection.h
/// Puts moved mesh vertices back onto the zero set of an implicit function, by Newton steps
/// along its gradient (central differences at a tenth of a cell), each step at most a cell.

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
};

} // namespace ib
