// PU-RBF against the blended tangent planes (Hoppe) on real scans: how far the zero set passes
// from the samples, and what the whole pipeline makes of it. The scans are not part of the
// project: IB_SCANS lists ASCII files of "x y z nx ny nz" lines (':'-separated); without it
// the test is skipped. Export one from a mesh with e.g. pymeshlab:
//   numpy.savetxt(f, numpy.hstack([m.vertex_matrix(), m.vertex_normal_matrix()]))
// Measurement knobs (PuRbf::Param overrides): IB_RBF_CENTRES, IB_RBF_REG, IB_RBF_OVERLAP,
// IB_RBF_MAX, IB_RBF_MIN, IB_RBF_OFF, IB_RBF_CAP; IB_PIPELINE=1 also runs the whole filter.
// It prints, asserting nothing: the files are not the project's.
#include "geometry.h"
#include "implicit/hoppe.h"
#include "implicit/pu_rbf.h"
#include "reconstruct.h"
#include "spacing.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

using namespace ib;

namespace {

bool LoadXyzn(const std::string& path, Points& P, Points& N)
{
    std::ifstream in(path);
    if (!in)
        return false;
    std::vector<double> v;
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream s(line);
        double x[6];
        if (s >> x[0] >> x[1] >> x[2] >> x[3] >> x[4] >> x[5])
            v.insert(v.end(), x, x + 6);
    }
    const Eigen::Index n = Eigen::Index(v.size() / 6);
    P.resize(n, 3);
    N.resize(n, 3);
    for (Eigen::Index i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a) {
            P(i, a) = v[size_t(6 * i + a)];
            N(i, a) = v[size_t(6 * i + 3 + a)];
        }
    N.rowwise().normalize();
    return n > 0;
}

double Quantile(std::vector<double> x, double q)
{
    if (x.empty())
        return 0;
    const size_t k = std::min(x.size() - 1, size_t(q * double(x.size())));
    std::nth_element(x.begin(), x.begin() + Eigen::Index(k), x.end());
    return x[k];
}

struct Accuracy
{
    double p50 = 0, p99 = 0, max = 0;      ///< |f(p_i)| / local spacing at the samples
    double mid_p99 = 0, mid_max = 0;       ///< |f| / spacing at midpoints to the 6 nearest samples
};

Accuracy Measure(const ImplicitFunction& f, const Points& P, const SampleIndex& index, const Eigen::VectorXd& spacing)
{
    Accuracy a;
    Eigen::VectorXd v(P.rows());
    f.Eval(P, v);
    std::vector<double> r(size_t(P.rows()));
    for (Eigen::Index i = 0; i < P.rows(); ++i)
        r[size_t(i)] = std::abs(v[i]) / spacing[i];
    a.p50 = Quantile(r, 0.5);
    a.p99 = Quantile(r, 0.99);
    a.max = *std::max_element(r.begin(), r.end());
    const int k = 6;
    Points M(P.rows() * k, 3);
    Eigen::VectorXd s(M.rows());
    SampleIndex::Queue queue;
    for (Eigen::Index i = 0; i < P.rows(); ++i) {
        index.Nearest(P.row(i).transpose(), k + 1, queue);
        int j = 0;
        for (int q = 0; q < queue.getNofElements() && j < k; ++q)
            if (queue.getIndex(q) != int(i)) {
                M.row(i * k + j) = 0.5 * (P.row(i) + P.row(queue.getIndex(q)));
                s[i * k + j] = spacing[i];
                ++j;
            }
        for (; j < k; ++j) {
            M.row(i * k + j) = P.row(i);
            s[i * k + j] = spacing[i];
        }
    }
    Eigen::VectorXd w(M.rows());
    f.Eval(M, w);
    std::vector<double> m(size_t(M.rows()));
    for (Eigen::Index i = 0; i < M.rows(); ++i)
        m[size_t(i)] = std::abs(w[i]) / s[i];
    a.mid_p99 = Quantile(m, 0.99);
    a.mid_max = *std::max_element(m.begin(), m.end());
    return a;
}

