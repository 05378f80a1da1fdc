#pragma once
// How close an implicit function is to a known surface (geometry.h's Shape), shared by the
// PU-RBF tests (test_pu_rbf.cpp, test_pu_rbf_robustness.cpp).

#include "geometry.h"

#include <algorithm>
#include <cstdio>

namespace ib::test {

struct Accuracy
{
    double max_abs = 0, mean_abs = 0;        ///< |f| on the true surface, in spacings
    double max_sd_error = 0;                 ///< |f - signed distance| at +-0.5 spacing, in spacings
    int wrong_sign = 0;                      ///< at +-3 spacings
};

/// Evaluates f on the true surface (at Q projected) and offset along the true normals.
inline Accuracy Measure(const ImplicitFunction& f, const Points& Q, const Shape& s, double spacing)
{
    const Points S = OnSurface(Q, s);
    Points Nt(S.rows(), 3);
    for (Eigen::Index i = 0; i < S.rows(); ++i)
        Nt.row(i) = s.normal(S.row(i).transpose()).transpose();
    Accuracy a;
    Eigen::VectorXd v(S.rows());
    f.Eval(S, v);
    a.max_abs = v.cwiseAbs().maxCoeff() / spacing;
    a.mean_abs = v.cwiseAbs().mean() / spacing;
    for (double offset : {-3.0, 3.0}) {
        f.Eval(Points(S + offset * spacing * Nt), v);
        for (Eigen::Index i = 0; i < v.size(); ++i)
            a.wrong_sign += (v[i] > 0) != (offset > 0);
    }
    for (double offset : {-0.5, 0.5}) {
        f.Eval(Points(S + offset * spacing * Nt), v);
        a.max_sd_error = std::max(a.max_sd_error, (v.array() - offset * spacing).abs().maxCoeff() / spacing);
    }
    return a;
}

inline bool AllFiniteOnGrid(const ImplicitFunction& f, const Points& P)
{
    const Points G = GridAround(P, 40);
    Eigen::VectorXd v(G.rows());
    f.Eval(G, v);
    return v.allFinite();
}

inline void Print(const char* what, const Accuracy& a)
{
    std::printf("[ PU-RBF   ] %-28s |f| on surface: max %.4f mean %.5f spacings; |f - sd| at 0.5 spacing: max %.4f; wrong signs at 3 spacings: %d\n",
                what, a.max_abs, a.mean_abs, a.max_sd_error, a.wrong_sign);
}

} // namespace ib::test
