#pragma once
/// \file reconstruct.h
/// The pipeline: samples (+ normals) -> implicit function -> SODS -> gated marching cubes ->
/// surface with its boundary loops. Parameters in, result out, progress through a VCG callback.
/// Throws ib::InputError, with a message that says what is wrong and what to do, on bad input.

#include "boundaries.h"
#include "boundary_fit.h"
#include "boundary_smoothing.h"
#include "boundary_trim.h"
#include "gated_mc.h"
#include "implicit/hoppe.h"
#include "implicit/pu_rbf.h"
#include "manifold_check.h"
#include "memory_budget.h"
#include "normals.h"
#include "orientation_seam.h"
#include "outliers.h"
#include "pinches.h"
#include "sods.h"
#include "spacing.h"

#include <vcg/complex/append.h>
#include <vcg/complex/algorithms/clean.h>
#include <vcg/complex/algorithms/update/selection.h>

#include <Eigen/Eigenvalues>

#include <chrono>
#include <memory>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <iomanip>
#include <numeric>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace ib {

/// Bad input or parameters; what() is meant for the user.
class InputError : public std::runtime_error
{
public:
    using std::runtime_error::runtime_error;
};

/// The progress callback returned false: the host asked to stop. Nothing is returned.
class Cancelled : public std::runtime_error
{
public:
    Cancelled() : std::runtime_error("cancelled") {}
};

/// Turns a callback's false ("stop") into a Cancelled exception, thrown from the call, so each
/// stage stops at its next progress report without checking. Like ProgressRange, the target
/// lives in thread-local state; stages report from the calling thread only (ParallelFor
/// rethrows there once its threads are done).
class Cancellation
{
public:
    /// A callback forwarding to `target`, or null when target is null.
    static vcg::CallBackPos* Watch(vcg::CallBackPos* target)
    {
        target_ = target;
        return target ? &Forward : nullptr;
    }

private:
    static bool Forward(const int pos, const char* what)
    {
        if (!target_(pos, what))
            throw Cancelled();
        return true;
    }
    static inline thread_local vcg::CallBackPos* target_ = nullptr;
};

/// Forwards a stage's own 0..100 progress into a range of the caller's callback. VCG's
/// callback is a plain function pointer, so the range lives in thread-local state; stages
/// report from the calling thread only.
class ProgressRange
{
public:
    /// A callback mapping 0..100 into [lo, hi] of `target`, or null when target is null.
    static vcg::CallBackPos* Into(vcg::CallBackPos* target, int lo, int hi)
    {
        target_ = target;
        lo_ = lo;
        hi_ = hi;
        return target ? &Forward : nullptr;
    }

private:
    static bool Forward(const int pos, const char* what)
    {
        return target_(lo_ + (hi_ - lo_) * std::clamp(pos, 0, 100) / 100, what);
    }
    static inline thread_local vcg::CallBackPos* target_ = nullptr;
    static inline thread_local int lo_ = 0, hi_ = 100;
};

class Reconstruction
{
public:
    static constexpr int kMinPoints = 10;        ///< fewer samples cannot define tangent planes
    static constexpr int kMinResolution = 8;
    static constexpr int kMaxResolution = 4096;
    static constexpr int kMaxAutoResolution = 1024;
    /// Measured before filling at the automatic resolution: undersampling loops have at most 9
    /// edges (bun_zipper, fandisk, tum_rabbit, pymeshlab's bunny), the smallest real hole 18
    /// (bun_zipper at resolution 100); the paper's own bunny at 100 showed gaps of up to 12.
    static constexpr int kDefaultMinBoundaryEdges = 12;
    /// Tangent disks are thickened by this many cells along the normal, so that cells the
    /// implicit surface enters through its small departures from the samples' planes count
    /// too. Thicker slabs (half a disk radius) closed the narrow holes of pymeshlab's bunny and
    /// split bun_zipper's holes into more loops, with no fewer gaps on the noisier gargoyle.
    static constexpr double kDiskSlack = 0.25;
    /// A filled hole has at most this many faces per squared edge of its loops (see SmallHoles).
    static constexpr double kPatchFacesPerSquaredEdge = 0.5;
    /// Merged scans: a hole none of whose points is farther than this many local spacings from
    /// a sample is a gap in the scans' coverage, filled whatever its size: range scans leave
    /// such gaps where no view reached (occlusion, grazing angles). Measured on the 9 Stanford
    /// bunny scans: such gaps 1.4-2.2 spacings deep, the shallowest real hole (bun_zipper's
    /// smallest) 3.4; gaps 3.2-3.7 deep also occur, and stay open.
    static constexpr double kCoverageGap = 2.5;
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
    /// Surface faces within this many median spacings of an orientation seam are cut away: the
    /// walls a signed implicit function forms where the normals flip reach about 1.75 spacings
    /// to either side (Möbius strip, both implicit functions).
    static constexpr double kSeamRadius = 2.0;
    /// Pieces of surface with fewer faces left by the trim are removed (a few cells' worth).
    static constexpr size_t kMinPieceFaces = 10;

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