double EnvDouble(const char* name, double fallback)
{
    const char* v = std::getenv(name);
    return v && *v ? std::atof(v) : fallback;
}

} // namespace

TEST(PuRbfScans, ZeroSetPassesThroughTheSamples)
{
    const char* list = std::getenv("IB_SCANS");
    if (!list || !*list)
        GTEST_SKIP() << "IB_SCANS not set";
    std::stringstream paths(list);
    std::string path;
    while (std::getline(paths, path, ':')) {
        Points P, N;
        if (!LoadXyzn(path, P, N)) {
            std::printf("%s: cannot read\n", path.c_str());
            continue;
        }
        const SampleIndex index(P);
        const Eigen::VectorXd spacing = SampleSpacing::Local(index);
        PuRbf::Param rp;
        rp.max_centres = int(EnvDouble("IB_RBF_CENTRES", rp.max_centres));
        rp.regularization = EnvDouble("IB_RBF_REG", rp.regularization);
        rp.overlap = EnvDouble("IB_RBF_OVERLAP", rp.overlap);
        rp.max_samples = int(EnvDouble("IB_RBF_MAX", rp.max_samples));
        rp.min_samples = int(EnvDouble("IB_RBF_MIN", rp.min_samples));
        rp.off_surface = EnvDouble("IB_RBF_OFF", rp.off_surface);
        rp.max_fit_samples = int(EnvDouble("IB_RBF_CAP", rp.max_fit_samples));
        const PuRbf rbf(P, N, rp);
        const HoppeDistance hoppe(index, N);
        const Accuracy a = Measure(rbf, P, index, spacing), b = Measure(hoppe, P, index, spacing);
        const auto& st = rbf.Statistics();
        std::printf("%s: %lld samples, %d cells, %.1f centres/cell, fit %.3f s, fallbacks %d\n", path.c_str(),
                    (long long)P.rows(), st.cells, double(st.centres) / st.cells, st.fit_seconds, st.solver_fallbacks);
        std::printf("  |f|/spacing  samples p50 %.4f p99 %.4f max %.4f | midpoints p99 %.4f max %.4f  (PU-RBF)\n", a.p50,
                    a.p99, a.max, a.mid_p99, a.mid_max);
        std::printf("  |f|/spacing  samples p50 %.4f p99 %.4f max %.4f | midpoints p99 %.4f max %.4f  (Hoppe)\n", b.p50,
                    b.p99, b.max, b.mid_p99, b.mid_max);
        if (EnvDouble("IB_PIPELINE", 0) == 0)
            continue;
        for (auto implicit : {Reconstruction::Implicit::PuRbf, Reconstruction::Implicit::Hoppe}) {
            Reconstruction::Param p;
            p.implicit = implicit;
            p.rbf = rp;
            CoreMesh m;
            const auto r = Reconstruction::Compute(P, N, p, m);
            std::vector<double> d;
            SampleIndex::Queue queue;
            for (const auto& vx : m.vert) {
                index.Nearest(Eigen::Vector3d(vx.cP()[0], vx.cP()[1], vx.cP()[2]), 1, queue);
                d.push_back(std::sqrt(queue.getWeight(0)) / r.sample_spacing);
            }
            const auto t = test::Check(m);
            std::string loops;
            for (const auto& l : r.loops)
                loops += " " + std::to_string(l.Edges());
            std::printf("  pipeline %s: %zu faces, loops [%s ], non-manifold edges %d, vertex-sample distance p99 "
                        "%.3f max %.3f spacings, implicit %.2f s\n",
                        implicit == Reconstruction::Implicit::PuRbf ? "PU-RBF" : "Hoppe ", m.face.size(),
                        loops.c_str(), t.non_manifold_edges, Quantile(d, 0.99),
                        d.empty() ? 0.0 : *std::max_element(d.begin(), d.end()), r.seconds_implicit);
        }
    }
}
