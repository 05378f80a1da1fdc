#pragma once
/// \file covered_openings.h
/// Openings of the finished surface that lie among samples, closed. Where two sheets come
/// within a few spacings (an ear, a fin) or the surface folds into a crease, the implicit
/// surface leaves the tangent disks' slabs and the gate opens holes in places the scan
/// covered. A hole of the scan is a region of the surface with no sample in it; an opening
/// among samples is not one. The test spans the loop by the fan from its centroid to its
/// edges (what a patch closing it would be) and asks how far the fan gets from the samples:
/// where no point of it is farther from a sample than the surface around the loop already is
/// (its faces within kBand spacings), or than kReach median spacings, the patch is as well
/// supported as the surface it closes, and the loop is closed by VCGlib's ear-cutting hole
/// filler (vcg/complex/algorithms/hole.h, with its minimum-weight ears). The fan of a loop
/// that bounds its piece from outside (the rim of a flat scan) lies on the piece itself, among
/// samples: a loop whose fan is not smaller than half its piece is no opening.
/// When the input is a mesh, its triangles say where its holes are, more surely than the
/// samples' spacing: an opening whose fan lies over the triangles is closed (OverTriangles).

#include "boundaries.h"
#include "implicit/mesh_distance.h"
#include "mesh_holes.h"
#include "mesh.h"
#include "samples.h"

#include <vcg/complex/algorithms/hole.h>
#include <vcg/complex/algorithms/update/normal.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>
#include <vector>

namespace ib {

namespace covered_openings_detail {
// The hole filler reads vertex and face normals, which CoreMesh leaves out to save memory at
// millions of faces: each opening is filled in a small copy of the faces around its loop.
class FillVertex;
class FillFace;
struct FillTypes : public vcg::UsedTypes<vcg::Use<FillVertex>::AsVertexType, vcg::Use<FillFace>::AsFaceType>
{
};
class FillVertex : public vcg::Vertex<FillTypes, vcg::vertex::Coord3d, vcg::vertex::Normal3d, vcg::vertex::BitFlags>
{
};
class FillFace
    : public vcg::Face<FillTypes, vcg::face::VertexRef, vcg::face::Normal3d, vcg::face::BitFlags, vcg::face::FFAdj>
{
};
class FillMesh : public vcg::tri::TriMesh<std::vector<FillVertex>, std::vector<FillFace>>
{
};
} // namespace covered_openings_detail

class CoveredOpenings
{
public:
    /// A fan no farther than this many median spacings from the samples is among them, whatever
    /// the surface around: one spacing, the gap a sampling leaves between its samples. Measured
    /// on the loops of the corpus and pymeshlab's meshes (BENCHMARKS, "Openings among
    /// samples"): the real holes reach 1.21 and more (1.05 to 1.22 times the surface's own gap
    /// around them), most spurious loops of thin parts and creases under 1. Random sampling
    /// leaves gaps wider than its median spacing almost everywhere, so there only the surface's
    /// own gap counts.
    static constexpr double kReach = 1.0;
    /// A loop's fan of at least this fraction of its piece's area bounds the piece from outside.
    static constexpr double kOutsideFan = 0.5;
    /// The fan is probed at points this many median spacings apart.
    static constexpr double kProbeStep = 0.25;
    /// The surface around a loop, whose own distance from the samples the fan may match: the
    /// faces within this many median spacings of the loop.
    static constexpr double kBand = 3.0;

    struct Result
    {
        int closed = 0;            ///< openings closed
        /// How close the closest decision to keep a loop open was: the smallest reach over its
        /// limit (above 1; 0: none kept).
        double closest_kept = 0;
    };

    /// Closes the openings of `mesh` (an oriented 2-manifold with boundary, face-face adjacency
    /// up to date) among `samples` (median local spacing `spacing`; `local`, when given, each
    /// sample's own: the band around a loop in a sparser part is as many of its spacings wide).
    /// Loops that pass a vertex twice or touch another loop are left as they are. Face-face
    /// adjacency is rebuilt when anything is closed.
    static Result Compute(CoreMesh& mesh, const SampleIndex& samples, double spacing,
                          const Eigen::VectorXd* local = nullptr)
    {
        if (!(spacing > 0))
            return Result();
        return CloseWhere(mesh, [&](const BoundaryLoop& loop, const std::vector<int>& faceOfVertex) {
            const double band =
                kBand * std::max(spacing, local ? BoundaryLoops::SpacingAround(mesh, loop, samples, *local) : 0.0);
            const double limit =
                std::max(kReach, SurfaceGap(mesh, loop, faceOfVertex, samples, band, kProbeStep * spacing) / spacing);
            return Reach(mesh, loop, samples, spacing, limit) / spacing / limit;
        });
    }