    struct Param
    {
        int resolution = 0;          ///< cells along the longest bbox side; 0 = from sample spacing
        Occupancy occupancy = Occupancy::TangentDisks;
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
        PuRbf::Param rbf;            ///< the PU-RBF's cells and fits (threads: taken from `threads`)
        int hoppe_neighbours = 8;    ///< tangent planes blended by the signed distance
        const ImplicitFunction* given = nullptr;  ///< used with Implicit::Given; not owned
        /// Holes whose loops all have fewer edges are undersampling: their hole triangles are
        /// added to the surface (paper §3.1). 0 keeps every hole.
        int min_boundary_edges = kDefaultMinBoundaryEdges;
        /// Faces at the boundary farther than this many local spacings from every sample are
        /// peeled off (the margin the SODS adds past the scan's edge). 0 = no trim.
        double boundary_trim = 0.25;
        /// After smoothing, move the boundary within the surface onto the edge of the samples
        /// (boundary_fit.h).
        bool boundary_fit = true;
        int boundary_smoothing = 4;  ///< iterations of collinearity moves (paper §3.3), 0 = off
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
    };

    struct Result
    {
        std::vector<BoundaryLoop> loops;  ///< boundary loops of the surface, largest first
        std::vector<int> loops_before_filling;  ///< edge counts of all loops before small holes were filled
        int holes_filled = 0;             ///< hole regions added to the surface
        size_t faces_trimmed = 0;         ///< unsupported faces peeled off the boundary
        size_t faces_unpinched = 0;       ///< faces of smaller fans removed at pinch vertices
        size_t seam_points = 0;           ///< where neighbouring samples' normals flip (orientation_seam.h)
        size_t faces_cut_at_seams = 0;    ///< surface faces removed around those points
        size_t boundary_vertices_fitted = 0;  ///< boundary vertices moved onto the samples' edge
        size_t duplicates_removed = 0;    ///< samples at the same position as an earlier one
        std::vector<Eigen::Index> outliers;  ///< input rows left out as outliers (outliers.h), ascending
        size_t faces_unsupported = 0;     ///< faces of pieces supported by fewer than kMinPoints samples
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
        size_t evaluations = 0;
        size_t crossed_corners = 0;  ///< corners of the SODS and hole cells the surface crosses
        double lattice_corners = 0;  ///< what a full-lattice extraction would have evaluated
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
            ReleaseFreedMemory();
            throw;
        }
    }

