#pragma once
/// \file reconstruct.h
/// The pipeline: samples (+ normals) -> implicit function -> SODS -> gated marching cubes ->
/// surface with its boundary loops. Parameters in, result out, progress through a VCG callback.
/// Throws ib::InputError, with a message that says what is wrong and what to do, on bad input.

#include "boundary_stage.h"
#include "covered_openings.h"
#include "gated_mc.h"
#include "implicit/hoppe.h"
#include "implicit/pu_rbf.h"
#include "implicit_projection.h"
#include "input_check.h"
#include "manifold_check.h"
#include "memory_budget.h"
#include "normals.h"
#include "open_sides.h"
#include "orientation_seam.h"
#include "outliers.h"
#include "progress.h"
#include "reconstruction_param.h"
#include "scan_edges.h"
#include "sods.h"
#include "spacing.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

namespace ib {

class Reconstruction
{
public:
    static constexpr int kMinResolution = ReconstructionParam::kMinResolution;
    static constexpr int kMaxResolution = ReconstructionParam::kMaxResolution;
    static constexpr int kMaxAutoResolution = 1024;
    /// Tangent disks are thickened by this many cells along the normal, so that cells the
    /// implicit surface enters through its small departures from the samples' planes count
    /// too. Thicker slabs (half a disk radius) closed the narrow holes of pymeshlab's bunny and
    /// split bun_zipper's holes into more loops, with no fewer gaps on the noisier gargoyle.
    static constexpr double kDiskSlack = 0.25;
    /// Automatic resolution: lattice cell = this × the median sample spacing. Tangent disks of
    /// one spacing cover a uniformly sampled surface at any cell size, so the cell is chosen for
    /// the boundaries: measured on the Stanford bunny scan (bun_zipper, 34,834 samples), 0.6
    /// finds all 5 holes as single loops (1.0 merges the smallest into undersampling noise).
    static constexpr double kCellPerSpacing = 0.6;
    /// A tangent disk is at least this many of its sample's local spacings thick on each side:
    /// the thinnest slab it has at the automatic resolution (half a cell plus the slack, for a
    /// normal along an axis), for the spacing divided by √2. A sample on the edge of a scan or
    /// a hole finds its neighbours in a half disk, which makes its spacing up to √2 larger; a
    /// slab from that spacing closed the smallest real holes of bun_zipper, fertility and
    /// pymeshlab's bunny.
    static constexpr double kSlabPerSpacing = kCellPerSpacing * (0.5 + kDiskSlack) / M_SQRT2;

    using Param = ReconstructionParam;
    using NormalSource = Param::NormalSource;
    using Implicit = Param::Implicit;
    using Occupancy = Param::Occupancy;


    struct Result
    {
        std::vector<BoundaryLoop> loops;  ///< boundary loops of the surface, largest first
        BoundaryStage::Result boundary;   ///< holes filled, faces trimmed, loops fitted
        CoveredOpenings::Result openings;  ///< openings among samples closed (covered_openings.h)
        size_t seam_points = 0;           ///< where neighbouring samples' normals flip (orientation_seam.h)
        size_t covered_scan_edges = 0;    ///< merged scans: edge samples another scan covers, left out of the PU-RBF's fit
        size_t duplicates_removed = 0;    ///< samples at the same position as an earlier one
        std::vector<Eigen::Index> outliers;  ///< input rows left out as outliers (outliers.h), ascending
        size_t faces_not_manifold = 0;    ///< faces removed from edges shared by more than two faces (manifold_check.h)
        size_t vertices_split = 0;        ///< vertices where separate fans met, split (manifold_check.h)
        size_t hole_cells = 0;
        bool hole_search_capped = false;
        int resolution = 0;
        bool resolution_automatic = false;
        int resolution_from_spacing = 0;  ///< what the spacing asks for (longest side / kCellPerSpacing spacings)
        double cell_size = 0;
        double sample_spacing = 0;
        Index3 lattice_cells = Index3::Zero();
        int rbf_cells = 0;           ///< local RBF fits (PU-RBF only)
        size_t sods_cells = 0;
        size_t implicit_evaluations = 0;  ///< lattice corners where the implicit function was evaluated
        size_t crossed_cell_corners = 0;  ///< corners of the SODS and hole cells the surface crosses
        double full_lattice_evaluations = 0;  ///< what a full-lattice extraction would have evaluated (corners)
        double memory_limit = 0;     ///< the budget used, bytes
        double memory_estimate = 0;  ///< the estimated peak, bytes (MemoryBudget::PeakBytes)
        bool normals_estimated = false;
        bool normals_flipped = false;
        size_t normals_turned = 0;        ///< estimated normals turned to agree with their neighbours
        size_t normals_filled = 0;        ///< zero or NaN normals among given ones, estimated
        double seconds_normals = 0, seconds_implicit = 0, seconds_sods = 0, seconds_extraction = 0,
               seconds_boundaries = 0;
    };

