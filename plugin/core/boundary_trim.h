#pragma once
/// \file boundary_trim.h
/// Peels off the rim of surface that the SODS lets past the last samples. Tangent disks (or
/// the paper's dilation) extend the occupancy beyond a scan's boundary by their radius, and
/// the implicit surface fills that margin. Starting at the boundary, a face is removed when it
/// is unsupported: its centroid is farther from its nearest sample than that sample's `reach`,
/// and the samples around it all lie to one side (seen from the centroid in the face's plane,
/// their directions leave a gap wider than kOutsideGap). Then its neighbours are examined in
/// turn. The side test keeps the peel out of the gaps between samples inside the scan, which
/// can be as wide as the reach on a regular grid (a square grid's gaps are 0.71 spacings).

#include "mesh.h"
#include "parallel.h"
#include "samples.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <deque>
#include <vector>

namespace ib {

class BoundaryTrim
{
public:
    static constexpr double kOutsideGap = 135 * M_PI / 180;
    static constexpr int kAround = 8;  ///< samples examined around a face
    /// How far, in its own spacings, a sample across the gap may be; probes reach this many
    /// times the nearest sample's distance into the gap.
    static constexpr double kAcross = 2.0;
    static constexpr double kAcrossProbes = 8.0;
    /// A sample across the gap counts when it lies within this angle of the gap's middle
    /// direction (beyond the face, not beside it along the scan's edge) and its spacing is at
    /// least kSparser times the nearest sample's (a sparser part: where both sides are sampled
    /// alike, a gap wider than the near side's sampling leaves is a hole).
    static constexpr double kAcrossAngle = M_PI / 4;
    static constexpr double kSparser = 3.0;

    /// Among the faces f of `mesh` with inSurface[f], removes (sets inSurface[f] = 0) those
    /// reachable from the boundary through unsupported faces. reach: per sample, the largest
    /// supported distance. Needs the mesh's face-face adjacency (vcg UpdateTopology::FaceFace),
    /// built once for the whole extraction: surface membership is read from inSurface.
    /// Returns the number of faces removed.
    /// `spacing`, when given (per sample, its local spacing), lets a face whose nearest samples
    /// lie to one side look across the gap: where a sample beyond it lies within kAcross of its
    /// own spacings, the face is in a gap of that sample's sampling (a sparse part beside a
    /// dense one), not past the scan's edge, and stays.
    static size_t Compute(const CoreMesh& mesh, const SampleIndex& samples, const Eigen::VectorXd& reach,
                          std::vector<char>& inSurface, int threads = 0, const Eigen::VectorXd* spacing = nullptr)
    {
        const size_t n = mesh.face.size();
        std::vector<char> far(n, 0);
        ParallelFor(n, threads, [&](size_t begin, size_t end, int) {
            SampleIndex::Queue queue;
            for (size_t f = begin; f < end; ++f) {
                if (!inSurface[f])
                    continue;
                const vcg::Point3d c = vcg::Barycenter(mesh.face[f]);
                samples.Nearest(Eigen::Vector3d(c[0], c[1], c[2]), 1, queue);
                far[f] = std::sqrt(queue.getWeight(0)) > reach[queue.getIndex(0)];
            }
        });
        SampleIndex::Queue queue;
        auto unsupported = [&](size_t f) { return far[f] && SamplesOnOneSide(mesh.face[f], samples, queue, spacing); };

        std::deque<int> pending;
        for (size_t f = 0; f < n; ++f)
            if (inSurface[f] && far[f])
                for (int i = 0; i < 3; ++i)
                    if (Across(mesh, f, i, inSurface) < 0) {
                        pending.push_back(int(f));
                        break;
                    }
        size_t removed = 0;
        while (!pending.empty()) {
            const size_t f = size_t(pending.front());
            pending.pop_front();
            if (!inSurface[f] || !unsupported(f))
                continue;
            inSurface[f] = 0;
            ++removed;
            for (int i = 0; i < 3; ++i)
                if (const int g = Across(mesh, f, i, inSurface); g >= 0)
                    pending.push_back(g);
        }
        return removed;
    }

    /// Removes (sets inSurface to 0) the connected pieces of surface with fewer than
    /// `min_faces` faces: the scraps a trim leaves beside a boundary. Needs face-face
    /// adjacency, as Compute. Returns faces removed.
    static size_t RemoveScraps(const CoreMesh& mesh, std::vector<char>& inSurface, size_t min_faces)
    {
        size_t removed = 0;
        for (const std::vector<int>& piece : Pieces(mesh, inSurface))
            if (piece.size() < min_faces) {
                for (int f : piece)
                    inSurface[size_t(f)] = 0;
                removed += piece.size();
            }
        return removed;
    }

