#pragma once
/// \file boundary_fit.h
/// Moves the boundary, within the surface, onto the edge of the samples. The trim
/// (boundary_trim.h) removes whole faces beyond a reach, so the boundary it leaves lies
/// somewhere between that reach and a face past the last samples, while a scan's real edge is
/// its outermost samples. For each boundary vertex v, with n the surface normal there, o is
/// the direction in the tangent plane away from the centroid of the samples around v (out of
/// the surface; where it disagrees with the loop's orientation, as in a notch of the trimmed
/// loop with a dense row of samples along the edge past it, the loop's own direction over a
/// few vertices each way). Among those samples that lie
/// beside v (within a local spacing across o and off the surface), the upper hull of their
/// positions along o marks the edge at v; v moves along o onto it (plus
/// `offset` local spacings), by at most `max_move` spacings, and the vertices next to v follow
/// (FollowMoves); where samples lie within a spacing of a point 1.5 spacings past the edge,
/// they go on there (a cut at an orientation seam) and v stays. All targets are computed
/// before any vertex moves. The moved vertices are put back on the implicit surface (the move
/// is along its tangent plane, implicit_projection.h), then moves that would fold a face are
/// pulled back (fold_guard.h; the faces out of the surface count too: with the hole layer they
/// close the surface).

#include "boundaries.h"
#include "fold_guard.h"
#include "implicit_projection.h"
#include "mesh.h"
#include "samples.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <vector>

namespace ib {

class BoundaryFit
{
public:
    /// Loop vertices each way over which the loop's direction is taken where the samples'
    /// centroid does not tell the side (a notch of the trimmed boundary).
    static constexpr size_t kStencil = 3;
    /// How far past the edge, in local spacings, a vertex looks for samples going on.
    static constexpr double kBeyond = 1.5;

    struct Param
    {
        double offset = 0.0;    ///< boundary beyond the outermost samples, in local spacings
        double max_move = 1.5;  ///< largest move, in local spacings
        int neighbours = 16;    ///< samples examined around each boundary vertex
        int ring_steps = 3;     ///< smoothing steps of the vertices next to the moved ones
        int newton_steps = 2;   ///< projection steps onto the implicit surface (0 = off)
        double cell_size = 0;   ///< lattice cell: a projection step moves a vertex by at most one
    };

