#pragma once
/// \file boundary_stage.h
/// The boundary stage of the pipeline, on the gated extraction (surface faces first, then the
/// hole faces marching cubes found closing each hole): decides which holes are undersampling
/// and fills them (paper §3.1), cuts the surface at orientation seams and where it passes
/// over none of an input mesh's triangles, trims what the SODS added past the scan's edge,
/// removes pinches and scraps, smooths the loops (paper §3.3) and fits them to the samples'
/// edge.

#include "boundaries.h"
#include "boundary_fit.h"
#include "boundary_smoothing.h"
#include "boundary_trim.h"
#include "gated_mc.h"
#include "mesh_holes.h"
#include "orientation_seam.h"
#include "parallel.h"
#include "pinches.h"
#include "samples.h"

#include <vcg/complex/append.h>
#include <vcg/complex/algorithms/clean.h>
#include <vcg/complex/algorithms/update/selection.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace ib {

class BoundaryStage
{
public:
    /// Measured before filling at the automatic resolution: undersampling loops have at most 9
    /// edges (bun_zipper, fandisk, tum_rabbit, pymeshlab's bunny), the smallest real hole 18
    /// (bun_zipper at resolution 100); the paper's own bunny at 100 showed gaps of up to 12.
    static constexpr int kDefaultMinBoundaryEdges = 12;
    /// A filled hole has at most this many faces per squared edge of its loops (see SmallHoles).
    static constexpr double kPatchFacesPerSquaredEdge = 0.5;
    /// Merged scans: a hole none of whose points is farther than this many local spacings from
    /// a sample is a gap in the scans' coverage, filled whatever its size: range scans leave
    /// such gaps where no view reached (occlusion, grazing angles). Measured on the 9 Stanford
    /// bunny scans: such gaps 1.4-2.2 spacings deep, the shallowest real hole (bun_zipper's
    /// smallest) 3.4; gaps 3.2-3.7 deep also occur, and stay open.
    static constexpr double kCoverageGap = 2.5;
    /// Surface faces within this many median spacings of an orientation seam are cut away: the
    /// walls a signed implicit function forms where the normals flip reach about 1.75 spacings
    /// to either side (Möbius strip, both implicit functions).
    static constexpr double kSeamRadius = 2.0;
    /// A sample at a hole's rim has its neighbours on one side only, so its local spacing reads
    /// up to sqrt(2) times too wide (half the disk holds its k neighbours): measured at the loops
    /// of uniformly sampled scans (bun_zipper, a terrain with holes cut into it), 1.2 to 1.6
    /// times the median. A loop's local spacing counts for its size only beyond that.
    static constexpr double kRimSpacing = M_SQRT2;
    /// Pieces of surface with fewer faces left by the trim are removed (a few cells' worth).
    static constexpr size_t kMinPieceFaces = 10;

    struct Param
    {
        /// Holes whose loops all have fewer edges are undersampling: their hole triangles are
        /// added to the surface (paper §3.1). Counted at the median spacing: a loop among
        /// samples k times sparser may have k times as many. 0 keeps every hole.
        int min_boundary_edges = kDefaultMinBoundaryEdges;
        /// Faces at the boundary farther than this many local spacings from every sample are
        /// peeled off (the margin the SODS adds past the scan's edge). 0 = no trim.
        double boundary_trim = 0.25;
        int boundary_smoothing = 4;  ///< iterations of collinearity moves (paper §3.3), 0 = off
        /// After smoothing, move the boundary within the surface onto the edge of the samples
        /// (boundary_fit.h).
        bool boundary_fit = true;
        /// The samples are several merged scans: gaps between their coverage are filled too.
        bool merged_scans = false;
        /// The input's triangles (one scan given as a mesh), or null: the surface is cut where
        /// it passes over none of them, and holes they cover are filled (mesh_holes.h). Not owned.
        const MeshDistance* input_mesh = nullptr;
        /// The extraction is the closed full-lattice reference: nothing to fill, trim or smooth.
        bool reference = false;
        int min_support = 10;        ///< pieces supported by fewer samples are removed
        double cell_size = 0;        ///< the lattice's
        double sample_spacing = 0;   ///< the median local spacing
        int threads = 0;             ///< 0 = all cores
    };