    /// Removes (sets inSurface to 0) the connected pieces of surface whose faces have fewer
    /// than `min_samples` distinct nearest samples: a surface needs that many samples to be
    /// defined at all (the input's own minimum), so such a piece is the implicit function's
    /// bubble around a few stray samples off the surface (outliers that claim each other as
    /// neighbours in a group too small for outliers.h to tell), or a scrap of the trim. Needs
    /// face-face adjacency, as Compute. Returns faces removed.
    static size_t RemoveUnsupported(const CoreMesh& mesh, const SampleIndex& samples, size_t min_samples,
                                    std::vector<char>& inSurface)
    {
        size_t removed = 0;
        SampleIndex::Queue queue;
        for (const std::vector<int>& piece : Pieces(mesh, inSurface)) {
            std::vector<Eigen::Index> nearest;
            for (size_t i = 0; i < piece.size() && nearest.size() < min_samples; ++i) {
                const vcg::Point3d c = vcg::Barycenter(mesh.face[size_t(piece[i])]);
                samples.Nearest(Eigen::Vector3d(c[0], c[1], c[2]), 1, queue);
                if (std::find(nearest.begin(), nearest.end(), queue.getIndex(0)) == nearest.end())
                    nearest.push_back(queue.getIndex(0));
            }
            if (nearest.size() >= min_samples)
                continue;
            for (int f : piece)
                inSurface[size_t(f)] = 0;
            removed += piece.size();
        }
        return removed;
    }

private:
    /// The connected pieces of the faces with inSurface (face indices, each piece in the order
    /// of a breadth-first walk from its lowest face).
    static std::vector<std::vector<int>> Pieces(const CoreMesh& mesh, const std::vector<char>& inSurface)
    {
        std::vector<std::vector<int>> pieces;
        std::vector<char> seen(mesh.face.size(), 0);
        for (size_t seed = 0; seed < mesh.face.size(); ++seed) {
            if (!inSurface[seed] || seen[seed])
                continue;
            std::vector<int> members{int(seed)};
            seen[seed] = 1;
            for (size_t i = 0; i < members.size(); ++i)
                for (int e = 0; e < 3; ++e)
                    if (const int g = Across(mesh, size_t(members[i]), e, inSurface); g >= 0 && !seen[size_t(g)]) {
                        seen[size_t(g)] = 1;
                        members.push_back(g);
                    }
            pieces.push_back(std::move(members));
        }
        return pieces;
    }

    /// True when the kAround samples nearest to the face's centroid, projected onto the face's
    /// plane, leave an angular gap wider than kOutsideGap around it, and (with `spacing`) no
    /// sample across that gap is sparser and near enough (see Compute): looked for from points
    /// pushed into the gap's middle, 1, 2, 4, 8 times the nearest sample's distance.
    static bool SamplesOnOneSide(const CoreFace& face, const SampleIndex& samples, SampleIndex::Queue& queue,
                                 const Eigen::VectorXd* spacing = nullptr)
    {
        const vcg::Point3d bc = vcg::Barycenter(face), nn = vcg::TriangleNormal(face);
        const Eigen::Vector3d c(bc[0], bc[1], bc[2]);
        Eigen::Vector3d n(nn[0], nn[1], nn[2]);
        if (!(n.norm() > 0))
            return true;
        n.normalize();
        const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
        samples.Nearest(c, kAround, queue);
        // The query returns at most kAround; saying so lets GCC 12 see that std::sort stays
        // inside `angle` (-Warray-bounds otherwise follows its path for more than 16 elements).
        const int near = std::clamp(queue.getNofElements(), 0, kAround);
        if (near == 0)
            return true;
        std::array<double, kAround> angle;
        int closest = 0;  // the queue's slot of the nearest sample
        for (int i = 0; i < near; ++i) {
            const Eigen::Vector3d d = samples.P().row(queue.getIndex(i)).transpose() - c;
            angle[size_t(i)] = std::atan2(d.dot(v), d.dot(u));
            if (queue.getWeight(i) < queue.getWeight(closest))
                closest = i;
        }
        std::sort(angle.begin(), angle.begin() + near);
        double gap = angle[0] + 2 * M_PI - angle[size_t(near - 1)], from = angle[size_t(near - 1)];
        for (int i = 1; i < near; ++i)
            if (angle[size_t(i)] - angle[size_t(i - 1)] > gap) {
                gap = angle[size_t(i)] - angle[size_t(i - 1)];
                from = angle[size_t(i - 1)];
            }
        if (gap <= kOutsideGap)
            return false;
        if (!spacing)
            return true;
        // Look across: probe points pushed from the centroid into the gap, farther each time.
        const double nearSpacing = (*spacing)[queue.getIndex(closest)];
        const double nearest = std::sqrt(queue.getWeight(closest));
        const double middle = from + gap / 2;
        const Eigen::Vector3d m = std::cos(middle) * u + std::sin(middle) * v;
        SampleIndex::Queue across;
        for (double t = nearest; t <= kAcrossProbes * nearest; t *= 2) {
            samples.Nearest(c + t * m, 1, across);
            const Eigen::Index j = across.getIndex(0);
            const Eigen::Vector3d d = samples.P().row(j).transpose() - c;
            const double own = (*spacing)[j];
            if (own >= kSparser * nearSpacing && d.norm() <= kAcross * own &&
                std::abs(std::remainder(std::atan2(d.dot(v), d.dot(u)) - middle, 2 * M_PI)) < kAcrossAngle)
                return false;
        }
        return true;
    }

    /// The surface face across edge i of face f, or -1 (a border, or a face not in the surface).
    static int Across(const CoreMesh& mesh, size_t f, int i, const std::vector<char>& inSurface)
    {
        const CoreFace* g = mesh.face[f].cFFp(i);
        const size_t index = vcg::tri::Index(mesh, g);
        return g == &mesh.face[f] || !inSurface[index] ? -1 : int(index);
    }
};

} // namespace ib