private:
    /// Compute's body; cb already turns a false into Cancelled.
    static Result Run(const Points& input, const Points& inputNormals, const Param& p, CoreMesh& surface,
                      CoreMesh* holes, vcg::CallBackPos* cb)
    {
        using Clock = std::chrono::steady_clock;
        auto seconds = [](Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); };
        CheckInput(input, inputNormals, p);
        Result r;
        // Repeated samples (merged scans, exported meshes with seams) would make every
        // neighbourhood collapse to one point and the spacing zero: keep one of each.
        std::vector<Eigen::Index> kept = DistinctRows(input);
        r.duplicates_removed = size_t(input.rows() - Eigen::Index(kept.size()));
        if (Eigen::Index(kept.size()) < kMinPoints)
            throw InputError("Only " + std::to_string(kept.size()) + " distinct vertex positions; at least " +
                             std::to_string(kMinPoints) + " are needed to fit tangent planes.");
        auto t = Clock::now();
        {
            const Points distinct = input(kept, Eigen::all);
            const std::vector<Eigen::Index> inliers = Outliers::Kept(SampleIndex(distinct), p.threads);
            r.outliers.reserve(kept.size() - inliers.size());
            for (size_t i = 0, j = 0; i < kept.size(); ++i) {
                if (j < inliers.size() && inliers[j] == Eigen::Index(i))
                    kept[j++] = kept[i];
                else
                    r.outliers.push_back(kept[i]);
            }
            kept.resize(inliers.size());
        }
        const Points P = input(kept, Eigen::all);
        const Points N = inputNormals.rows() ? Points(inputNormals(kept, Eigen::all)) : Points();
        if (P.rows() < kMinPoints)
            throw InputError("Only " + std::to_string(P.rows()) + " samples are left once " +
                             std::to_string(r.outliers.size()) + " outliers (samples far from all others) are left " +
                             "out; at least " + std::to_string(kMinPoints) + " are needed to fit tangent planes.");

        const SampleIndex samples(P);  // the k-d tree every stage shares, from normals to the trim
        const Points facing = p.facing.rows() ? Points(p.facing(kept, Eigen::all)) : Points();
        const Points normals = OrientedNormals(samples, N, facing, p, r, cb);
        r.seconds_normals = seconds(t);

        t = Clock::now();
        if (cb) cb(5, "Building the implicit function");
        const std::vector<int> scan = ScanOf(p.scan_sizes, input.rows(), kept);
        const Eigen::VectorXd spacing = ScanSpacing(samples, scan, p.threads);
        r.sample_spacing = SampleSpacing::Median(spacing);
        const Eigen::Vector3d lo = P.colwise().minCoeff().transpose(), hi = P.colwise().maxCoeff().transpose();
        const double longest = (hi - lo).maxCoeff();
        r.resolution_automatic = p.resolution == 0;
        r.resolution = p.resolution;
        r.resolution_from_spacing =
            int(std::min(1e9, std::round(longest / (kCellPerSpacing * r.sample_spacing))));
        if (r.resolution_automatic)
            r.resolution = std::clamp(r.resolution_from_spacing, kMinResolution, kMaxAutoResolution);
        // Padding keeps every SODS cell and its corners inside the lattice: the widest disk
        // (capped at the lattice size: an outlier's disk may be clipped), the dilation, one more.
        const double cell = longest / r.resolution;
        const int diskCells = p.occupancy == Occupancy::TangentDisks
                                  ? std::min(r.resolution, int(std::ceil(p.sample_radius * spacing.maxCoeff() / cell)))
                                  : 0;
        const Lattice lattice = Lattice::Fit(lo, hi, r.resolution, p.sods_dilation + diskCells + 1);
        r.cell_size = lattice.cell_size;
        r.lattice_cells = lattice.cells;
        r.lattice_corners = lattice.CornerCount();
        r.memory_limit = p.memory_limit > 0 ? p.memory_limit : MemoryBudget::Default();
        // Before the implicit function, the largest per-sample cost: a surface of n samples at
        // spacing s covers about n·s² / cell² cells, in a layer two cells thick, or as thick as
        // the tangent disks' slab on cells finer than the automatic resolution's.
        const double expectedCells = double(P.rows()) * std::pow(r.sample_spacing / cell, 2) *
                                     std::max(2.0, 2 * kSlabPerSpacing * r.sample_spacing / cell);
        CheckMemory(p.extraction, lattice, double(input.rows()), expectedCells, r);
        const std::unique_ptr<ImplicitFunction> fitted =
            p.implicit == Implicit::Given ? nullptr : MakeImplicit(P, normals, samples, p, cb);
        const ImplicitFunction& f = fitted ? *fitted : *p.given;
        if (const auto* rbf = dynamic_cast<const PuRbf*>(fitted.get()))
            r.rbf_cells = rbf->Cells();
        r.seconds_implicit = seconds(t);

        t = Clock::now();
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
        // have one-sided neighbourhoods, so larger spacings.)
        const Eigen::VectorXd foldWidth = OrientationSeam::FoldWidths(samples, normals, spacing, p.threads, scan);
        Sods sods = p.occupancy == Occupancy::TangentDisks
                        ? Sods::FromDisks(lattice, OnZeroSet(P, normals, f), normals, p.sample_radius * spacing,
                                          kDiskSlack * lattice.cell_size, p.threads, 0.5 * foldWidth,
                                          kSlabPerSpacing * spacing, kCellPerSpacing * r.sample_spacing)
                        : Sods::FromSamples(lattice, P);
        for (int i = 0; i < p.sods_dilation; ++i)
            sods = sods.Dilated();
        r.sods_cells = sods.Count();
        r.seconds_sods = seconds(t);
        CheckMemory(p.extraction, lattice, double(input.rows()), double(r.sods_cells), r);

        t = Clock::now();
        // Extracted straight into `surface`: the hole faces are split off at the end, so a large
        // run never holds two copies of its mesh.
        surface.Clear();
        GatedMarchingCubes::Param mp;
        mp.extraction = p.extraction;
        const GatedMarchingCubes::Result mc =
            GatedMarchingCubes::Compute(lattice, sods, f, surface, mp, ProgressRange::Into(cb, 40, 96));
        r.evaluations = mc.evaluations;
        r.crossed_corners = mc.crossed_corners;
        r.hole_cells = mc.hole_cells;
        r.hole_search_capped = mc.hole_search_capped;
        r.seconds_extraction = seconds(t);
        ReleaseFreedMemory();  // the corner and edge hash maps, before the boundary stage grows

        t = Clock::now();
        if (cb) cb(97, "Tracing boundary loops, filling small holes");
        const Points seam = OrientationSeam::Find(samples, normals, spacing, foldWidth, p.threads, scan);
        r.seam_points = size_t(seam.rows());
        const std::vector<char> inSurface =
            Boundaries(surface, mc, samples, spacing, seam, f, lattice.cell_size, p, r);
        if (holes) {
            // The hole faces come from marching cubes over whatever cells the hole search
            // reached; where two of those touch only at a corner, their fans meet in a pinch.
            // Their smaller fans, and fans that touch the surface only at a vertex, are left
            // out, so that the holes layer, alone and with the surface, stays a 2-manifold.
            std::vector<char> inHoles(inSurface.size());
            std::transform(inSurface.begin(), inSurface.end(), inHoles.begin(), [](char s) { return char(!s); });
            Pinches::Resolve(surface, inHoles, 8, &inSurface);
            Split(surface, inHoles, 1, *holes);
        }
        KeepSurface(surface, inSurface);
        // An empty layer would look like success: say why nothing came out instead.
        if (surface.face.empty())
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
        ReleaseFreedMemory();  // before the host copies the surface
        r.seconds_boundaries = seconds(t);
        return r;
    }

