#pragma once
/// \file input_check.h
/// What the samples must be before anything is fitted to them, checked up front so that bad
/// input gets a message that says what is wrong and what to do, never a crash: at least
/// kMinPoints finite samples spread in two directions, one normal per sample (or none).

#include "lattice.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

namespace ib {

/// Bad input or parameters; what() is meant for the user.
class InputError : public std::runtime_error
{
public:
    using std::runtime_error::runtime_error;
};

struct InputCheck
{
    static constexpr int kMinPoints = 10;  ///< fewer samples cannot define tangent planes

    /// Throws InputError unless P (n×3) holds at least kMinPoints finite samples, not all at one
    /// position or on one line; N (normals), `facing` (directions per sample) and `scanSizes`
    /// (rows per scan) are each empty or match P's rows.
    static void Samples(const Points& P, const Points& N, const Points& facing,
                        const std::vector<Eigen::Index>& scanSizes)
    {
        if (P.rows() == 0)
            throw InputError("The layer has no vertices: select a point cloud or mesh layer with at least " +
                             std::to_string(kMinPoints) + " vertices.");
        if (P.rows() < kMinPoints)
            throw InputError("The layer has only " + std::to_string(P.rows()) + " vertices; at least " +
                             std::to_string(kMinPoints) + " samples are needed to fit tangent planes.");
        const Eigen::Index bad = (!P.array().isFinite()).rowwise().any().count();
        if (bad > 0)
            throw InputError(std::to_string(bad) + " of " + std::to_string(P.rows()) +
                             " vertices have NaN or infinite coordinates: remove them first "
                             "(e.g. Filters > Cleaning and Repairing > Remove Duplicate and Unreferenced Vertices, "
                             "or select them with Conditional Vertex Selection and delete).");
        const Eigen::Vector3d extent = (P.colwise().maxCoeff() - P.colwise().minCoeff()).transpose();
        if (!(extent.maxCoeff() > 0))
            throw InputError("All vertices are at the same position: there is no surface to reconstruct.");
        // Second principal extent: zero when every sample lies on one line (a flat scan is fine).
        const Points centred = P.rowwise() - P.colwise().mean();
        const Eigen::Vector3d spread =
            Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(centred.transpose() * centred).eigenvalues();  // ascending
        if (!(spread[1] > 1e-12 * spread[2]))  // second extent under a millionth of the first
            throw InputError("All vertices lie on one line: a surface needs samples spread in two directions.");
        if (facing.rows() != 0 && facing.rows() != P.rows())
            throw InputError("The facing directions have " + std::to_string(facing.rows()) + " rows for " +
                             std::to_string(P.rows()) + " samples.");
        if (N.rows() != 0 && N.rows() != P.rows())
            throw InputError("There must be one normal per vertex.");
        if (!scanSizes.empty() && std::accumulate(scanSizes.begin(), scanSizes.end(), Eigen::Index(0)) != P.rows())
            throw InputError("The scans' sizes must add up to the number of vertices.");
    }

    /// Throws InputError unless every index of the m×3 faces F is a row of P.
    static void FacesOf(const Points& P, const Faces& F)
    {
        const Eigen::Index bad = ((F.array() < 0) || (F.array() >= P.rows())).rowwise().any().count();
        if (bad > 0)
            throw InputError(std::to_string(bad) + " of " + std::to_string(F.rows()) + " faces refer to vertices " +
                             "the layer does not have.");
    }

    /// Indices of the rows of P, in order, skipping rows equal to an earlier one.
    static std::vector<Eigen::Index> DistinctRows(const Points& P)
    {
        std::vector<Eigen::Index> order(size_t(P.rows()));
        std::iota(order.begin(), order.end(), Eigen::Index(0));
        auto less = [&](Eigen::Index a, Eigen::Index b) {
            for (int c = 0; c < 3; ++c)
                if (P(a, c) != P(b, c))
                    return P(a, c) < P(b, c);
            return a < b;
        };
        std::sort(order.begin(), order.end(), less);
        std::vector<char> keep(size_t(P.rows()), 1);
        for (size_t i = 1; i < order.size(); ++i)
            if (P.row(order[i]) == P.row(order[i - 1]))
                keep[size_t(order[i])] = 0;
        std::vector<Eigen::Index> kept;
        for (Eigen::Index i = 0; i < P.rows(); ++i)
            if (keep[size_t(i)])
                kept.push_back(i);
        return kept;
    }

    /// True when N holds a usable normal for every sample; false when it holds none at all
    /// (no rows, or all zero: what a point cloud without normals gets in MeshLab).
    static bool HasNormals(const Points& N)
    {
        return N.rows() > 0 && (N.rowwise().squaredNorm().array() > 0).any();
    }
};

} // namespace ib