    /// P: n×3 samples; N: n×3 normals or empty (0 rows) when there are none.
    /// `surface` receives the extracted surface (vertices welded, faces along the normals);
    /// `holes`, when given, the hole triangles left open (surface + holes is closed where the
    /// implicit surface is). Loop vertex indices refer to `surface`. Throws InputError on bad
    /// input, Cancelled when cb returns false; then `surface` and `holes` are left empty.
    static Result Compute(const Points& input, const Points& inputNormals, const Param& p, CoreMesh& surface,
                          CoreMesh* holes = nullptr, vcg::CallBackPos* cb = nullptr)
    {
        try {
            return Run(input, inputNormals, p, surface, holes, Cancellation::Watch(cb));
        } catch (...) {
            surface.Clear();
            if (holes)
                holes->Clear();
            MemoryBudget::ReleaseFreed();
            throw;
        }
    }

private:
    /// Compute's body; cb already turns a false into Cancelled.
    static Result Run(const Points& input, const Points& inputNormals, const Param& p, CoreMesh& surface,
                      CoreMesh* holes, vcg::CallBackPos* cb)
    {
        InputCheck::Samples(input, inputNormals, p.facing, p.scan_sizes);
        InputCheck::FacesOf(input, p.faces);
        p.Check();
        p.tile.Check(input);
        Result r;
        // Repeated samples (merged scans, exported meshes with seams) would make every
        // neighbourhood collapse to one point and the spacing zero: keep one of each.
        std::vector<Eigen::Index> kept = InputCheck::DistinctRows(input);
        r.duplicates_removed = size_t(input.rows() - Eigen::Index(kept.size()));
        if (Eigen::Index(kept.size()) < InputCheck::kMinPoints)
            throw InputError("Only " + std::to_string(kept.size()) + " distinct vertex positions; at least " +
                             std::to_string(InputCheck::kMinPoints) + " are needed to fit tangent planes.");
        Stopwatch watch;
        kept = Outliers::KeptRows(input, std::move(kept), r.outliers, p.threads);
        const Points P = input(kept, Eigen::all);
        const Points N = inputNormals.rows() ? Points(inputNormals(kept, Eigen::all)) : Points();
        if (P.rows() < InputCheck::kMinPoints)
            throw InputError("Only " + std::to_string(P.rows()) + " samples are left once " +
                             std::to_string(r.outliers.size()) + " outliers (samples far from all others) are left " +
                             "out; at least " + std::to_string(InputCheck::kMinPoints) + " are needed to fit tangent planes.");

        const SampleIndex samples(P);  // the k-d tree every stage shares, from normals to the trim
        const Points facing = p.facing.rows() ? Points(p.facing(kept, Eigen::all)) : Points();
        const Points normals = OrientedNormals(samples, N, facing, p, r, cb);
        r.seconds_normals = watch.Lap();

        if (cb) cb(5, "Building the implicit function");
        const std::vector<int> scan = ScanOfSamples(p.scan_sizes, input.rows(), kept);
        const Eigen::VectorXd spacing = SampleSpacing::PerScan(samples, scan, p.threads, &normals);
        r.sample_spacing = p.tile.spacing > 0 ? p.tile.spacing : SampleSpacing::Median(spacing);
        const Eigen::Vector3d lo = P.colwise().minCoeff().transpose(), hi = P.colwise().maxCoeff().transpose();
        const double longest = (hi - lo).maxCoeff();
        r.resolution_automatic = p.resolution == 0 && !p.tile.Fixed();
        r.resolution = p.resolution;
        r.resolution_from_spacing =
            int(std::min(1e9, std::round(longest / (kCellPerSpacing * r.sample_spacing))));
        if (r.resolution_automatic)
            r.resolution = std::clamp(r.resolution_from_spacing, kMinResolution, kMaxAutoResolution);
        if (p.tile.Fixed())
            r.resolution = std::max(1, int(std::ceil(longest / p.tile.cell)));
        // Padding keeps every SODS cell and its corners inside the lattice: the widest disk
        // (capped at the lattice size: an outlier's disk may be clipped), the dilation, one more.
        const double cell = p.tile.Fixed() ? p.tile.cell : longest / r.resolution;
        const int diskCells = p.sods_occupancy == Occupancy::TangentDisks
                                  ? std::min(r.resolution, int(std::ceil(p.sample_radius * spacing.maxCoeff() / cell)))
                                  : 0;
        const int pad = p.sods_dilation + diskCells + 1;
        const Lattice lattice = p.tile.Fixed() ? p.tile.Over(lo, hi, pad) : Lattice::Fit(lo, hi, r.resolution, pad);
        r.cell_size = lattice.cell_size;
        r.lattice_cells = lattice.cells;
        r.full_lattice_evaluations = lattice.CornerCount();
        r.memory_limit = p.memory_limit > 0 ? p.memory_limit : MemoryBudget::Default();
        // Before the implicit function, the largest per-sample cost: a surface of n samples at
        // spacing s covers about n·s² / cell² cells, in a layer two cells thick, or as thick as
        // the tangent disks' slab on cells finer than the automatic resolution's.
        const double expectedCells = double(P.rows()) * std::pow(r.sample_spacing / cell, 2) *
                                     std::max(2.0, 2 * kSlabPerSpacing * r.sample_spacing / cell);
        r.memory_estimate = CheckMemory(p, lattice, double(input.rows()), expectedCells, r);
        const std::unique_ptr<MeshDistance> triangles = InputTriangles(input, p);
        const std::unique_ptr<ImplicitFunction> fitted =
            p.implicit == Implicit::Given ? nullptr : MakeImplicit(normals, samples, spacing, scan, p, r, cb);
        const ImplicitFunction& f = fitted ? *fitted : *p.given;
        if (const auto* rbf = dynamic_cast<const PuRbf*>(fitted.get()))
            r.rbf_cells = rbf->Cells();
        r.seconds_implicit = watch.Lap();

        if (cb) cb(36, "Building the spatial occupancy data structure");
        // At a thin part's rim the surface turns between the two sides' flat disks: there they
        // reach half way to the other side. On cells finer than the automatic resolution's for
        // a sample's spacing (the sparse parts of an unevenly sampled scan, a resolution set by
        // hand) a disk keeps the shape it has there: its slab (kSlabPerSpacing), as flat disks a
        // cell or two thick lost the curved surface at their rims (a unit sphere sampled 0.11
        // apart, on 0.0055 cells, leaves the plane by 1.1 cells one spacing away); and the
        // automatic cell's reach, as the random gaps between samples, no longer bridged by the
        // cells, opened as holes. (A reach from each sample's own spacing, not the median,
        // closed the smallest real holes of bun_zipper and fertility: samples at a hole's rim
        // have one-sided neighbourhoods, so larger spacings.) Where the sampling ends (a scan's
        // edge, a thin tube's open end) a disk covers only its half behind its sample
        // (OpenSides): at halftunnel's countersunk hole, without normals, the full disks of its
        // rim, whose estimated planes lean 25 degrees over the opening, capped it.
        const Eigen::VectorXd foldWidth = OrientationSeam::FoldWidths(samples, normals, spacing, p.threads, scan);
        Sods sods = p.sods_occupancy == Occupancy::TangentDisks
                        ? Sods::FromDisks(lattice, ImplicitProjection::OntoZeroSet(P, normals, f), normals,
                                          p.sample_radius * spacing, kDiskSlack * lattice.cell_size, p.threads,
                                          0.5 * foldWidth,
                                          kSlabPerSpacing * spacing, kCellPerSpacing * r.sample_spacing,
                                          OpenSides::Compute(samples, normals, p.sample_radius * spacing, p.threads))
                        : Sods::FromSamples(lattice, P);
        for (int i = 0; i < p.sods_dilation; ++i)
            sods = sods.Dilated();
        r.sods_cells = sods.Count();
        r.seconds_sods = watch.Lap();
        r.memory_estimate = CheckMemory(p, lattice, double(input.rows()), double(r.sods_cells), r);

        // Extracted straight into `surface`: the hole faces are split off at the end, so a large
        // run never holds two copies of its mesh.
        surface.Clear();
        GatedMarchingCubes::Param mp;
        mp.extraction = p.extraction;
        const GatedMarchingCubes::Result mc =
            GatedMarchingCubes::Compute(lattice, sods, f, surface, mp, ProgressRange::Into(cb, 40, 96));
        r.implicit_evaluations = mc.evaluations;
        r.crossed_cell_corners = mc.crossed_corners;
        r.hole_cells = mc.hole_cells;
        r.hole_search_capped = mc.hole_search_capped;
        r.seconds_extraction = watch.Lap();
        MemoryBudget::ReleaseFreed();  // the corner and edge hash maps, before the boundary stage grows

        if (cb) cb(97, "Tracing boundary loops, filling small holes");
        const Points seam = OrientationSeam::Find(samples, normals, spacing, foldWidth, p.threads, scan);
        r.seam_points = size_t(seam.rows());
        std::vector<char> inSurface;
        r.boundary = BoundaryStage::Compute(surface, mc, samples, spacing, seam, f, BoundaryParam(p, r, triangles.get()),
                                            inSurface);
        if (holes)
            BoundaryStage::SplitHoles(surface, inSurface, *holes);
        BoundaryStage::KeepSurface(surface, inSurface);
        // On the whole surface, before a tile's clip: the halo sees a seam's openings whole. A
        // mesh's triangles say where its holes are (mesh_holes.h): an opening over them is
        // none. A min_boundary_edges of 0 keeps every opening.
        if (p.min_boundary_edges > 0 && p.extraction != GatedMarchingCubes::Extraction::Plain)
            r.openings = triangles ? CoveredOpenings::OverTriangles(surface, *triangles, r.cell_size)
                                   : CoveredOpenings::Compute(surface, samples, r.sample_spacing, &spacing);
        p.tile.Clip(surface);
        if (holes)
            p.tile.Clip(*holes);
        // An empty layer would look like success: say why nothing came out instead (a tile's
        // block may hold no surface).
        if (surface.face.empty() && p.tile.block.isEmpty())
            throw InputError("No surface was extracted at resolution " + std::to_string(r.resolution) +
                             ": the samples are too few or too scattered to outline a surface. Try a lower "
                             "resolution, a larger sample radius or SODS dilation, or more samples.");
        const ManifoldCheck::Result check = ManifoldCheck::Repair(surface);
        r.faces_not_manifold = check.faces_removed;
        r.vertices_split = check.vertices_split;
        if (!check.manifold || !check.oriented)
            throw std::logic_error(std::string("the surface is not ") + (check.manifold ? "oriented" : "a 2-manifold") +
                                   " after its repair");
        r.loops = BoundaryLoops::Compute(surface);
        MemoryBudget::ReleaseFreed();  // before the host copies the surface
        r.seconds_boundaries = watch.Lap();
        return r;
    }

