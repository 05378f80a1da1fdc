#pragma once
/// \file mesh_distance.h
/// Signed distance to a triangle mesh, so that any closed surface (screened Poisson's output,
/// a CAD model, another reconstruction) can serve as the implicit function whose surface the
/// SODS gates (the paper's claim that the method works on top of any implicit function).
///
/// Distance: to the closest point on the mesh, found with VCGlib's uniform grid over the faces
/// (vcg::GridStaticPtr, queried without marks so that threads can share it). Sign: from the
/// angle-weighted pseudo-normal of the closest feature, after
/// J. A. Bærentzen, H. Aanæs, "Signed distance computation using the angle weighted
/// pseudonormal", IEEE TVCG 11(3), 2005: the face normal when the closest point is inside a
/// face, the sum of the two face normals at an edge, the angle-weighted vertex normal at a
/// vertex. For a closed, outward-oriented 2-manifold this is exactly the sign of the point's
/// side. For a mesh that is not perfectly closed (a crack, a missing face, a non-manifold
/// edge) the sign still comes from the nearest surface's orientation, so it is right near the
/// mesh, where marching cubes looks; only points whose nearest feature is a crack's rim get the
/// rim faces' side, which flips the sign at most in a thin wedge beyond the crack. A winding
/// number would be exact far from the mesh but costs a pass over all faces per query.
///
/// Sign convention (implicit_function.h): negative inside (against the face normals).
///
/// The same closest-point query tells how far a point lies past an open mesh's border
/// (PastBorder), which keeps an input mesh's holes open (mesh_holes.h). Most points asked are
/// nowhere near a border, and those are answered without the closest-point search: see
/// BorderMargin.

#include "implicit_function.h"
#include "../parallel.h"
#include "../samples.h"

#include <vcg/complex/complex.h>
#include <vcg/complex/algorithms/clean.h>
#include <vcg/complex/algorithms/closest.h>
#include <vcg/complex/algorithms/update/normal.h>
#include <vcg/complex/algorithms/update/topology.h>
#include <vcg/space/index/grid_static_ptr.h>

#include <algorithm>
#include <limits>
#include <memory>
#include <stdexcept>
#include <vector>

namespace ib {

class DistanceVertex;
class DistanceFace;
struct DistanceUsedTypes
    : public vcg::UsedTypes<vcg::Use<DistanceVertex>::AsVertexType, vcg::Use<DistanceFace>::AsFaceType>
{
};
class DistanceVertex : public vcg::Vertex<DistanceUsedTypes, vcg::vertex::Coord3d, vcg::vertex::Normal3d,
                                          vcg::vertex::BitFlags, vcg::vertex::Mark>
{
};
class DistanceFace : public vcg::Face<DistanceUsedTypes, vcg::face::VertexRef, vcg::face::Normal3d,
                                      vcg::face::BitFlags, vcg::face::FFAdj, vcg::face::Mark>
{
};
class DistanceMesh : public vcg::tri::TriMesh<std::vector<DistanceVertex>, std::vector<DistanceFace>>
{
};

class MeshDistance : public ImplicitFunction
{
public:
    struct Stats
    {
        size_t faces = 0;            ///< faces used (after cleaning)
        size_t degenerate_faces = 0; ///< zero-area or repeated-vertex faces dropped
        int border_edges = 0;        ///< edges with one face: the mesh is not closed
        int non_manifold_edges = 0;
    };

