// Prints the PU-RBF's fit and evaluation cost next to HoppeDistance's, on ~36k samples of a
// noisy torus, with 1 and 2 threads, for the benchmark notes (was the unit test
// PuRbf.SpeedReport). Built with -DIB_BUILD_BENCH=ON; run: build/pu_rbf_speed
#include "../plugin/core/tests/geometry.h"
#include "implicit/hoppe.h"
#include "implicit/pu_rbf.h"

#include <chrono>
#include <cstdio>

using namespace ib;
using test::AddNoise;
using test::GridAround;
using test::OnSurface;
using test::Torus;
using test::TorusPoints;

int main()
{
    Points P, N;
    TorusPoints(112, 1.0, 0.35, P, N);  // ~36k samples
    AddNoise(P, 0.001);
    using Clock = std::chrono::steady_clock;
    auto seconds = [](Clock::time_point a) { return std::chrono::duration<double>(Clock::now() - a).count(); };
    // Queries: a shell of lattice corners near the surface, as marching cubes would ask.
    Points Q = OnSurface(GridAround(P, 80), Torus(1.0, 0.35));
    Q += 0.02 * Points::Random(Q.rows(), 3);
    Eigen::VectorXd v(Q.rows());
    for (int threads : {1, 2}) {
        PuRbf::Param p;
        p.threads = threads;
        auto t0 = Clock::now();
        const PuRbf f(P, N, p);
        const double fit = seconds(t0);
        t0 = Clock::now();
        f.Eval(Q, v);
        const double eval = seconds(t0);
        if (!v.allFinite()) {
            std::fprintf(stderr, "PU-RBF: non-finite values with %d thread(s)\n", threads);
            return 1;
        }

        t0 = Clock::now();
        const SampleIndex index(P);
        const HoppeDistance h(index, N, 8, threads);
        const double hfit = seconds(t0);
        t0 = Clock::now();
        h.Eval(Q, v);
        const double heval = seconds(t0);
        const auto& s = f.Statistics();
        std::printf("[ PU-RBF   ] %ld samples, %d thread(s): PU-RBF fit %.3f s (%d cells, %.0f centres/cell, %zu of %zu "
                    "off-surface points dropped), eval %.3f us/query (wall); Hoppe index %.3f s, eval %.3f us/query (%ld queries)\n",
                    long(P.rows()), threads, fit, s.cells, double(s.centres) / s.cells, s.off_surface_dropped,
                    s.off_surface_points + s.off_surface_dropped, 1e6 * eval / Q.rows(), hfit, 1e6 * heval / Q.rows(),
                    long(Q.rows()));
    }
    return 0;
}