    /// The implicit function p asks for, fitted to the samples (sharing their k-d tree) with
    /// unit normals N and local `spacing` (within each sample's own scan, `scan`). Merged scans:
    /// the PU-RBF is fitted without the samples on a scan's edge that another scan covers
    /// (scan_edges.h; counted in r): on the 9 Stanford bunny scans, where several scans' edges
    /// meet, its zero set otherwise left the sheets and opened holes the scans had covered.
    static std::unique_ptr<ImplicitFunction> MakeImplicit(const Points& N, const SampleIndex& samples,
                                                          const Eigen::VectorXd& spacing, const std::vector<int>& scan,
                                                          const Param& p, Result& r, vcg::CallBackPos* cb)
    {
        if (p.implicit == Implicit::Hoppe)
            return std::make_unique<HoppeDistance>(samples, N, p.hoppe_neighbours, p.threads);
        PuRbf::Param rp =
            p.scan_sizes.size() > 1 ? p.rbf.PerSheet(SampleSpacing::Overlap(samples, spacing, p.threads, &N)) : p.rbf;
        rp.threads = p.threads;
        rp.spacing = spacing;
        rp.root = p.tile.Root();
        try {
            if (p.scan_sizes.size() > 1) {
                const std::vector<Eigen::Index> fit = ScanEdges::Uncovered(samples, N, scan, spacing, p.threads);
                if (fit.size() < size_t(samples.Size()) && fit.size() >= size_t(InputCheck::kMinPoints)) {
                    r.covered_scan_edges = size_t(samples.Size()) - fit.size();
                    rp.spacing = spacing(fit);
                    return std::make_unique<PuRbf>(Points(samples.P()(fit, Eigen::all)), Points(N(fit, Eigen::all)),
                                                   rp, ProgressRange::Into(cb, 5, 35));
                }
            }
            return std::make_unique<PuRbf>(samples, N, rp, ProgressRange::Into(cb, 5, 35));
        } catch (const std::invalid_argument& e) {
            throw InputError(e.what());
        }
    }

