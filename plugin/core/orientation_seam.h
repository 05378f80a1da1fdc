#pragma once
/// \file orientation_seam.h
/// Orientation seams: where neighbouring samples lie in each other's tangent plane but their
/// normals point to opposite sides, the normals have flipped along the surface (a one-sided
/// surface such as a Möbius strip, or a region that normal propagation turned inside out). No
/// signed implicit function can follow such a flip: its zero set there forms walls across the
/// surface that join it in knots (handles, extra loops), differently for every implicit. The
/// seam is cut instead: surface faces near a seam point are moved into the holes, leaving one
/// clean boundary across the surface.
/// Opposite normals across a thin part (the two sides of a plate) are not a seam: there each
/// sample lies off the other's tangent plane by the part's thickness. Nor along a sharp fold
/// (a thin part's rim, a narrow V-groove's crease), where the two sides meet: the pairs right
/// at the fold lie in each other's tangent planes, but the sample's other opposite-facing
/// neighbours, a little way along the other side, lie off its tangent plane; on a flipped
/// sheet every opposite-facing neighbour lies in it.

#include "mesh.h"
#include "parallel.h"
#include "samples.h"

#include <cmath>
#include <vector>

namespace ib {

class OrientationSeam
{
public:
    /// Normals at more than 120 degrees to each other disagree.
    static constexpr double kOpposite = -0.5;
    /// Neighbours within this many local spacings are compared.
    static constexpr double kNeighbourhood = 1.5;
    /// A neighbour within this many local spacings of the other's tangent plane lies in it
    /// (plates thinner than that are below what the samples resolve).
    static constexpr double kInPlane = 0.25;

    /// Per sample, how far its opposite-facing neighbours (normals over 120 degrees apart,
    /// within kNeighbourhood spacings, of the same scan) lie off its tangent plane at most: 0
    /// on a sheet with nothing facing it; about the distance to the other side at a thin part's
    /// rim or a narrow groove's crease. A sample is at a fold when this is at least kInPlane
    /// spacings. spacing and scan as in Find.
    static Eigen::VectorXd FoldWidths(const SampleIndex& samples, const Points& N, const Eigen::VectorXd& spacing,
                                      int threads = 0, const std::vector<int>& scan = {})
    {
        const Points& P = samples.P();
        const int k = std::min<int>(8, int(P.rows()) - 1);
        Eigen::VectorXd width = Eigen::VectorXd::Zero(P.rows());
        ParallelFor(size_t(P.rows()), threads, [&](size_t begin, size_t end, int) {
            SampleIndex::Queue queue;
            for (size_t i = begin; i < end; ++i) {
                const Eigen::Index a = Eigen::Index(i);
                samples.Nearest(P.row(a).transpose(), k + 1, queue);
                for (int q = 0; q < queue.getNofElements(); ++q) {
                    const Eigen::Index b = queue.getIndex(q);
                    if ((scan.empty() || scan[size_t(a)] == scan[size_t(b)]) && Opposite(P, N, a, b, spacing[a]))
                        width[a] = std::max(width[a], std::abs((P.row(b) - P.row(a)).dot(N.row(a))));
                }
            }
        }, 256);
        return width;
    }

    /// Seam points: the midpoints of the neighbouring pairs (i, j), i < j, of samples whose unit
    /// normals N (n×3) disagree while each lies in the other's tangent plane, neither at a fold
    /// (foldWidth: FoldWidths of the same samples). spacing: per sample, its local spacing.
    /// scan: per sample, its scan when several are merged; pairs from different scans are
    /// skipped: a registration error cannot flip a normal, so a flip there is one scan's wrong
    /// normal at a grazing border, which the implicit function outvotes (cutting there opened
    /// 11 of the 31 loops of the 9 merged Stanford bunny scans). Returns m×3 points, m = 0 for
    /// consistently oriented samples.
    static Points Find(const SampleIndex& samples, const Points& N, const Eigen::VectorXd& spacing,
                       const Eigen::VectorXd& foldWidth, int threads = 0, const std::vector<int>& scan = {})
    {
        const Points& P = samples.P();
        const int k = std::min<int>(8, int(P.rows()) - 1);
        auto fold = [&](Eigen::Index a) { return foldWidth[a] >= kInPlane * spacing[a]; };
        // Per sample, its seam partners of higher index: the order of the points does not
        // depend on the thread count.
        std::vector<std::vector<Eigen::Index>> partners(size_t(P.rows()));
        ParallelFor(size_t(P.rows()), threads, [&](size_t begin, size_t end, int) {
            SampleIndex::Queue queue;
            for (size_t i = begin; i < end; ++i) {
                const Eigen::Index a = Eigen::Index(i);
                if (fold(a))
                    continue;
                samples.Nearest(P.row(a).transpose(), k + 1, queue);
                for (int q = 0; q < queue.getNofElements(); ++q) {
                    const Eigen::Index b = queue.getIndex(q);
                    if (b > a && !fold(b) && (scan.empty() || scan[size_t(a)] == scan[size_t(b)]) &&
                        Opposite(P, N, a, b, spacing[a]) && InPlane(P, N, a, b, spacing[a]))
                        partners[i].push_back(b);
                }
            }
        }, 256);
        std::vector<Eigen::Vector3d> mid;
        for (Eigen::Index a = 0; a < P.rows(); ++a)
            for (Eigen::Index b : partners[size_t(a)])
                mid.push_back(0.5 * (P.row(a) + P.row(b)).transpose());
        Points out(Eigen::Index(mid.size()), 3);
        for (size_t i = 0; i < mid.size(); ++i)
            out.row(Eigen::Index(i)) = mid[i].transpose();
        return out;
    }

    /// Among the faces f of `mesh` with inSurface[f], removes (sets to 0) those whose centroid
    /// lies within `radius` of a seam point (rows of `seam`). Returns the number removed.
    static size_t Cut(const CoreMesh& mesh, const Points& seam, double radius, std::vector<char>& inSurface,
                      int threads = 0)
    {
        if (seam.rows() == 0)
            return 0;
        const SampleIndex index(seam);
        std::vector<char> cut(mesh.face.size(), 0);
        ParallelFor(mesh.face.size(), threads, [&](size_t begin, size_t end, int) {
            SampleIndex::Queue queue;
            for (size_t f = begin; f < end; ++f) {
                if (!inSurface[f])
                    continue;
                const vcg::Point3d c = vcg::Barycenter(mesh.face[f]);
                index.Nearest(Eigen::Vector3d(c[0], c[1], c[2]), 1, queue);
                cut[f] = queue.getWeight(0) < radius * radius;
            }
        });
        size_t removed = 0;
        for (size_t f = 0; f < cut.size(); ++f)
            if (cut[f]) {
                inSurface[f] = 0;
                ++removed;
            }
        return removed;
    }

private:
    /// Neighbours (within kNeighbourhood spacings) whose normals disagree.
    static bool Opposite(const Points& P, const Points& N, Eigen::Index a, Eigen::Index b, double spacing)
    {
        return N.row(a).dot(N.row(b)) < kOpposite && (P.row(b) - P.row(a)).norm() <= kNeighbourhood * spacing;
    }

    /// Each lies in the other's tangent plane.
    static bool InPlane(const Points& P, const Points& N, Eigen::Index a, Eigen::Index b, double spacing)
    {
        const Eigen::RowVector3d d = P.row(b) - P.row(a);
        return std::abs(d.dot(N.row(a))) < kInPlane * spacing && std::abs(d.dot(N.row(b))) < kInPlane * spacing;
    }
};

} // namespace ib