    /// V: n×3 vertex positions; F: m×3 vertex indices of triangles oriented outwards (normals
    /// by the right-hand rule point to the outside). Both are copied. Throws
    /// std::invalid_argument when no usable face remains or indices are out of range.
    MeshDistance(const Points& V, const Faces& F, int threads = 0)
        : threads_(threads)
    {
        if (F.rows() == 0)
            throw std::invalid_argument("the implicit mesh has no faces");
        if ((F.array() < 0).any() || (F.array() >= V.rows()).any())
            throw std::invalid_argument("the implicit mesh has face indices out of range");
        if (!V.array().isFinite().all())
            throw std::invalid_argument("the implicit mesh has NaN or infinite vertex coordinates");
        auto vi = vcg::tri::Allocator<DistanceMesh>::AddVertices(mesh_, size_t(V.rows()));
        for (Eigen::Index i = 0; i < V.rows(); ++i, ++vi)
            vi->P() = vcg::Point3d(V(i, 0), V(i, 1), V(i, 2));
        auto fi = vcg::tri::Allocator<DistanceMesh>::AddFaces(mesh_, size_t(F.rows()));
        for (Eigen::Index i = 0; i < F.rows(); ++i, ++fi)
            for (int k = 0; k < 3; ++k)
                fi->V(k) = &mesh_.vert[size_t(F(i, k))];

        // Coincident vertices are merged so that edges across them get both faces' normals.
        vcg::tri::Clean<DistanceMesh>::RemoveDuplicateVertex(mesh_);
        stats_.degenerate_faces = size_t(vcg::tri::Clean<DistanceMesh>::RemoveDegenerateFace(mesh_)) +
                                  size_t(vcg::tri::Clean<DistanceMesh>::RemoveZeroAreaFace(mesh_));
        vcg::tri::Clean<DistanceMesh>::RemoveUnreferencedVertex(mesh_);
        vcg::tri::Allocator<DistanceMesh>::CompactEveryVector(mesh_);
        if (mesh_.fn == 0)
            throw std::invalid_argument("the implicit mesh has only degenerate (zero-area) faces");
        stats_.faces = size_t(mesh_.fn);

        vcg::tri::UpdateTopology<DistanceMesh>::FaceFace(mesh_);
        int edges = 0;
        vcg::tri::Clean<DistanceMesh>::CountEdgeNum(mesh_, edges, stats_.border_edges, stats_.non_manifold_edges);
        vcg::tri::UpdateFlags<DistanceMesh>::FaceBorderFromFF(mesh_);
        vcg::tri::UpdateFlags<DistanceMesh>::VertexBorderFromFaceBorder(mesh_);
        vcg::tri::UpdateNormal<DistanceMesh>::PerFaceNormalized(mesh_);
        vcg::tri::UpdateNormal<DistanceMesh>::PerVertexAngleWeighted(mesh_);
        vcg::tri::UpdateNormal<DistanceMesh>::NormalizePerVertex(mesh_);
        vcg::tri::UpdateBounding<DistanceMesh>::Box(mesh_);
        grid_.Set(mesh_.face.begin(), mesh_.face.end());
        IndexBorder();
        maxDistance_ = std::max(1.0, 1e6 * mesh_.bbox.Diag());
    }

    MeshDistance(const MeshDistance&) = delete;  // the grid points into mesh_

    void Eval(const Points& Q, Eigen::Ref<Eigen::VectorXd> values) const override
    {
        ParallelFor(size_t(Q.rows()), threads_, [&](size_t begin, size_t end, int) {
            for (size_t i = begin; i < end; ++i)
                values[Eigen::Index(i)] = EvalOne(vcg::Point3d(Q(Eigen::Index(i), 0), Q(Eigen::Index(i), 1), Q(Eigen::Index(i), 2)));
        }, 256);
    }

    /// Per row of the n×3 points Q, how far it lies past the mesh's border: the length of
    /// p - q within the plane of the closest face, where q, p's closest point on the mesh, lies
    /// on a border edge or vertex; 0 when q lies inside a face or on an edge or vertex inside
    /// the mesh (p is over the mesh, at any height).
    Eigen::VectorXd PastBorder(const Points& Q) const
    {
        Eigen::VectorXd past(Q.rows());
        ParallelFor(size_t(Q.rows()), threads_, [&](size_t begin, size_t end, int) {
            SampleIndex::Queue queue;
            // Points asked in a row usually lie close together (faces of neighbouring cells):
            // the last point tested stands for every point within half its margin.
            Eigen::Vector3d tested = Eigen::Vector3d::Zero();
            double reach = -1;
            for (size_t i = begin; i < end; ++i) {
                const Eigen::Vector3d p = Q.row(Eigen::Index(i)).transpose();
                if (reach > 0 && (p - tested).squaredNorm() < reach * reach) {
                    past[Eigen::Index(i)] = 0;
                    continue;
                }
                const double margin = BorderMargin(p, queue);
                past[Eigen::Index(i)] = margin > 0 ? 0 : PastBorderOne(vcg::Point3d(p[0], p[1], p[2]));
                tested = p;
                reach = 0.5 * margin;
            }
        }, 256);
        return past;
    }

    const Stats& Statistics() const { return stats_; }

private:
    /// The feature of face f its point q lies on, told by q's barycentric coordinates: a vertex
    /// (its index in f), else an edge (edge e runs from vertex e to e + 1), else the face.
    struct Feature
    {
        int vertex = -1, edge = -1;
    };
    static Feature FeatureOf(const DistanceFace& f, const vcg::Point3d& q)
    {
        Feature feature;
        vcg::Point3d b;
        if (!vcg::InterpolationParameters(f, f.cN(), q, b))
            return feature;
        const double eps = 1e-9;
        int zeros = 0, zero = -1, one = -1;
        for (int k = 0; k < 3; ++k) {
            if (b[k] <= eps) {
                ++zeros;
                zero = k;
            } else {
                one = k;
            }
        }
        if (zeros >= 2)
            feature.vertex = one;
        else if (zeros == 1)  // on the edge opposite vertex `zero`
            feature.edge = (zero + 1) % 3;
        return feature;
    }

    const DistanceFace* Closest(const vcg::Point3d& p, double& d, vcg::Point3d& q) const
    {
        vcg::face::PointDistanceBaseFunctor<double> distance;
        vcg::tri::EmptyTMark<DistanceMesh> noMarks;
        d = maxDistance_;
        return grid_.GetClosest(distance, noMarks, p, maxDistance_, d, q);
    }

