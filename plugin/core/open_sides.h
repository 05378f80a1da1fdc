#pragma once
/// \file open_sides.h
/// Open sides: the samples at a real boundary, where the sampling ends, and the direction in
/// which it ends. Their tangent disks should stop there (Sods::FromDisks' `open`) instead of
/// reaching a disk radius into empty space: where a thin tube ends (a countersunk hole's
/// stub), a full disk leans over its opening and covers it before any hole is judged.
///
/// The test is the classic boundary-point one (e.g. Bendels, Schnabel and Klein, "Detecting
/// holes in point set surfaces", WSCG 2006, the angle criterion): the neighbours facing the
/// sample's way, projected into its tangent plane, leave an angular gap wider than kGap around
/// it. A gap is no end of the surface when something lies ahead in it, beyond the sample: a
/// sample facing the same way among the 3 kNeighbours nearest (a gap in the sampling: the disks
/// bridge it, or the boundary stage judges the opening they leave, as without open sides), or
/// the other side where a thin part's rim or a crease turns, whose samples face away. Such
/// a sample counts when it lies within the sample's disk radius (the two sides' disks meet:
/// the part is thinner there than the disks resolve), or in the gap and either farther ahead
/// along it than off the tangent plane or facing into it: the other side of a plate beyond its
/// rim is nearly in the plane, a rounded rim's samples turn to face out, while across a thin
/// tube's open end the other wall lies along the normal, more than a disk radius away.

#include "parallel.h"
#include "samples.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace ib {

class OpenSides
{
public:
    /// Neighbours facing the sample's way that decide the gap.
    static constexpr int kNeighbours = 30;
    /// An angular gap wider than this (radians, 120 degrees) between them opens the sample.
    static constexpr double kGap = 2.0 * M_PI / 3.0;
    /// A sample facing away counts as ahead in the gap beyond this many disk radii.
    static constexpr double kAhead = 0.2;
    /// A sample facing away whose normal is within 60 degrees of the gap's direction faces into it.
    static constexpr double kFacesInto = 0.5;

    /// P: the n×3 samples of `samples`, N: n×3 unit normals (consistently oriented), radius:
    /// n tangent-disk radii (Sods::FromDisks). Returns n×3: per sample at an open side, the
    /// unit direction in its tangent plane towards the middle of its gap; else a zero row.
    static Points Compute(const SampleIndex& samples, const Points& N, const Eigen::VectorXd& radius, int threads = 0)
    {
        const Points& P = samples.P();
        Points open = Points::Zero(P.rows(), 3);
        // Across a thin part half the nearest face away: ask for more to find kNeighbours
        // facing this way.
        const int full = std::min<int>(3 * kNeighbours, int(P.rows()) - 1) + 1;
        const int first = std::min<int>(kNeighbours, int(P.rows()) - 1) + 1;
        if (full < 4)
            return open;
        ParallelFor(size_t(P.rows()), threads, [&](size_t begin, size_t end, int) {
            SampleIndex::Queue queue;
            std::vector<std::pair<double, Eigen::Index>> near;
            std::vector<double> angles;
            for (size_t s = begin; s < end; ++s) {
                const Eigen::Index i = Eigen::Index(s);
                const Eigen::Vector3d p = P.row(i).transpose(), n = N.row(i).transpose();
                const Eigen::Vector3d u = AnyPerpendicular(n), v = n.cross(u);
                // Most samples are surrounded, which those facing this way among the nearest
                // kNeighbours show without the longer query: fewer neighbours leave gaps at
                // least as wide.
                for (int asked : {first, full}) {
                    samples.Nearest(p, asked, queue);
                    near.clear();
                    for (int q = 0; q < queue.getNofElements(); ++q)
                        if (queue.getIndex(q) != i)
                            near.emplace_back(queue.getWeight(q), Eigen::Index(queue.getIndex(q)));
                    std::sort(near.begin(), near.end());
                    // The nearest kNeighbours facing this way, and everything nearer than the last.
                    size_t count = 0, facing = 0;
                    while (count < near.size() && facing < size_t(kNeighbours))
                        facing += N.row(near[count++].second).dot(n) > 0;
                    const Gap gap = LargestGap(P, N, near, count, p, n, u, v, angles);
                    if (gap.measured && gap.width <= kGap)
                        break;
                    if (asked != full)
                        continue;
                    if (!gap.measured)
                        break;
                    const Eigen::Vector3d o = std::cos(gap.middle) * u + std::sin(gap.middle) * v;
                    if (!SurfaceGoesOn(P, N, near, count, p, n, o, std::cos(gap.width / 2), radius[i]))
                        open.row(i) = o.transpose();
                }
            }
        }, 256);
        return open;
    }

private:
    struct Gap
    {
        bool measured = false;  ///< at least 3 neighbours facing this way
        double width = 0;       ///< radians
        double middle = 0;      ///< its direction's angle in the frame (u, v)
    };

