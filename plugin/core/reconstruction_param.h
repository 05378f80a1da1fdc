#pragma once
/// \file reconstruction_param.h
/// What Reconstruction::Compute (reconstruct.h) takes: the choices of each stage, with their
/// defaults, and the ranges a user may set them in (Check, with messages that say what to use).

#include "boundary_stage.h"
#include "gated_mc.h"
#include "implicit/implicit_function.h"
#include "implicit/pu_rbf.h"
#include "input_check.h"
#include "lattice.h"
#include "tiling.h"

#include <Eigen/Core>

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

namespace ib {

struct ReconstructionParam
{
    static constexpr int kMinResolution = 8;
    static constexpr int kMaxResolution = 4096;

    enum class NormalSource { LayerOrEstimate, Estimate };
    /// The implicit function whose zero set is extracted.
    enum class Implicit {
        PuRbf,  ///< partition-of-unity RBF (paper §4, pu_rbf.h)
        Hoppe,  ///< blended signed distance to the nearest tangent planes (hoppe.h)
        Given   ///< Param::given, e.g. the signed distance to a closed mesh (mesh_distance.h)
    };
    /// What a sample marks in the SODS before dilation.
    enum class Occupancy {
        TangentDisks,  ///< cells crossed by the sample's tangent disk (radius from local spacing)
        SampleCells    ///< the cell holding the sample (the paper's SODS; use with dilation 1)
    };

    int resolution = 0;          ///< cells along the longest bbox side; 0 = from sample spacing
    Occupancy sods_occupancy = Occupancy::TangentDisks;
    double sample_radius = 1.25; ///< tangent disk radius, in local sample spacings
    int sods_dilation = 0;       ///< 26-neighbourhood rings added around occupied cells
    NormalSource normals = NormalSource::LayerOrEstimate;
    int normal_neighbours = 15;  ///< k for normal estimation (10 flips normals on noisy scans; see README)
    std::optional<Eigen::Vector3d> viewpoint;  ///< orient estimated normals towards it
    /// n×3 (rows as the input) or empty: per sample, a direction its estimated normal must
    /// face, e.g. towards the scanner of its scan (the layer's camera) or along its range
    /// grid's triangles; zero rows: none. Used when normals are estimated, without viewpoint.
    Points facing;
    Implicit implicit = Implicit::PuRbf;
    PuRbf::Param rbf = PuRbf::Param::Local();  ///< the PU-RBF's fits (threads: `threads`)
    int hoppe_neighbours = 8;    ///< tangent planes blended by the signed distance
    const ImplicitFunction* given = nullptr;  ///< used with Implicit::Given; not owned
    // The boundary stage's (BoundaryStage::Param: holes filled below min_boundary_edges).
    int min_boundary_edges = BoundaryStage::kDefaultMinBoundaryEdges;
    double boundary_trim = 0.25;
    bool boundary_fit = true;
    int boundary_smoothing = 4;
    GatedMarchingCubes::Extraction extraction = GatedMarchingCubes::Extraction::SodsDriven;
    /// Refuse runs estimated to need more memory (bytes); 0 = half the physical memory.
    double memory_limit = 0;
    int threads = 0;             ///< 0 = all cores
    /// Rows per scan when the input is several range scans one after the other (merged
    /// layers); empty: one scan. Sample spacing is then measured within each scan:
    /// overlapping scans multiply the density, but not the detail, since their sheets lie
    /// apart by the registration error (the 9 Stanford bunny scans: 0.00044 over all of
    /// them, about a third of a scan's own spacing, and sheets up to 0.0006 apart).
    std::vector<Eigen::Index> scan_sizes;
    /// m×3 rows of the input (one scan given as a triangle mesh), or empty (a point cloud):
    /// the holes of the triangulation stay open, as their rims say (mesh_holes.h).
    Faces faces;
    /// A tile of a scan reconstructed tile by tile (tiling.h): the whole scan's lattice, octree
    /// root and spacing, and the block whose faces are kept; default: not a tile.
    Tile tile;

    /// Throws InputError when a parameter is out of its range.
    void Check() const
    {
        if (resolution != 0 && (resolution < kMinResolution || resolution > kMaxResolution))
            throw InputError("Resolution " + std::to_string(resolution) + " is out of range: use 0 (automatic, " +
                             "from the sample spacing) or a value between " + std::to_string(kMinResolution) +
                             " and " + std::to_string(kMaxResolution) + ".");
        if (sods_dilation < 0 || sods_dilation > 8)
            throw InputError("SODS dilation must be between 0 and 8 rings (1 is the paper's 26-neighbourhood).");
        if (!(sample_radius >= 0.25 && sample_radius <= 8))
            throw InputError("The sample radius must be between 0.25 and 8 sample spacings (1.25 is the default).");
        if (boundary_smoothing < 0 || boundary_smoothing > 100)
            throw InputError("Boundary smoothing must be between 0 and 100 iterations (4 is the paper's choice).");
        if (!(boundary_trim >= 0 && boundary_trim <= 8))
            throw InputError("The boundary trim must be between 0 (off) and 8 sample spacings.");
        if (implicit == Implicit::Given && given == nullptr)
            throw InputError("No implicit function was given: choose a mesh layer as the implicit surface.");
        if (rbf.min_samples < 4 || rbf.min_samples > 2000)
            throw InputError("The PU-RBF's minimum samples per cell must be between 4 and 2000 (50 is the paper's).");
        if (rbf.max_samples < std::max(8, rbf.min_samples / 4) || rbf.max_samples > 5000)
            throw InputError("The PU-RBF's maximum samples per cell must be between 8 and 5000 and not far below "
                             "the minimum (160 is the paper's).");
        if (!(rbf.overlap >= 1 && rbf.overlap <= 4))
            throw InputError("The PU-RBF's overlap must be between 1 (no overlap) and 4 (1.5 is the default).");
        if (!(rbf.off_surface > 0 && rbf.off_surface <= 4))
            throw InputError("The PU-RBF's off-surface distance must be above 0 and at most 4 sample spacings.");
        if (!(memory_limit >= 0))
            throw InputError("The memory limit cannot be negative (0 = half the physical memory).");
        if (min_boundary_edges < 0)
            throw InputError("The minimum number of boundary edges cannot be negative (0 keeps every hole).");
        if (normal_neighbours < 3 || normal_neighbours > 256)
            throw InputError("Normal neighbours must be between 3 and 256.");
        if (tile.Fixed() && resolution != 0)
            throw InputError("A fixed lattice sets its own cell size: leave the resolution at 0 with it.");
    }
};

} // namespace ib