    /// Points along the border edges at most borderStep_ apart, ends included, and the indices
    /// of the mesh's vertices and of those points.
    void IndexBorder()
    {
        std::vector<double> lengths;
        for (const DistanceFace& f : mesh_.face)
            for (int e = 0; e < 3; ++e)
                lengths.push_back(vcg::Distance(f.cP(e), f.cP((e + 1) % 3)));
        std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
        borderStep_ = lengths[lengths.size() / 2];
        std::vector<Eigen::RowVector3d> along;
        for (const DistanceFace& f : mesh_.face)
            for (int e = 0; e < 3; ++e) {
                if (!f.IsB(e))
                    continue;
                const vcg::Point3d a = f.cP(e), b = f.cP((e + 1) % 3);
                const int pieces = std::max(1, int(std::ceil(vcg::Distance(a, b) / borderStep_)));
                for (int k = 0; k <= pieces; ++k) {
                    const vcg::Point3d q = a + (b - a) * (double(k) / pieces);
                    along.emplace_back(q[0], q[1], q[2]);
                }
            }
        if (along.empty())
            return;
        borderPoints_.resize(Eigen::Index(along.size()), 3);
        for (size_t i = 0; i < along.size(); ++i)
            borderPoints_.row(Eigen::Index(i)) = along[i];
        vertices_.resize(Eigen::Index(mesh_.vert.size()), 3);
        for (size_t i = 0; i < mesh_.vert.size(); ++i)
            vertices_.row(Eigen::Index(i)) << mesh_.vert[i].cP()[0], mesh_.vert[i].cP()[1], mesh_.vert[i].cP()[2];
        borderIndex_ = std::make_unique<SampleIndex>(borderPoints_);
        vertexIndex_ = std::make_unique<SampleIndex>(vertices_);
    }

    /// How far p's closest point on the mesh is from possibly lying on its border. That point
    /// is no farther from p than p's nearest vertex, and every point of the border lies within
    /// half a step of one of the points indexed along it, so when p's nearest indexed border
    /// point is farther than its nearest vertex plus half a step, p is over the mesh inside its
    /// border (PastBorderOne would find 0) and the margin, the difference, is positive. Moving
    /// p by d changes both distances by at most d, so the points within half the margin of p
    /// are inside too. Infinite for a closed mesh; zero or negative near the border.
    double BorderMargin(const Eigen::Vector3d& p, SampleIndex::Queue& queue) const
    {
        if (!borderIndex_)
            return std::numeric_limits<double>::infinity();
        vertexIndex_->Nearest(p, 1, queue);
        const double vertex = std::sqrt(queue.getWeight(0));
        borderIndex_->Nearest(p, 1, queue);
        const double border = std::sqrt(queue.getWeight(0));
        return border - (vertex + 0.5 * borderStep_ * (1 + 1e-9) + 1e-12 * maxDistance_);
    }

    double PastBorderOne(const vcg::Point3d& p) const
    {
        double d;
        vcg::Point3d q(0, 0, 0);
        const DistanceFace* f = Closest(p, d, q);
        if (f == nullptr)
            return 0;
        const Feature at = FeatureOf(*f, q);
        const bool border = at.vertex >= 0 ? f->cV(at.vertex)->IsB() : at.edge >= 0 && f->IsB(at.edge);
        if (!border)
            return 0;
        const vcg::Point3d offset = p - q;
        return (offset - f->cN() * offset.dot(f->cN())).Norm();
    }

    double EvalOne(const vcg::Point3d& p) const
    {
        double d;
        vcg::Point3d q(0, 0, 0);
        const DistanceFace* f = Closest(p, d, q);
        if (f == nullptr)  // cannot happen with a non-empty mesh and this search radius
            return maxDistance_;
        const vcg::Point3d n = PseudoNormal(*f, q);
        return (p - q).dot(n) < 0 ? -d : d;
    }

    /// The angle-weighted pseudo-normal at q, the closest point of face f.
    static vcg::Point3d PseudoNormal(const DistanceFace& f, const vcg::Point3d& q)
    {
        const Feature at = FeatureOf(f, q);
        if (at.vertex >= 0)
            return f.cV(at.vertex)->cN();
        if (at.edge >= 0)
            return f.cN() + f.cFFp(at.edge)->cN();  // a border edge's own face counts twice
        return f.cN();
    }

    DistanceMesh mesh_;
    Points vertices_, borderPoints_;                       // for BorderMargin; empty when closed
    std::unique_ptr<SampleIndex> vertexIndex_, borderIndex_;
    double borderStep_ = 0;
    // VCG's grid queries are not const but only read the grid (no marks with EmptyTMark).
    mutable vcg::GridStaticPtr<DistanceFace, double> grid_;
    double maxDistance_ = 1;
    Stats stats_;
    int threads_;
};

} // namespace ib