    /// Unit normals: the layer's, or estimated ones (and says so in r), turned to the rows of
    /// `facing` (per sample, see Param::facing; empty: none).
    static Points OrientedNormals(const SampleIndex& samples, const Points& N, const Points& facing, const Param& p,
                                  Result& r, vcg::CallBackPos* cb)
    {
        if (p.normals == NormalSource::LayerOrEstimate && InputCheck::HasNormals(N))
            return PointNormals::Given(samples, N, p.normal_neighbours, r.normals_filled);
        if (cb) cb(2, "Estimating normals");
        PointNormals::Param np;
        np.neighbours = p.normal_neighbours;
        np.viewpoint = p.viewpoint;
        np.facing = facing;
        np.threads = p.threads;
        r.normals_estimated = true;
        PointNormals::Report report;
        Points normals = PointNormals::Compute(samples, np, &report);
        r.normals_flipped = report.flipped;
        r.normals_turned = report.turned;
        return normals;
    }

    /// The input's triangles (p.faces over the input's rows) for the boundary stage, or null
    /// for a point cloud.
    static std::unique_ptr<MeshDistance> InputTriangles(const Points& input, const Param& p)
    {
        if (!p.faces.rows())
            return nullptr;
        try {
            return std::make_unique<MeshDistance>(input, p.faces, p.threads);
        } catch (const std::invalid_argument&) {  // only zero-area faces
            throw InputError("Every face of the layer has zero area: remove the faces (keep the vertices) or turn "
                             "'Keep the mesh's holes' off.");
        }
    }

