#pragma once
/// \file implicit_function.h
/// The one interface every implicit function implements: batch evaluation.
///
/// Sign convention (used everywhere in this project): negative inside, positive outside,
/// i.e. the function grows along the outward normals of the samples; near the surface its
/// value is close to the signed distance. Marching cubes orients output faces so that their
/// normals point to the positive side, hence along the input normals.

#include "../lattice.h"

namespace ib {

class ImplicitFunction
{
public:
    virtual ~ImplicitFunction() = default;

    /// Evaluates the function at the m×3 query points Q into `values` (length m).
    /// Must be safe to call from several threads at once on disjoint outputs.
    virtual void Eval(const Points& Q, Eigen::Ref<Eigen::VectorXd> values) const = 0;
};

} // namespace ib
