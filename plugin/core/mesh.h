#pragma once
/// \file mesh.h
/// The triangle mesh type the core produces (VCGlib, double precision), independent of
/// MeshLab's CMeshO; the MeshLab glue copies it into a layer with vcg::tri::Append.

#include <vcg/complex/complex.h>

#include <Eigen/Core>

#include <vector>

namespace ib {

class CoreVertex;
class CoreFace;
struct CoreUsedTypes : public vcg::UsedTypes<vcg::Use<CoreVertex>::AsVertexType, vcg::Use<CoreFace>::AsFaceType>
{
};
// Only what the core uses (the boundary steps need face-face adjacency): a million-sample scan
// at a fine lattice makes millions of faces.
class CoreVertex : public vcg::Vertex<CoreUsedTypes, vcg::vertex::Coord3d, vcg::vertex::BitFlags>
{
};
class CoreFace : public vcg::Face<CoreUsedTypes, vcg::face::VertexRef, vcg::face::BitFlags, vcg::face::FFAdj>
{
};
class CoreMesh : public vcg::tri::TriMesh<std::vector<CoreVertex>, std::vector<CoreFace>>
{
};

/// Position of vertex v of m.
inline Eigen::Vector3d PositionOf(const CoreMesh& m, int v)
{
    const auto& q = m.vert[size_t(v)].cP();
    return Eigen::Vector3d(q[0], q[1], q[2]);
}

/// Moves vertex v of m to p.
inline void MoveVertex(CoreMesh& m, int v, const Eigen::Vector3d& p)
{
    m.vert[size_t(v)].P() = vcg::Point3d(p[0], p[1], p[2]);
}

/// Face-face adjacency of an edge-manifold mesh (marching cubes output), the same as
/// vcg::tri::UpdateTopology::FaceFace gives (a border edge points to its own face), found
/// through the faces around each vertex: about 16 bytes per face of scratch instead of the
/// 100 of VCG's sorted edge list, which matters at millions of faces. Where more than two faces
/// share an edge, each is linked to the first other one found.
inline void UpdateFaceFace(CoreMesh& mesh)
{
    const size_t nv = mesh.vert.size(), nf = mesh.face.size();
    std::vector<uint32_t> first(nv + 1, 0), around(3 * nf);
    for (const CoreFace& f : mesh.face)
        for (int i = 0; i < 3; ++i)
            ++first[vcg::tri::Index(mesh, f.cV(i)) + 1];
    for (size_t v = 0; v < nv; ++v)
        first[v + 1] += first[v];
    std::vector<uint32_t> next(first.begin(), first.end() - 1);
    for (size_t f = 0; f < nf; ++f)
        for (int i = 0; i < 3; ++i)
            around[next[vcg::tri::Index(mesh, mesh.face[f].cV(i))]++] = uint32_t(f);
    for (size_t f = 0; f < nf; ++f) {
        CoreFace& face = mesh.face[f];
        for (int i = 0; i < 3; ++i) {
            face.FFp(i) = &face;
            face.FFi(i) = char(i);
            const CoreVertex* a = face.cV(i);
            const CoreVertex* b = face.cV((i + 1) % 3);
            const size_t va = vcg::tri::Index(mesh, a);
            for (uint32_t k = first[va]; k < first[va + 1]; ++k) {
                CoreFace& other = mesh.face[around[k]];
                if (&other == &face)
                    continue;
                int j = 0;
                while (j < 3 && !(other.cV(j) == b && other.cV((j + 1) % 3) == a) &&
                       !(other.cV(j) == a && other.cV((j + 1) % 3) == b))
                    ++j;
                if (j < 3) {
                    face.FFp(i) = &other;
                    face.FFi(i) = char(j);
                    break;
                }
            }
        }
    }
}

} // namespace ib