    /// The boundary stage's parameters from the pipeline's, on the lattice and spacing of r;
    /// `triangles`: the input's (InputTriangles), or null.
    static BoundaryStage::Param BoundaryParam(const Param& p, const Result& r, const MeshDistance* triangles)
    {
        BoundaryStage::Param bp;
        bp.input_mesh = triangles;
        bp.min_boundary_edges = p.min_boundary_edges;
        bp.boundary_trim = p.boundary_trim;
        bp.boundary_smoothing = p.boundary_smoothing;
        bp.boundary_fit = p.boundary_fit;
        bp.merged_scans = p.scan_sizes.size() > 1;
        bp.reference = p.extraction == GatedMarchingCubes::Extraction::Plain;
        bp.min_support = InputCheck::kMinPoints;
        bp.cell_size = r.cell_size;
        bp.sample_spacing = r.sample_spacing;
        bp.threads = p.threads;
        return bp;
    }

    /// MemoryBudget::Check for `samples` input samples and `sodsCells` cells, or the whole
    /// lattice when the extraction is dense; returns the estimate.
    static double CheckMemory(const Param& p, const Lattice& lattice, double samples, double sodsCells,
                              const Result& r)
    {
        return MemoryBudget::Check(samples, sodsCells, p.extraction != GatedMarchingCubes::Extraction::SodsDriven,
                                   lattice.CornerCount(), r.memory_limit, r.resolution, double(p.faces.rows()));
    }

};

} // namespace ib