    struct Result
    {
        std::vector<int> loops_before_filling;  ///< edge counts of all loops before small holes were filled
        int holes_filled = 0;             ///< hole regions added to the surface
        /// How close the size decisions were (edges of a hole's longest loop, before filling,
        /// counted at the median spacing, rounded down (see SmallHoles); 0: no such hole): the
        /// largest hole filled as undersampling, and the smallest hole the
        /// implicit surface closes that was kept open. A min_boundary_edges above the second
        /// fills it too; one at or below the first keeps that one open.
        int largest_hole_filled = 0;
        int smallest_hole_kept = 0;
        size_t faces_cut_at_seams = 0;    ///< surface faces removed around orientation seams
        size_t faces_cut_at_mesh_holes = 0;  ///< surface faces over none of the input's triangles (mesh_holes.h)
        size_t faces_trimmed = 0;         ///< unsupported faces peeled off the boundary
        size_t faces_unpinched = 0;       ///< faces of smaller fans removed at pinch vertices
        size_t faces_unsupported = 0;     ///< faces of pieces supported by fewer than min_support samples
        size_t boundary_vertices_fitted = 0;  ///< boundary vertices moved onto the samples' edge
    };

    /// The boundary stage on the whole extraction `all` (surface faces first, then hole faces):
    /// fills small holes, trims, removes pinches and scraps, smooths, fits the boundary to the
    /// samples' edge (in that order: fitting last puts the straightened loop back on the scan's
    /// edge, where the smoothing's corner cuts had moved it). `inSurface` receives, per face of
    /// `all`, 1 for the surface, 0 for the hole faces left open.
    /// Smoothing and fit move surface and hole faces alike, so the holes follow the boundary.
    static Result Compute(CoreMesh& all, const GatedMarchingCubes::Result& mc, const SampleIndex& samples,
                          const Eigen::VectorXd& spacing, const Points& seam, const ImplicitFunction& f,
                          const Param& p, std::vector<char>& inSurface)
    {
        Result r;
        inSurface.assign(all.face.size(), 0);
        std::fill(inSurface.begin(), inSurface.begin() + long(mc.surface_faces), 1);
        UpdateFaceFace(all);  // once, for every boundary step
        if (p.reference)
            return r;  // the closed reference: nothing to fill, trim or smooth
        // Merged scans: a hole region within kCoverageGap spacings of the samples everywhere is a
        // gap between the scans' coverage, filled whatever its loops' size.
        const std::vector<int> fill = SmallHoles(all, inSurface, mc, p.min_boundary_edges,
                                                 p.merged_scans ? &samples : nullptr, spacing, p.threads,
                                                 r.loops_before_filling, &r, p.input_mesh, p.cell_size,
                                                 &samples, p.sample_spacing);
        for (size_t face = mc.surface_faces; face < all.face.size(); ++face)
            if (fill[size_t(mc.face_region[face - mc.surface_faces])])
                inSurface[face] = 1;
        r.holes_filled = int(std::count(fill.begin(), fill.end(), 1));
        // After the filling, so that the cut is not taken for a small hole and closed again.
        r.faces_cut_at_seams =
            OrientationSeam::Cut(all, seam, kSeamRadius * p.sample_spacing, inSurface, p.threads);
        if (p.input_mesh)
            r.faces_cut_at_mesh_holes =
                MeshHoles::Cut(all, *p.input_mesh, p.cell_size, p.min_boundary_edges, inSurface);
        if (p.boundary_trim > 0)
            r.faces_trimmed =
                BoundaryTrim::Compute(all, samples, p.boundary_trim * spacing, inSurface, p.threads, &spacing);
        r.faces_unpinched = Pinches::Resolve(all, inSurface);
        r.faces_unsupported = BoundaryTrim::RemoveUnsupported(all, samples, p.min_support, inSurface);
        // A piece smaller than the smallest hole kept, or than a few cells when every hole is
        // kept, is a scrap of the trim.
        if (p.boundary_trim > 0)
            r.faces_trimmed += BoundaryTrim::RemoveScraps(
                all, inSurface, std::max(kMinPieceFaces, size_t(p.min_boundary_edges * p.min_boundary_edges / 4)));
        const std::vector<BoundaryLoop> loops = BoundaryLoops::Compute(all, inSurface);
        BoundarySmoothing::Param sp;
        sp.iterations = p.boundary_smoothing;
        sp.cell_size = p.cell_size;
        BoundarySmoothing::Compute(all, loops, &f, sp);
        if (p.boundary_fit) {
            BoundaryFit::Param fp;
            fp.cell_size = p.cell_size;
            r.boundary_vertices_fitted = BoundaryFit::Compute(all, loops, inSurface, samples, spacing, &f, fp);
        }
        return r;
    }