public:
    /// The samples moved along their normals onto the implicit surface (one Newton step, f
    /// being close to a signed distance): the tangent disks are laid where the surface to be
    /// extracted is, not where the noisy or smoothed-over samples are. A fitted function (the
    /// PU-RBF) passes up to about a spacing away from samples at sharp or noisy spots.
    static Points OnZeroSet(const Points& P, const Points& N, const ImplicitFunction& f)
    {
        Eigen::VectorXd value(P.rows());
        f.Eval(P, value);
        return (P.array() - N.array().colwise() * value.array()).matrix();
    }

    /// Per sample of `kept` (rows of an input of `rows` rows), the index of its scan given the
    /// scans' sizes; empty for a single scan.
    static std::vector<int> ScanOf(const std::vector<Eigen::Index>& sizes, Eigen::Index rows,
                                   const std::vector<Eigen::Index>& kept)
    {
        if (sizes.size() <= 1)
            return {};
        std::vector<int> scanOfRow(size_t(rows), 0);
        Eigen::Index row = 0;
        for (size_t s = 0; s < sizes.size(); ++s)
            for (Eigen::Index i = 0; i < sizes[s] && row < rows; ++i)
                scanOfRow[size_t(row++)] = int(s);
        std::vector<int> scan;
        scan.reserve(kept.size());
        for (Eigen::Index i : kept)
            scan.push_back(scanOfRow[size_t(i)]);
        return scan;
    }

    /// Local sample spacing, measured among the samples of each sample's own scan (`scan`: the
    /// scan index per sample, empty for one scan). The samples of a scan too small to measure
    /// get the spacing among all samples.
    static Eigen::VectorXd ScanSpacing(const SampleIndex& samples, const std::vector<int>& scan, int threads)
    {
        if (scan.empty())
            return SampleSpacing::Local(samples, 1, threads);
        std::vector<std::vector<Eigen::Index>> rows(size_t(*std::max_element(scan.begin(), scan.end()) + 1));
        for (size_t i = 0; i < scan.size(); ++i)
            rows[size_t(scan[i])].push_back(Eigen::Index(i));
        Eigen::VectorXd spacing(samples.Size());
        std::vector<Eigen::Index> unmeasured;
        for (const std::vector<Eigen::Index>& own : rows) {
            if (own.size() <= size_t(SampleSpacing::kNeighbours)) {
                unmeasured.insert(unmeasured.end(), own.begin(), own.end());
                continue;
            }
            spacing(own) = SampleSpacing::Local(SampleIndex(samples.P()(own, Eigen::all)), 1, threads);
        }
        if (!unmeasured.empty())
            spacing(unmeasured) = SampleSpacing::Local(samples, 1, threads)(unmeasured);
        return spacing;
    }

    /// The implicit function p asks for, fitted to the samples P with unit normals N.
    static std::unique_ptr<ImplicitFunction> MakeImplicit(const Points& P, const Points& N, const SampleIndex& samples,
                                                          const Param& p, vcg::CallBackPos* cb)
    {
        if (p.implicit == Implicit::Hoppe)
            return std::make_unique<HoppeDistance>(samples, N, p.hoppe_neighbours, p.threads);
        PuRbf::Param rp = p.rbf;
        rp.threads = p.threads;
        try {
            return std::make_unique<PuRbf>(P, N, rp, ProgressRange::Into(cb, 5, 35));
        } catch (const std::invalid_argument& e) {
            throw InputError(e.what());
        }
    }

    /// Unit normals: the layer's, or estimated ones (and says so in r), turned to the rows of
    /// `facing` (per sample, see Param::facing; empty: none).
    static Points OrientedNormals(const SampleIndex& samples, const Points& N, const Points& facing, const Param& p,
                                  Result& r, vcg::CallBackPos* cb)
    {
        if (p.normals == NormalSource::LayerOrEstimate && HasNormals(N)) {
            Points normals = N;
            std::vector<Eigen::Index> missing;
            for (Eigen::Index i = 0; i < N.rows(); ++i) {
                const double length = N.row(i).norm();
                if (std::isfinite(length) && length > 0)
                    normals.row(i) /= length;
                else
                    missing.push_back(i);
            }
            PointNormals::FillMissing(samples, normals, missing, p.normal_neighbours);
            r.normals_filled = missing.size();
            return normals;
        }
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

    /// The boundary stage on the whole extraction `all` (surface faces first, then hole faces):
    /// fills small holes, trims, removes pinches and scraps, smooths, fits the boundary to the
    /// samples' edge (in that order: fitting last puts the straightened loop back on the scan's
    /// edge, where the smoothing's corner cuts had moved it). Returns which faces are surface.
    /// Smoothing and fit move surface and hole faces alike, so the holes follow the boundary.
    static std::vector<char> Boundaries(CoreMesh& all, const GatedMarchingCubes::Result& mc, const SampleIndex& samples,
                                        const Eigen::VectorXd& spacing, const Points& seam,
                                        const ImplicitFunction& f, double cell, const Param& p, Result& r)
    {
        std::vector<char> inSurface(all.face.size(), 0);
        std::fill(inSurface.begin(), inSurface.begin() + long(mc.surface_faces), 1);
        UpdateFaceFace(all);  // once, for every boundary step
        if (p.extraction == GatedMarchingCubes::Extraction::Plain)
            return inSurface;  // the closed reference: nothing to fill, trim or smooth
        // Merged scans: a hole region within kCoverageGap spacings of the samples everywhere is a
        // gap between the scans' coverage, filled whatever its loops' size.
        const std::vector<int> fill = SmallHoles(all, inSurface, mc, p.min_boundary_edges,
                                                 p.scan_sizes.size() > 1 ? &samples : nullptr, spacing, p.threads,
                                                 r.loops_before_filling);
        for (size_t face = mc.surface_faces; face < all.face.size(); ++face)
            if (fill[size_t(mc.face_region[face - mc.surface_faces])])
                inSurface[face] = 1;
        r.holes_filled = int(std::count(fill.begin(), fill.end(), 1));
        // After the filling, so that the cut is not taken for a small hole and closed again.
        r.faces_cut_at_seams =
            OrientationSeam::Cut(all, seam, kSeamRadius * r.sample_spacing, inSurface, p.threads);
        if (p.boundary_trim > 0)
            r.faces_trimmed = BoundaryTrim::Compute(all, samples, p.boundary_trim * spacing, inSurface, p.threads);
        r.faces_unpinched = Pinches::Resolve(all, inSurface);
        r.faces_unsupported = BoundaryTrim::RemoveUnsupported(all, samples, kMinPoints, inSurface);
        // A piece smaller than the smallest hole kept, or than a few cells when every hole is
        // kept, is a scrap of the trim.
        if (p.boundary_trim > 0)
            r.faces_trimmed += BoundaryTrim::RemoveScraps(
                all, inSurface, std::max(kMinPieceFaces, size_t(p.min_boundary_edges * p.min_boundary_edges / 4)));
        const std::vector<BoundaryLoop> loops = BoundaryLoops::Compute(all, inSurface);
        BoundarySmoothing::Param sp;
        sp.iterations = p.boundary_smoothing;
        sp.cell_size = cell;
        BoundarySmoothing::Compute(all, loops, &f, sp);
        if (p.boundary_fit) {
            BoundaryFit::Param fp;
            fp.cell_size = cell;
            r.boundary_vertices_fitted = BoundaryFit::Compute(all, loops, inSurface, samples, spacing, &f, fp);
        }
        return inSurface;
    }

    /// Per hole region: 1 if it is an undersampling gap to fill, i.e. closed (the implicit
    /// surface closes it within the search), its hole faces span its loops as a patch, not a
    /// balloon (at most kPatchFacesPerSquaredEdge × (its loops' edges)² faces: a flat patch
    /// inside a loop of L edges has about L² / 2π of them; where the implicit surface closes a
    /// gap by a detour far from every sample, a torn tip whose fit bulges away, many more), and
    /// small: every loop along it has fewer than `min_edges` edges, or, with `coverage` (the
    /// samples of merged scans, their local `spacing`; null: no such rule), none of it is
    /// farther than kCoverageGap spacings from them. Also reports the edge counts of all loops.
    static std::vector<int> SmallHoles(const CoreMesh& all, const std::vector<char>& inSurface,
                                       const GatedMarchingCubes::Result& mc, int min_edges,
                                       const SampleIndex* coverage, const Eigen::VectorXd& spacing, int threads,
                                       std::vector<int>& loopEdges)
    {
        std::vector<int> fill(mc.region_closed.begin(), mc.region_closed.end());
        std::vector<double> edges(fill.size(), 0), faces(fill.size(), 0);
        std::vector<char> large(fill.size(), 0);
        for (int region : mc.face_region)
            ++faces[size_t(region)];
        for (const BoundaryLoop& loop : BoundaryLoops::Compute(all, inSurface)) {
            loopEdges.push_back(loop.Edges());
            std::vector<size_t> regions;
            for (int face : loop.across)
                if (face >= 0)  // else a boundary of the whole closed surface (the lattice border)
                    regions.push_back(size_t(mc.face_region[size_t(face) - mc.surface_faces]));
            std::sort(regions.begin(), regions.end());
            regions.erase(std::unique(regions.begin(), regions.end()), regions.end());
            for (size_t region : regions) {
                edges[region] += loop.Edges();
                large[region] |= char(loop.Edges() >= min_edges);
            }
        }
        std::vector<char> candidate(fill.size(), 0);
        for (size_t i = 0; i < fill.size(); ++i) {
            const bool closedPatch =
                fill[i] && edges[i] > 0 && faces[i] <= kPatchFacesPerSquaredEdge * edges[i] * edges[i];
            candidate[i] = closedPatch && large[i];
            fill[i] = closedPatch && !large[i];
        }
        if (coverage) {
            const std::vector<double> depth = RegionDepths(all, mc, candidate, *coverage, spacing, threads);
            for (size_t i = 0; i < fill.size(); ++i)
                fill[i] = fill[i] || (candidate[i] && depth[i] <= kCoverageGap);
        }
        return fill;
    }

    /// Per hole region of `all` (its faces from mc.surface_faces on) with `regions[i]` set, the
    /// largest distance from a face's centre to its nearest sample, in that sample's local
    /// spacings (0 for the other regions).
    static std::vector<double> RegionDepths(const CoreMesh& all, const GatedMarchingCubes::Result& mc,
                                            const std::vector<char>& regions, const SampleIndex& samples,
                                            const Eigen::VectorXd& spacing, int threads)
    {
        const size_t n = all.face.size() - mc.surface_faces;
        std::vector<double> faceDepth(n, 0);
        ParallelFor(n, threads, [&](size_t begin, size_t end, int) {
            SampleIndex::Queue queue;
            for (size_t i = begin; i < end; ++i) {
                if (!regions[size_t(mc.face_region[i])])
                    continue;
                const vcg::Point3d c = vcg::Barycenter(all.face[mc.surface_faces + i]);
                samples.Nearest(Eigen::Vector3d(c[0], c[1], c[2]), 1, queue);
                faceDepth[i] = std::sqrt(queue.getWeight(0)) / spacing[queue.getIndex(0)];
            }
        });
        std::vector<double> depth(regions.size(), 0);
        for (size_t i = 0; i < n; ++i)
            depth[size_t(mc.face_region[i])] = std::max(depth[size_t(mc.face_region[i])], faceDepth[i]);
        return depth;
    }

    /// Hands memory freed by the last stage back to the system. Millions of small hash map
    /// nodes, once freed, stay in the allocator's heap and count towards the process's peak
    /// when the next stage (or the host's copy of the result) allocates large blocks.
    static void ReleaseFreedMemory()
    {
#ifdef __GLIBC__
        malloc_trim(0);
#endif
    }

    /// Deletes the faces f of `mesh` with !inSurface[f] and the vertices they alone used;
    /// compacts, keeping the order of what remains and a valid face-face adjacency (edges
    /// towards deleted faces become border edges).
    static void KeepSurface(CoreMesh& mesh, const std::vector<char>& inSurface)
    {
        for (size_t face = 0; face < mesh.face.size(); ++face) {
            CoreFace& f = mesh.face[face];
            for (int i = 0; inSurface[face] && i < 3; ++i)
                if (!inSurface[vcg::tri::Index(mesh, f.FFp(i))]) {
                    f.FFp(i) = &f;
                    f.FFi(i) = i;
                }
        }
        for (size_t face = 0; face < mesh.face.size(); ++face)
            if (!inSurface[face])
                vcg::tri::Allocator<CoreMesh>::DeleteFace(mesh, mesh.face[face]);
        vcg::tri::Clean<CoreMesh>::RemoveUnreferencedVertex(mesh);
        vcg::tri::Allocator<CoreMesh>::CompactEveryVector(mesh);
    }

    /// Copies the faces f of `all` with inSurface[f] == which, and their vertices, into `out`.
    static void Split(CoreMesh& all, const std::vector<char>& inSurface, char which, CoreMesh& out)
    {
        vcg::tri::UpdateSelection<CoreMesh>::Clear(all);
        for (size_t face = 0; face < all.face.size(); ++face)
            if (inSurface[face] == which)
                all.face[face].SetS();
        vcg::tri::Append<CoreMesh, CoreMesh>::MeshCopy(out, all, true);
    }

    /// Indices of the rows of P, in order, skipping rows equal to an earlier one.
    static std::vector<Eigen::Index> DistinctRows(const Points& P)
    {
        std::vector<Eigen::Index> order(size_t(P.rows()));
        std::iota(order.begin(), order.end(), Eigen::Index(0));
        auto less = [&](Eigen::Index a, Eigen::Index b) {
            for (int c = 0; c < 3; ++c)
                if (P(a, c) != P(b, c))
                    return P(a, c) < P(b, c);
            return a < b;
        };
        std::sort(order.begin(), order.end(), less);
        std::vector<char> keep(size_t(P.rows()), 1);
        for (size_t i = 1; i < order.size(); ++i)
            if (P.row(order[i]) == P.row(order[i - 1]))
                keep[size_t(order[i])] = 0;
        std::vector<Eigen::Index> kept;
        for (Eigen::Index i = 0; i < P.rows(); ++i)
            if (keep[size_t(i)])
                kept.push_back(i);
        return kept;
    }

    /// True when N holds a usable normal for every sample; false when it holds none at all
    /// (no rows, or all zero: what a point cloud without normals gets in MeshLab).
    static bool HasNormals(const Points& N)
    {
        return N.rows() > 0 && (N.rowwise().squaredNorm().array() > 0).any();
    }

    /// Refuses, before allocating, a run whose estimated peak (MemoryBudget::PeakBytes: the
    /// samples, and the SODS cells or, for full-lattice extraction, the lattice) exceeds
    /// r.memory_limit; records the estimate in r.memory_estimate.
    static void CheckMemory(GatedMarchingCubes::Extraction extraction, const Lattice& lattice, double samples,
                            double sodsCells, Result& r)
    {
        const bool dense = extraction != GatedMarchingCubes::Extraction::SodsDriven;
        const double bytes = MemoryBudget::PeakBytes(samples, sodsCells, dense ? lattice.CornerCount() : 0);
        r.memory_estimate = bytes;
        if (bytes <= r.memory_limit)
            return;
        const double sampleBytes = MemoryBudget::PeakBytes(samples, 0, 0);
        std::ostringstream msg;
        msg.precision(2);
        msg << std::fixed << "Resolution " << r.resolution << " would need about " << bytes / 1e9
            << " GB of memory (" << std::setprecision(0) << samples << " samples, "
            << (dense ? lattice.CornerCount() : sodsCells) << (dense ? " lattice corners)" : " occupied cells)")
            << std::setprecision(2) << ", over the limit of " << r.memory_limit / 1e9 << " GB: ";
        if (sampleBytes > r.memory_limit)  // no lattice, however coarse, would fit
            msg << "the samples alone need about " << sampleBytes / 1e9
                << " GB; thin them out (e.g. Poisson-disk sampling) or raise the memory limit.";
        else
            msg << "lower the resolution (0 = automatic)" << (dense ? ", use the SODS-driven extraction" : "")
                << " or raise the memory limit.";
        throw InputError(msg.str());
    }

private:
    static void CheckInput(const Points& P, const Points& N, const Param& p)
    {
        std::ostringstream msg;
        if (P.rows() == 0)
            throw InputError("The layer has no vertices: select a point cloud or mesh layer with at least " +
                             std::to_string(kMinPoints) + " vertices.");
        if (P.rows() < kMinPoints)
            throw InputError("The layer has only " + std::to_string(P.rows()) + " vertices; at least " +
                             std::to_string(kMinPoints) + " samples are needed to fit tangent planes.");
        const Eigen::Index bad = (!P.array().isFinite()).rowwise().any().count();
        if (bad > 0)
            throw InputError(std::to_string(bad) + " of " + std::to_string(P.rows()) +
                             " vertices have NaN or infinite coordinates: remove them first "
                             "(e.g. Filters > Cleaning and Repairing > Remove Duplicate and Unreferenced Vertices, "
                             "or select them with Conditional Vertex Selection and delete).");
        const Eigen::Vector3d extent = (P.colwise().maxCoeff() - P.colwise().minCoeff()).transpose();
        if (!(extent.maxCoeff() > 0))
            throw InputError("All vertices are at the same position: there is no surface to reconstruct.");
        // Second principal extent: zero when every sample lies on one line (a flat scan is fine).
        const Points centred = P.rowwise() - P.colwise().mean();
        const Eigen::Vector3d spread =
            Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(centred.transpose() * centred).eigenvalues();  // ascending
        if (!(spread[1] > 1e-12 * spread[2]))  // second extent under a millionth of the first
            throw InputError("All vertices lie on one line: a surface needs samples spread in two directions.");
        if (p.facing.rows() != 0 && p.facing.rows() != P.rows())
            throw InputError("The facing directions have " + std::to_string(p.facing.rows()) + " rows for " +
                             std::to_string(P.rows()) + " samples.");
        if (p.resolution != 0 && (p.resolution < kMinResolution || p.resolution > kMaxResolution))
            throw InputError("Resolution " + std::to_string(p.resolution) + " is out of range: use 0 (automatic, " +
                             "from the sample spacing) or a value between " + std::to_string(kMinResolution) +
                             " and " + std::to_string(kMaxResolution) + ".");
        if (p.sods_dilation < 0 || p.sods_dilation > 8)
            throw InputError("SODS dilation must be between 0 and 8 rings (1 is the paper's 26-neighbourhood).");
        if (!(p.sample_radius >= 0.25 && p.sample_radius <= 8))
            throw InputError("The sample radius must be between 0.25 and 8 sample spacings (1.25 is the default).");
        if (p.boundary_smoothing < 0 || p.boundary_smoothing > 100)
            throw InputError("Boundary smoothing must be between 0 and 100 iterations (4 is the paper's choice).");
        if (!(p.boundary_trim >= 0 && p.boundary_trim <= 8))
            throw InputError("The boundary trim must be between 0 (off) and 8 sample spacings.");
        if (p.implicit == Implicit::Given && p.given == nullptr)
            throw InputError("No implicit function was given: choose a mesh layer as the implicit surface.");
        if (p.rbf.min_samples < 4 || p.rbf.min_samples > 2000)
            throw InputError("The PU-RBF's minimum samples per cell must be between 4 and 2000 (50 is the paper's).");
        if (p.rbf.max_samples < std::max(8, p.rbf.min_samples / 4) || p.rbf.max_samples > 5000)
            throw InputError("The PU-RBF's maximum samples per cell must be between 8 and 5000 and not far below "
                             "the minimum (160 is the paper's).");
        if (!(p.rbf.overlap >= 1 && p.rbf.overlap <= 4))
            throw InputError("The PU-RBF's overlap must be between 1 (no overlap) and 4 (1.5 is the default).");
        if (!(p.rbf.off_surface > 0 && p.rbf.off_surface <= 4))
            throw InputError("The PU-RBF's off-surface distance must be above 0 and at most 4 sample spacings.");
        if (!(p.memory_limit >= 0))
            throw InputError("The memory limit cannot be negative (0 = half the physical memory).");
        if (p.min_boundary_edges < 0)
            throw InputError("The minimum number of boundary edges cannot be negative (0 keeps every hole).");
        if (p.normal_neighbours < 3 || p.normal_neighbours > 256)
            throw InputError("Normal neighbours must be between 3 and 256.");
        if (N.rows() != 0 && N.rows() != P.rows())
            throw InputError("There must be one normal per vertex.");
        if (!p.scan_sizes.empty() &&
            std::accumulate(p.scan_sizes.begin(), p.scan_sizes.end(), Eigen::Index(0)) != P.rows())
            throw InputError("The scans' sizes must add up to the number of vertices.");
    }
};

} // namespace ib