    /// The same for a surface made from a mesh (`input`, its triangles; `cellSize`, the
    /// lattice's): an opening whose fan lies over the triangles everywhere (MeshHoles: at most
    /// kPastBorderCells cells past their border) is no hole of the mesh, and is closed. A
    /// hole of the mesh leaves its fan past the border.
    static Result OverTriangles(CoreMesh& mesh, const MeshDistance& input, double cellSize)
    {
        if (!(cellSize > 0))
            return Result();
        const double allowed = MeshHoles::kPastBorderCells * cellSize;
        return CloseWhere(mesh, [&](const BoundaryLoop& loop, const std::vector<int>&) {
            // In batches, the centroid first: over a hole of the mesh it is past the border by
            // the most, so most holes are told at once.
            const Points fan = FanPoints(mesh, loop, 0.5 * cellSize);
            double past = 0;
            for (Eigen::Index at = 0, batch = 1; at < fan.rows() && past <= allowed; at += batch, batch = 256)
                past = std::max(past, input.PastBorder(fan.middleRows(at, std::min(batch, fan.rows() - at))).maxCoeff());
            return past / allowed;
        });
    }

    /// How far the fan from the centroid of `loop` (vertices of `mesh`) to its edges gets from
    /// `samples`: the largest distance from a probe point to its nearest sample, the loop's own
    /// edges left out (they are the surface around's, which SurfaceGap measures). Probes are
    /// kProbeStep × `spacing` apart; stops early, with a value above `limit` × `spacing`, once
    /// one is that far.
    static double Reach(const CoreMesh& mesh, const BoundaryLoop& loop, const SampleIndex& samples, double spacing,
                        double limit)
    {
        const Eigen::Vector3d c = Centroid(mesh, loop);
        SampleIndex::Queue queue;
        samples.Nearest(c, 1, queue);
        double reach = std::sqrt(queue.getWeight(0));  // first: where the fan leaves the surface, it is farthest here
        const size_t n = loop.vertices.size();
        for (size_t i = 0; i < n && reach <= limit * spacing; ++i)
            reach = std::max(reach, Farthest(c, PositionOf(mesh, loop.vertices[i]), PositionOf(mesh, loop.vertices[(i + 1) % n]),
                                             samples, kProbeStep * spacing, limit * spacing, queue, false));
        return reach;
    }

    /// The largest distance from the surface within `radius` of `loop` (faces whose centre is
    /// that close to one of its vertices, reached from the loop through face-face adjacency;
    /// probed as the fan is, `step` apart) to the nearest sample.
    static double SurfaceGap(const CoreMesh& mesh, const BoundaryLoop& loop, const std::vector<int>& faceOfVertex,
                             const SampleIndex& samples, double radius, double step)
    {
        Points rim(Eigen::Index(loop.vertices.size()), 3);
        for (size_t i = 0; i < loop.vertices.size(); ++i)
            rim.row(Eigen::Index(i)) = PositionOf(mesh, loop.vertices[i]).transpose();
        const SampleIndex near(rim);
        SampleIndex::Queue queue;
        std::unordered_map<size_t, char> seen;
        std::vector<size_t> stack;
        for (int v : loop.vertices)
            if (seen.emplace(size_t(faceOfVertex[size_t(v)]), 1).second)
                stack.push_back(size_t(faceOfVertex[size_t(v)]));
        double gap = 0;
        while (!stack.empty()) {
            const CoreFace& f = mesh.face[stack.back()];
            stack.pop_back();
            const Eigen::Vector3d a = PositionOf(mesh, int(vcg::tri::Index(mesh, f.cV(0)))),
                                  b = PositionOf(mesh, int(vcg::tri::Index(mesh, f.cV(1)))),
                                  c = PositionOf(mesh, int(vcg::tri::Index(mesh, f.cV(2))));
            near.Nearest((a + b + c) / 3, 1, queue);
            if (queue.getWeight(0) > radius * radius)
                continue;
            gap = std::max(gap, Farthest(a, b, c, samples, step, HUGE_VAL, queue));
            for (int i = 0; i < 3; ++i) {
                const size_t g = vcg::tri::Index(mesh, f.cFFp(i));
                if (seen.emplace(g, 1).second)
                    stack.push_back(g);
            }
        }
        return gap;
    }

private:
    /// Closes the simple loops of `mesh` that do not bound their piece from outside and whose
    /// `excess(loop, faceOfVertex)` (how far the fan gets from the support, over what is
    /// allowed) is at most 1; Result::closest_kept is the smallest excess above 1.
    template <class Excess>
    static Result CloseWhere(CoreMesh& mesh, Excess excess)
    {
        Result r;
        if (mesh.face.empty())
            return r;
        const std::vector<BoundaryLoop> loops = BoundaryLoops::Compute(mesh);
        if (loops.empty())
            return r;
        const std::vector<int> uses = BoundaryLoops::Uses(mesh, loops);
        std::vector<double> pieceArea;
        const std::vector<int> piece = Pieces(mesh, pieceArea);
        std::vector<int> faceOfVertex(mesh.vert.size(), -1);
        for (size_t f = 0; f < mesh.face.size(); ++f)
            for (int i = 0; i < 3; ++i)
                faceOfVertex[vcg::tri::Index(mesh, mesh.face[f].cV(i))] = int(f);

        std::vector<const BoundaryLoop*> close;
        for (const BoundaryLoop& loop : loops) {
            bool simple = loop.Edges() >= 3;
            for (int v : loop.vertices)
                simple = simple && uses[size_t(v)] == 1;
            if (!simple)
                continue;
            const double area = pieceArea[size_t(piece[size_t(faceOfVertex[size_t(loop.vertices[0])])])];
            if (FanArea(mesh, loop) >= kOutsideFan * area)
                continue;
            const double e = excess(loop, faceOfVertex);
            if (e <= 1)
                close.push_back(&loop);
            else if (r.closest_kept == 0 || e < r.closest_kept)
                r.closest_kept = e;
        }
        if (close.empty())
            return r;
        // The loops are apart (no shared vertex), so one's new faces touch no other's ring.
        Around around;
        for (const BoundaryLoop* loop : close)
            for (int v : loop->vertices)
                around[v];
        for (size_t f = 0; f < mesh.face.size(); ++f)
            for (int i = 0; i < 3; ++i) {
                const auto it = around.find(int(vcg::tri::Index(mesh, mesh.face[f].cV(i))));
                if (it != around.end())
                    it->second.push_back(f);
            }
        for (const BoundaryLoop* loop : close)
            r.closed += int(Fill(mesh, *loop, around));
        UpdateFaceFace(mesh);
        return r;
    }

