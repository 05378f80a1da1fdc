#pragma once
/// \file scan_edges.h
/// The edges of merged range scans. A range scan is least reliable along its own edge
/// (silhouettes and grazing angles: mixed pixels pull samples off the surface), and where
/// scans overlap another scan usually sees the same surface from a better angle. Turk and
/// Levoy ("Zippered polygon meshes from range images", SIGGRAPH 1994) erode each scan's
/// border where another scan covers it before zippering; the implicit function here is fitted
/// without the covered edge samples for the same reason.

#include "parallel.h"
#include "samples.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace ib {

class ScanEdges
{
public:
    /// Neighbours within its own scan whose directions, seen in a sample's tangent plane,
    /// decide whether it lies on that scan's edge.
    static constexpr int kNeighbours = 12;
    /// A sample is on its scan's edge when its neighbours leave a gap wider than this (radians)
    /// around it: on a range grid an inner sample's largest gap is about 45 degrees.
    static constexpr double kEdgeGap = 0.5 * M_PI;
    /// Another scan covers an edge sample when one of its samples off its own edge lies within
    /// this many of the edge sample's spacings: registration leaves the sheets up to about a
    /// spacing apart along the normal, and the nearest sample of a sheet lies up to half a
    /// spacing aside.
    static constexpr double kCover = 1.5;

    /// Per sample (rows of samples.P(), unit normals N), 1 if it lies on the edge of its own
    /// scan (`scan`: the scan of each sample).
    static std::vector<char> Edges(const SampleIndex& samples, const Points& N, const std::vector<int>& scan,
                                   int threads)
    {
        const Points& P = samples.P();
        std::vector<char> edge(size_t(P.rows()), 0);
        const std::vector<std::vector<Eigen::Index>> rows = RowsOfScans(scan);
        for (const std::vector<Eigen::Index>& own : rows) {
            if (own.size() <= size_t(kNeighbours))
                continue;
            const Points Q = P(own, Eigen::all);
            const SampleIndex index(Q);
            ParallelFor(own.size(), threads, [&](size_t begin, size_t end, int) {
                SampleIndex::Queue queue;
                std::vector<double> angle;
                for (size_t k = begin; k < end; ++k) {
                    const Eigen::Index i = own[k];
                    const Eigen::Vector3d p = P.row(i).transpose(), n = N.row(i).transpose();
                    if (!(n.squaredNorm() > 0))
                        continue;
                    const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
                    index.Nearest(p, kNeighbours + 1, queue);
                    angle.clear();
                    for (int j = 0; j < queue.getNofElements(); ++j) {
                        const Eigen::Vector3d d = Q.row(queue.getIndex(j)).transpose() - p;
                        if (d.squaredNorm() > 0)
                            angle.push_back(std::atan2(d.dot(v), d.dot(u)));
                    }
                    if (angle.size() < 3)
                        continue;
                    std::sort(angle.begin(), angle.end());
                    double gap = angle.front() + 2 * M_PI - angle.back();
                    for (size_t j = 1; j < angle.size(); ++j)
                        gap = std::max(gap, angle[j] - angle[j - 1]);
                    edge[size_t(i)] = gap > kEdgeGap;
                }
            }, 256);
        }
        return edge;
    }

    /// Per sample, 1 if it is an edge sample (`edge`) with a sample of another scan, not on
    /// that scan's edge, within kCover times its local `spacing`.
    static std::vector<char> Covered(const SampleIndex& samples, const std::vector<char>& edge,
                                     const std::vector<int>& scan, const Eigen::VectorXd& spacing, int threads)
    {
        const Points& P = samples.P();
        std::vector<char> covered(size_t(P.rows()), 0);
        ParallelFor(size_t(P.rows()), threads, [&](size_t begin, size_t end, int) {
            SampleIndex::Queue queue;
            for (size_t i = begin; i < end; ++i) {
                if (!edge[i])
                    continue;
                // Overlapping scans multiply the density: 32 neighbours reach past the reach.
                samples.Nearest(P.row(Eigen::Index(i)).transpose(), 32, queue);
                const double reach = kCover * spacing[Eigen::Index(i)];
                for (int j = 0; j < queue.getNofElements() && !covered[i]; ++j) {
                    const size_t s = size_t(queue.getIndex(j));
                    covered[i] = scan[s] != scan[i] && !edge[s] && queue.getWeight(j) <= reach * reach;
                }
            }
        }, 256);
        return covered;
    }

    /// The rows of the samples a merged reconstruction fits its implicit function to, ascending:
    /// all but the edge samples (Edges, with unit normals N) that another scan covers (Covered).
    static std::vector<Eigen::Index> Uncovered(const SampleIndex& samples, const Points& N,
                                               const std::vector<int>& scan, const Eigen::VectorXd& spacing,
                                               int threads)
    {
        const std::vector<char> covered = Covered(samples, Edges(samples, N, scan, threads), scan, spacing, threads);
        std::vector<Eigen::Index> rows;
        for (size_t i = 0; i < covered.size(); ++i)
            if (!covered[i])
                rows.push_back(Eigen::Index(i));
        return rows;
    }
};

} // namespace ib
