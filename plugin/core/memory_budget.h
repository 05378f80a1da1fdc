#pragma once
/// \file memory_budget.h
/// How much memory a reconstruction may use, and how much an extraction will need, so that a
/// run that cannot fit is refused with a message instead of being killed mid-way (which, in
/// MeshLab, loses the user's unsaved work).

#include "input_check.h"

#include <iomanip>
#include <sstream>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <unistd.h>

namespace ib {

struct MemoryBudget
{
    /// The peak growth of a run is modelled as kBytesFixed + kBytesPerSample × samples +
    /// kBytesPerSodsCell × SODS cells, fitted to peaks measured through pymeshlab (the process's
    /// resident size before the call, with the point layer loaded, against its peak during the
    /// call; `bench/large_scan.py`, random samples of a smooth open surface at the automatic
    /// resolution): 100k, 1M, 5M, 10M and 20M samples with 0.59M to 3.9M cells, peaks 0.20 to
    /// 7.6 GB. The estimate lies 1% to 15% above each measured peak (BENCHMARKS.md): the
    /// smallest per-sample term that is never below one, with the per-cell term that then keeps
    /// the largest excess smallest.
    ///
    /// Per SODS cell: corner values and welded edge vertices (hash maps), the extracted
    /// vertices and faces with adjacency, and the host's copy of the result.
    static constexpr double kBytesPerSodsCell = 270;
    /// Per input sample, held while the surface is extracted: the input and its distinct,
    /// outlier-free copy, normals, the shared k-d tree (the PU-RBF's too), local spacings, the
    /// points projected onto the zero set and the PU-RBF's octree and local fits (one per 20 to
    /// 60 samples; the PU-RBF stage grows the process by about 1 GB of the 2.7 GB peak at 5M).
    static constexpr double kBytesPerSample = 380;
    /// Per face of an input mesh (mesh_holes.h): its copy with adjacency and normals, its share
    /// of the vertices' copy and VCGlib's grid over the faces.
    static constexpr double kBytesPerInputFace = 150;
    /// Thread stacks, the allocator's arenas, small tables.
    static constexpr double kBytesFixed = 30e6;

    /// Half the physical memory: room for the host application and its other layers.
    static double Default()
    {
        const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
        return pages > 0 && page > 0 ? 0.5 * double(pages) * double(page) : 4e9;
    }

    /// Estimated peak bytes of a run over `samples` input samples (and the `faces` of an input
    /// mesh) and an extraction over `sodsCells` cells, plus a dense array of `denseCorners`
    /// values (0 for the SODS-driven extraction). The host's own copy of the layer is not counted: it exists before the run.
    static double PeakBytes(double samples, double sodsCells, double denseCorners, double faces = 0)
    {
        return kBytesFixed + kBytesPerSample * samples + kBytesPerSodsCell * sodsCells + 8.0 * denseCorners +
               kBytesPerInputFace * faces;
    }
    /// Refuses, before allocating, a run at `resolution` whose estimated peak (PeakBytes over
    /// `samples` and `faces`, and `sodsCells` or, for a `dense` extraction, the lattice's `denseCorners`)
    /// exceeds `limit` bytes: throws InputError with what to change. Returns the estimate.
    static double Check(double samples, double sodsCells, bool dense, double denseCorners, double limit,
                        int resolution, double faces = 0)
    {
        const double bytes = PeakBytes(samples, sodsCells, dense ? denseCorners : 0, faces);
        if (bytes <= limit)
            return bytes;
        const double sampleBytes = PeakBytes(samples, 0, 0, faces);
        std::ostringstream msg;
        msg.precision(2);
        msg << std::fixed << "Resolution " << resolution << " would need about " << bytes / 1e9
            << " GB of memory (" << std::setprecision(0) << samples << " samples, "
            << (dense ? denseCorners : sodsCells) << (dense ? " lattice corners)" : " occupied cells)")
            << std::setprecision(2) << ", over the limit of " << limit / 1e9 << " GB: ";
        if (sampleBytes > limit)  // no lattice, however coarse, would fit
            msg << "the samples alone need about " << sampleBytes / 1e9
                << " GB; thin them out (e.g. Poisson-disk sampling) or raise the memory limit.";
        else
            msg << "lower the resolution (0 = automatic)" << (dense ? ", use the SODS-driven extraction" : "")
                << " or raise the memory limit.";
        throw InputError(msg.str());
    }

    /// Hands memory freed by the last stage back to the system. Millions of small hash map
    /// nodes, once freed, stay in the allocator's heap and count towards the process's peak
    /// when the next stage (or the host's copy of the result) allocates large blocks.
    static void ReleaseFreed()
    {
#ifdef __GLIBC__
        malloc_trim(0);
#endif
    }
};

} // namespace ib
