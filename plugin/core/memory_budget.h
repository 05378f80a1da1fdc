#pragma once
/// \file memory_budget.h
/// How much memory a reconstruction may use, and how much an extraction will need, so that a
/// run that cannot fit is refused with a message instead of being killed mid-way (which, in
/// MeshLab, loses the user's unsaved work).

#include <unistd.h>

namespace ib {

struct MemoryBudget
{
    /// The peak growth of a run is modelled as kBytesFixed + kBytesPerSample × samples +
    /// kBytesPerSodsCell × SODS cells, fitted to peaks measured through pymeshlab (the process's
    /// peak resident size over its size with the point layer loaded; `bench/large_scan.py`,
    /// random samples of a smooth open surface at the automatic resolution): 100k, 1M, 5M, 10M
    /// and 20M samples with 0.59M to 3.9M cells, peaks 0.20 to 4.1 GB. The estimate lies 2% to
    /// 13% above each measured peak (BENCHMARKS.md).
    ///
    /// Per SODS cell: corner values and welded edge vertices (hash maps), the extracted
    /// vertices and faces with adjacency, and the host's copy of the result.
    static constexpr double kBytesPerSodsCell = 300;
    /// Per input sample, held while the surface is extracted: the input and its distinct,
    /// outlier-free copy, normals, the shared k-d tree, local spacings, the points projected
    /// onto the zero set and the PU-RBF's octree and local fits.
    static constexpr double kBytesPerSample = 165;
    /// Thread stacks, the allocator's arenas, small tables.
    static constexpr double kBytesFixed = 30e6;

    /// Half the physical memory: room for the host application and its other layers.
    static double Default()
    {
        const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
        return pages > 0 && page > 0 ? 0.5 * double(pages) * double(page) : 4e9;
    }

    /// Estimated peak bytes of a run over `samples` input samples and an extraction over
    /// `sodsCells` cells, plus a dense array of `denseCorners` values (0 for the SODS-driven
    /// extraction). The host's own copy of the layer is not counted: it exists before the run.
    static double PeakBytes(double samples, double sodsCells, double denseCorners)
    {
        return kBytesFixed + kBytesPerSample * samples + kBytesPerSodsCell * sodsCells + 8.0 * denseCorners;
    }
};

} // namespace ib