    /// Points of the fan from the centroid of `loop` to its edges, a barycentric grid at most
    /// `step` apart in each fan triangle.
    static Points FanPoints(const CoreMesh& mesh, const BoundaryLoop& loop, double step)
    {
        const Eigen::Vector3d c = Centroid(mesh, loop);
        std::vector<Eigen::Vector3d> points{c};
        const size_t n = loop.vertices.size();
        for (size_t i = 0; i < n; ++i) {
            const Eigen::Vector3d a = PositionOf(mesh, loop.vertices[i]), b = PositionOf(mesh, loop.vertices[(i + 1) % n]);
            const int steps = std::max(1, int(std::ceil(std::max({(a - c).norm(), (b - c).norm(), (b - a).norm()}) / step)));
            for (int u = 0; u <= steps; ++u)
                for (int w = 0; u + w <= steps; ++w)
                    if (u + w > 0)
                        points.push_back(c + (a - c) * (double(u) / steps) + (b - c) * (double(w) / steps));
        }
        Points P(Eigen::Index(points.size()), 3);
        for (size_t k = 0; k < points.size(); ++k)
            P.row(Eigen::Index(k)) = points[k].transpose();
        return P;
    }

    /// The largest distance from points of the triangle a b c (a barycentric grid `step` apart
    /// at most) to their nearest sample; stops early, above `limit`, once one is that far.
    /// `withSideBC` false leaves the side b c out (the loop's own edge, for a fan: the surface
    /// around the loop holds it).
    static double Farthest(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                           const SampleIndex& samples, double step, double limit, SampleIndex::Queue& queue,
                           bool withSideBC = true)
    {
        const double longest = std::max({(b - a).norm(), (c - a).norm(), (c - b).norm()});
        const int steps = std::max(1, int(std::ceil(longest / step)));
        const int last = withSideBC ? steps : steps - 1;
        double farthest = 0;
        for (int u = 0; u <= last && farthest <= limit; ++u)
            for (int w = 0; u + w <= last; ++w) {
                samples.Nearest(a + (b - a) * (double(u) / steps) + (c - a) * (double(w) / steps), 1, queue);
                farthest = std::max(farthest, std::sqrt(queue.getWeight(0)));
            }
        return farthest;
    }

    using FillMesh = covered_openings_detail::FillMesh;
    using FillVertex = covered_openings_detail::FillVertex;
    using FillFace = covered_openings_detail::FillFace;
    using Around = std::unordered_map<int, std::vector<size_t>>;  ///< faces around some vertices

    static Eigen::Vector3d Centroid(const CoreMesh& mesh, const BoundaryLoop& loop)
    {
        Eigen::Vector3d c = Eigen::Vector3d::Zero();
        for (int v : loop.vertices)
            c += PositionOf(mesh, v);
        return c / double(loop.vertices.size());
    }

