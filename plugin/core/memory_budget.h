#pragma once
/// \file memory_budget.h
/// How much memory a reconstruction may use, and how much an extraction will need, so that a
/// run that cannot fit is refused with a message instead of being killed mid-way (which, in
/// MeshLab, loses the user's unsaved work).

#include <unistd.h>

namespace ib {

struct MemoryBudget
{
    /// Peak bytes per SODS cell of a SODS-driven run: corner values and welded edge vertices
    /// (hash maps), the extracted vertices and faces with adjacency, and the host's copy of
    /// the result. Measured: 325 (peak RSS growth over SODS cells, bench/extraction.py's
    /// synthetic 1M-sample scan at resolution 1024 through pymeshlab); rounded up.
    static constexpr double kBytesPerSodsCell = 400;

    /// Half the physical memory: room for the host application and its other layers.
    static double Default()
    {
        const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
        return pages > 0 && page > 0 ? 0.5 * double(pages) * double(page) : 4e9;
    }

    /// Peak bytes per input sample, held while the surface is extracted: the input and its
    /// distinct, outlier-free copies, normals, the shared k-d tree, local spacings, the points
    /// projected onto the zero set and the PU-RBF's octree and local fits.
    static constexpr double kBytesPerSample = 150;

    /// Estimated peak bytes of a run over `samples` input samples and an extraction over
    /// `sodsCells` cells, plus a dense array of `denseCorners` values (0 for the SODS-driven
    /// extraction). The host's own copy of the layer is not counted: it exists before the run.
    static double PeakBytes(double samples, double sodsCells, double denseCorners)
    {
        return kBytesPerSample * samples + kBytesPerSodsCell * sodsCells + 8.0 * denseCorners;
    }
};

} // namespace ib