    /// The widest angular gap between the first `count` of `near` that face n's way, projected
    /// into the tangent plane at p with axes u, v (angles: scratch space).
    static Gap LargestGap(const Points& P, const Points& N, const std::vector<std::pair<double, Eigen::Index>>& near,
                          size_t count, const Eigen::Vector3d& p, const Eigen::Vector3d& n, const Eigen::Vector3d& u,
                          const Eigen::Vector3d& v, std::vector<double>& angles)
    {
        angles.clear();
        for (size_t q = 0; q < count; ++q) {
            const Eigen::Index j = near[q].second;
            const Eigen::Vector3d d = P.row(j).transpose() - p;
            if (N.row(j).dot(n) > 0 && (d - d.dot(n) * n).squaredNorm() > 1e-18 * d.squaredNorm())
                angles.push_back(std::atan2(d.dot(v), d.dot(u)));
        }
        Gap gap;
        if (angles.size() < 3)
            return gap;
        std::sort(angles.begin(), angles.end());
        gap.measured = true;
        gap.width = angles.front() + 2 * M_PI - angles.back();
        double from = angles.back();
        for (size_t a = 1; a < angles.size(); ++a)
            if (angles[a] - angles[a - 1] > gap.width) {
                gap.width = angles[a] - angles[a - 1];
                from = angles[a - 1];
            }
        gap.middle = from + gap.width / 2;
        return gap;
    }

    static Eigen::Vector3d AnyPerpendicular(const Eigen::Vector3d& n)
    {
        const Eigen::Vector3d axis = std::abs(n[0]) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
        return n.cross(axis).normalized();
    }

    /// Whether the surface goes on past the gap: one of `near` (squared distances and rows,
    /// sorted) past the first `count` that faces n's way lies in the gap (within the angle of
    /// cosine `within` of o in the tangent plane), more than kAhead radii ahead along o; or one of
    /// the first `count` faces away and lies within `radius`, or lies in the gap and either
    /// farther ahead along o than kAhead radii and than its distance off the tangent plane, or
    /// faces into the gap.
    static bool SurfaceGoesOn(const Points& P, const Points& N,
                              const std::vector<std::pair<double, Eigen::Index>>& near, size_t count,
                              const Eigen::Vector3d& p, const Eigen::Vector3d& n, const Eigen::Vector3d& o,
                              double within, double radius)
    {
        const double ahead = kAhead * radius;
        for (size_t q = 0; q < near.size(); ++q) {
            const Eigen::Index j = near[q].second;
            const Eigen::Vector3d d = P.row(j).transpose() - p;
            const double along = d.dot(o);
            const bool inGap = along > within * (d - d.dot(n) * n).norm();
            if (N.row(j).dot(n) > 0) {
                // Past the ones that bound the gap: a gap in the sampling, with the surface
                // going on beyond it; whether it is a hole is the boundary stage's to decide.
                if (q >= count && inGap && along > ahead)
                    return true;
                continue;
            }
            if (q >= count)
                continue;
            if (near[q].first < radius * radius)
                return true;
            if (inGap && (along > std::max(ahead, std::abs(d.dot(n))) || N.row(j).dot(o) > kFacesInto))
                return true;
        }
        return false;
    }
};

} // namespace ib