    /// Fits the `loops` of the faces f of `mesh` with inSurface[f] (loops traced along the
    /// faces' orientation, boundaries.h). spacing: per sample of `samples`, its local spacing.
    /// f: the implicit function the moved vertices are projected on (null: no projection).
    /// Returns the number of vertices moved (pinch vertices, used twice by the loops, stay).
    static size_t Compute(CoreMesh& mesh, const std::vector<BoundaryLoop>& loops, const std::vector<char>& inSurface,
                          const SampleIndex& samples, const Eigen::VectorXd& spacing, const ImplicitFunction* f,
                          const Param& p)
    {
        const std::vector<int> uses = BoundaryLoops::Uses(mesh, loops);
        const std::vector<Eigen::Vector3d> normal = SurfaceNormals(mesh, inSurface, uses);
        std::vector<int> moved;
        std::vector<Eigen::Vector3d> start, target;
        std::vector<Eigen::Vector2d> beside;  // (along t, along out) of the samples beside a vertex
        SampleIndex::Queue queue, probe;
        for (const auto& loop : loops) {
            const size_t count = loop.vertices.size();
            for (size_t i = 0; i < count && count >= 3; ++i) {
                const int v = loop.vertices[i];
                if (uses[size_t(v)] != 1)
                    continue;
                const Eigen::Vector3d q = PositionOf(mesh, v);
                const Eigen::Vector3d n = normal[size_t(v)].normalized();
                const Eigen::Vector3d along =
                    PositionOf(mesh, loop.vertices[(i + 1) % count]) - PositionOf(mesh, loop.vertices[(i + count - 1) % count]);
                samples.Nearest(q, p.neighbours, queue);
                // Out of the surface: away from the samples' centroid, in the tangent plane. A
                // marching cubes loop zigzags from cell to cell, so its own direction at a
                // vertex can be 45 degrees off the scan's edge.
                Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
                const int found = queue.getNofElements();
                for (int k = 0; k < found; ++k)
                    centroid += samples.P().row(queue.getIndex(k)).transpose();
                Eigen::Vector3d out = q - centroid / std::max(found, 1);
                out = (out - out.dot(n) * n).normalized();
                if (!out.allFinite() || out.dot(along.cross(n)) <= 0) {
                    // The samples' centroid lies beyond v: v sits in a notch of the loop, a
                    // dense row of samples along the edge outside it (a cut), or the samples
                    // go on past it (an orientation seam's cut). The loop's direction over
                    // kStencil vertices each way, past the notch's own turns, says where out
                    // is; whether the samples end there is asked below, as for every vertex.
                    const Eigen::Vector3d wide = PositionOf(mesh, loop.vertices[(i + kStencil) % count]) -
                                                 PositionOf(mesh, loop.vertices[(i + count - kStencil % count) % count]);
                    out = wide.cross(n).normalized();
                    if (!out.allFinite())
                        continue;
                }
                const Eigen::Vector3d t = n.cross(out);
                // The edge at v: the upper hull, over a (along t) and o (along out), of the
                // samples beside v (within a spacing along t and off the surface), at a = 0:
                // the line between a sample on each side of v with nothing beyond it, as a mesh
                // through the samples would run. Not the line between the outermost sample of
                // each side: where the nearer of them lies well inside the edge, that line runs
                // inside and pulls v inwards (the cut torus with the PU-RBF: a vertex 1.2 cells
                // inside the cut; 0.71 at most with the hull). A wider window than a spacing
                // lets the hull's chords cut across a curved edge: the punched sphere's mean
                // error went from 0.09 to 0.14 cells at 1.5 spacings.
                const double none = -std::numeric_limits<double>::infinity();
                double h = 0, nearest = std::numeric_limits<double>::infinity();
                beside.clear();
                for (int k = 0; k < found; ++k) {
                    const int s = queue.getIndex(k);
                    const Eigen::Vector3d d = samples.P().row(s).transpose() - q;
                    if (queue.getWeight(k) < nearest) {
                        nearest = queue.getWeight(k);
                        h = spacing[s];
                    }
                    if (std::abs(d.dot(t)) <= spacing[s] && std::abs(d.dot(n)) <= spacing[s])
                        beside.emplace_back(d.dot(t), d.dot(out));
                }
                double edge = none;
                for (const Eigen::Vector2d& l : beside)
                    for (const Eigen::Vector2d& r : beside)
                        if (l[0] < 0 && r[0] >= 0)
                            edge = std::max(edge, l[1] + (r[1] - l[1]) * -l[0] / (r[0] - l[0]));
                if (edge == none)  // samples on one side only: the outermost of them
                    for (const Eigen::Vector2d& b : beside)
                        edge = std::max(edge, b[1]);
                if (!(h > 0) || edge == none)
                    continue;
                // The samples end at an edge: no sample within a spacing of a point kBeyond
                // spacings past it. Where they go on (an orientation seam's cut, whose faces
                // are gone), there is no edge to move to.
                samples.Nearest(q + (edge + kBeyond * h) * out, 1, probe);
                if (probe.getNofElements() == 0 || probe.getWeight(0) < h * h)
                    continue;
                const double step = std::clamp(edge + p.offset * h, -p.max_move * h, p.max_move * h);
                moved.push_back(v);
                start.push_back(q);
                target.push_back(q + step * out);
            }
        }
        for (size_t i = 0; i < moved.size(); ++i)
            MoveVertex(mesh, moved[i], target[i]);
        const size_t fitted = moved.size();
        FollowMoves(mesh, uses, p.ring_steps, moved, start);
        if (f && p.newton_steps > 0 && p.cell_size > 0)
            ImplicitProjection::Compute(mesh, moved, *f, p.newton_steps, p.cell_size);
        FoldGuard::Restore(mesh, moved, start);
        return fitted;
    }

private:
    /// Moves the vertices that share a face with a `moved` vertex, and are on no loop, to the
    /// mean of their neighbours, `steps` times: marching cubes leaves thin faces at the
    /// boundary, which a boundary vertex moving by a cell would fold over; its neighbours
    /// follow instead. Appends them to `moved`, and their positions before, to `start`.
    static void FollowMoves(CoreMesh& mesh, const std::vector<int>& uses, int steps, std::vector<int>& moved,
                            std::vector<Eigen::Vector3d>& start)
    {
        std::vector<int> slot(mesh.vert.size(), -1);  // -2: a moved vertex; >= 0: in `ring`
        for (int v : moved)
            slot[size_t(v)] = -2;
        std::vector<int> ring;
        for (const CoreFace& face : mesh.face) {
            const int a = int(vcg::tri::Index(mesh, face.cV(0))), b = int(vcg::tri::Index(mesh, face.cV(1))),
                      c = int(vcg::tri::Index(mesh, face.cV(2)));
            if (slot[size_t(a)] != -2 && slot[size_t(b)] != -2 && slot[size_t(c)] != -2)
                continue;
            for (int v : {a, b, c})
                if (slot[size_t(v)] == -1 && uses[size_t(v)] == 0) {
                    slot[size_t(v)] = int(ring.size());
                    ring.push_back(v);
                }
        }
        for (int v : ring) {
            moved.push_back(v);
            start.push_back(PositionOf(mesh, v));
        }
        std::vector<std::vector<int>> neighbours(ring.size());
        for (const CoreFace& face : mesh.face)
            for (int i = 0; i < 3; ++i)
                if (const int s = slot[vcg::tri::Index(mesh, face.cV(i))]; s >= 0)
                    for (int j = 1; j < 3; ++j)
                        neighbours[size_t(s)].push_back(int(vcg::tri::Index(mesh, face.cV((i + j) % 3))));
        std::vector<Eigen::Vector3d> next(ring.size());
        for (int step = 0; step < steps; ++step) {
            for (size_t i = 0; i < ring.size(); ++i) {
                next[i].setZero();
                for (int w : neighbours[i])
                    next[i] += PositionOf(mesh, w);
                next[i] /= double(neighbours[i].size());
            }
            for (size_t i = 0; i < ring.size(); ++i)
                MoveVertex(mesh, ring[i], next[i]);
        }
    }

    /// Area-weighted normals (from the faces' orientation) of the surface faces around each
    /// vertex with uses[v] > 0; zero elsewhere.
    static std::vector<Eigen::Vector3d> SurfaceNormals(const CoreMesh& mesh, const std::vector<char>& inSurface,
                                                       const std::vector<int>& uses)
    {
        std::vector<Eigen::Vector3d> normal(mesh.vert.size(), Eigen::Vector3d::Zero());
        for (size_t f = 0; f < mesh.face.size(); ++f) {
            if (!inSurface[f])
                continue;
            const vcg::Point3d nf = vcg::TriangleNormal(mesh.face[f]);
            for (int i = 0; i < 3; ++i)
                if (const size_t v = vcg::tri::Index(mesh, mesh.face[f].cV(i)); uses[v] > 0)
                    normal[v] += Eigen::Vector3d(nf[0], nf[1], nf[2]);
        }
        return normal;
    }
};

} // namespace ib
