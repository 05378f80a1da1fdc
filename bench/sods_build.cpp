// Times the tangent-disk SODS build on 1,000,000 samples of a unit sphere, with 1 and 2
// threads, at the automatic resolution's cell (0.6 spacings) and at resolutions 512 and 1024.
// Built with -DIB_BUILD_BENCH=ON; prints a Markdown table (BENCHMARKS.md).
#include "sods.h"

#include <chrono>
#include <cstdio>

using namespace ib;

int main()
{
    const int n = 1000000;
    Points P(n, 3), N(n, 3);
    const double golden = M_PI * (3 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {
        const double z = 1 - 2 * (i + 0.5) / n, r = std::sqrt(1 - z * z), phi = golden * i;
        P.row(i) << r * std::cos(phi), r * std::sin(phi), z;
        N.row(i) = P.row(i);
    }
    const double spacing = std::sqrt(4 * M_PI / n);
    std::printf("| resolution | threads | SODS cells | seconds | seconds per million samples |\n|---|---|---|---|---|\n");
    for (int resolution : {int(2 / (0.6 * spacing)), 512, 1024}) {
        const Lattice l = Lattice::Fit(Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1), resolution, 4);
        const Eigen::VectorXd radius = Eigen::VectorXd::Constant(n, 1.25 * spacing);
        for (int threads : {1, 2}) {
            const auto t0 = std::chrono::steady_clock::now();
            const Sods s = Sods::FromDisks(l, P, N, radius, 0.25 * l.cell_size, threads);
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            std::printf("| %d | %d | %zu | %.2f | %.2f |\n", resolution, threads, s.Count(), seconds, seconds * 1e6 / n);
        }
    }
}