    /// Per hole region: 1 if it is an undersampling gap to fill, i.e. closed (the implicit
    /// surface closes it within the search), its hole faces span its loops as a patch, not a
    /// balloon (at most kPatchFacesPerSquaredEdge × (its loops' edges)² faces: a flat patch
    /// inside a loop of L edges has about L² / 2π of them; where the implicit surface closes a
    /// gap by a detour far from every sample, a torn tip whose fit bulges away, many more), and
    /// small: every loop along it has fewer than `min_edges` edges, or, with `local` (the
    /// samples, `spacing` theirs, `medianSpacing` its median), fewer than `min_edges` times the
    /// spacing around the loop (BoundaryLoops::SpacingAround) over kRimSpacing medians, when
    /// above 1: the gaps a sampling leaves grow with its spacing, and where the samples thin
    /// out smoothly (an adaptive decimation) random gaps of a few sparse spacings opened as
    /// loops of 18 edges, which the trim then peeled open. Or, with `coverage` (the samples of
    /// merged scans, their local `spacing`; null: no such rule), none of it is
    /// farther than kCoverageGap spacings from them, or, with `mesh` (the input's triangles;
    /// null: none), all of it lies over them and near them (MeshHoles::Covered, on a lattice of
    /// `cellSize`, within kNearTriangles local spacings of `local`).
    /// Also reports the edge counts of all loops and, in `margins` (may be null),
    /// largest_hole_filled and smallest_hole_kept.
    static std::vector<int> SmallHoles(const CoreMesh& all, const std::vector<char>& inSurface,
                                       const GatedMarchingCubes::Result& mc, int min_edges,
                                       const SampleIndex* coverage, const Eigen::VectorXd& spacing, int threads,
                                       std::vector<int>& loopEdges, Result* margins = nullptr,
                                       const MeshDistance* mesh = nullptr, double cellSize = 0,
                                       const SampleIndex* local = nullptr, double medianSpacing = 0)
    {
        std::vector<int> fill(mc.region_closed.begin(), mc.region_closed.end());
        std::vector<double> edges(fill.size(), 0), faces(fill.size(), 0), longest(fill.size(), 0);
        std::vector<char> large(fill.size(), 0);
        for (int region : mc.face_region)
            ++faces[size_t(region)];
        for (const BoundaryLoop& loop : BoundaryLoops::Compute(all, inSurface)) {
            loopEdges.push_back(loop.Edges());
            const double scale =
                local && medianSpacing > 0
                    ? std::max(1.0, BoundaryLoops::SpacingAround(all, loop, *local, spacing) / (kRimSpacing * medianSpacing))
                    : 1.0;
            std::vector<size_t> regions;
            for (int face : loop.across)
                if (face >= 0)  // else a boundary of the whole closed surface (the lattice border)
                    regions.push_back(size_t(mc.face_region[size_t(face) - mc.surface_faces]));
            std::sort(regions.begin(), regions.end());
            regions.erase(std::unique(regions.begin(), regions.end()), regions.end());
            for (size_t region : regions) {
                edges[region] += loop.Edges();
                longest[region] = std::max(longest[region], loop.Edges() / scale);
                large[region] |= char(loop.Edges() >= min_edges * scale);
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
        if (mesh) {
            const std::vector<char> covered =
                MeshHoles::Covered(all, mc.surface_faces, mc.face_region, candidate, *mesh, cellSize, local, &spacing,
                                   threads);
            for (size_t i = 0; i < fill.size(); ++i)
                fill[i] = fill[i] || covered[i];
        }
        for (size_t i = 0; margins && i < fill.size(); ++i) {
            if (fill[i] && !candidate[i])
                margins->largest_hole_filled = std::max(margins->largest_hole_filled, int(longest[i]));
            if (candidate[i] && !fill[i] && (!margins->smallest_hole_kept || longest[i] < margins->smallest_hole_kept))
                margins->smallest_hole_kept = int(longest[i]);
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

    /// Copies the hole faces of `all` (!inSurface) into `holes`. The hole faces come from
    /// marching cubes over whatever cells the hole search reached; where two of those touch
    /// only at a corner, their fans meet in a pinch. Their smaller fans, and fans that touch
    /// the surface only at a vertex, are left out, so that the holes layer, alone and with the
    /// surface, stays a 2-manifold.
    static void SplitHoles(CoreMesh& all, const std::vector<char>& inSurface, CoreMesh& holes)
    {
        std::vector<char> inHoles(inSurface.size());
        std::transform(inSurface.begin(), inSurface.end(), inHoles.begin(), [](char s) { return char(!s); });
        Pinches::Resolve(all, inHoles, 8, &inSurface);
        Split(all, inHoles, 1, holes);
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
};

} // namespace ib