    static double FanArea(const CoreMesh& mesh, const BoundaryLoop& loop)
    {
        const Eigen::Vector3d c = Centroid(mesh, loop);
        double area = 0;
        const size_t n = loop.vertices.size();
        for (size_t i = 0; i < n; ++i)
            area += 0.5 * (PositionOf(mesh, loop.vertices[i]) - c).cross(PositionOf(mesh, loop.vertices[(i + 1) % n]) - c).norm();
        return area;
    }

    /// Per face of `mesh`, the index of its edge-connected piece; `area` receives each piece's.
    static std::vector<int> Pieces(const CoreMesh& mesh, std::vector<double>& area)
    {
        std::vector<int> piece(mesh.face.size(), -1);
        std::vector<size_t> stack;
        for (size_t seed = 0; seed < mesh.face.size(); ++seed) {
            if (piece[seed] >= 0)
                continue;
            const int id = int(area.size());
            area.push_back(0);
            piece[seed] = id;
            stack.push_back(seed);
            while (!stack.empty()) {
                const CoreFace& f = mesh.face[stack.back()];
                stack.pop_back();
                area[size_t(id)] += 0.5 * vcg::DoubleArea(f);
                for (int i = 0; i < 3; ++i) {
                    const size_t g = vcg::tri::Index(mesh, f.cFFp(i));
                    if (piece[g] < 0) {
                        piece[g] = id;
                        stack.push_back(g);
                    }
                }
            }
        }
        return piece;
    }

    /// Fills `loop` of `mesh` with the hole filler, run on a copy of the faces around the loop
    /// (`around`: the faces of each of its vertices); the new faces are appended to `mesh`.
    /// Returns whether any was added.
    static bool Fill(CoreMesh& mesh, const BoundaryLoop& loop, const Around& around)
    {
        std::vector<size_t> ring;
        for (int v : loop.vertices)
            ring.insert(ring.end(), around.at(v).begin(), around.at(v).end());
        std::sort(ring.begin(), ring.end());
        ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
        std::map<int, int> local;  // vertex of mesh -> vertex of the copy
        std::vector<int> global;   // the other way round
        for (size_t f : ring)
            for (int i = 0; i < 3; ++i) {
                const int v = int(vcg::tri::Index(mesh, mesh.face[f].cV(i)));
                if (local.emplace(v, int(global.size())).second)
                    global.push_back(v);
            }
        FillMesh copy;
        vcg::tri::Allocator<FillMesh>::AddVertices(copy, global.size());
        for (size_t k = 0; k < global.size(); ++k)
            copy.vert[k].P() = mesh.vert[size_t(global[k])].cP();
        vcg::tri::Allocator<FillMesh>::AddFaces(copy, ring.size());
        for (size_t k = 0; k < ring.size(); ++k)
            for (int i = 0; i < 3; ++i)
                copy.face[k].V(i) = &copy.vert[size_t(local[int(vcg::tri::Index(mesh, mesh.face[ring[k]].cV(i)))])];
        vcg::tri::UpdateTopology<FillMesh>::FaceFace(copy);
        vcg::tri::UpdateNormal<FillMesh>::PerVertexNormalizedPerFaceNormalized(copy);

        // The loop runs along its faces' edges: the edge vertices[0] -> vertices[1] is some
        // face's edge i -> i + 1.
        const FillVertex* a = &copy.vert[size_t(local[loop.vertices[0]])];
        const FillVertex* b = &copy.vert[size_t(local[loop.vertices[1]])];
        vcg::face::Pos<FillFace> start;
        for (FillFace& f : copy.face)
            for (int i = 0; i < 3; ++i)
                if (f.V(i) == a && f.V((i + 1) % 3) == b && vcg::face::IsBorder(f, i))
                    start = vcg::face::Pos<FillFace>(&f, i, f.V(i));
        if (start.IsNull())
            return false;
        const size_t before = copy.face.size();
        std::vector<FillFace**> update{&start.f};
        vcg::tri::Hole<FillMesh>::FillHoleEar<vcg::tri::MinimumWeightEar<FillMesh>>(copy, start, update);
        bool added = false;
        for (size_t k = before; k < copy.face.size(); ++k) {
            if (copy.face[k].IsD())
                continue;
            vcg::tri::Allocator<CoreMesh>::AddFace(mesh, &mesh.vert[size_t(global[vcg::tri::Index(copy, copy.face[k].V(0))])],
                                                   &mesh.vert[size_t(global[vcg::tri::Index(copy, copy.face[k].V(1))])],
                                                   &mesh.vert[size_t(global[vcg::tri::Index(copy, copy.face[k].V(2))])]);
            added = true;
        }
        return added;
    }
};

} // namespace ib
