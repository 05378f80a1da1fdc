#pragma once
/// \file mesh.h
/// The triangle mesh type the core produces (VCGlib, double precision), independent of
/// MeshLab's CMeshO; the MeshLab glue copies it into a layer with vcg::tri::Append.

#include <vcg/complex/complex.h>

namespace ib {

class CoreVertex;
class CoreFace;
struct CoreUsedTypes : public vcg::UsedTypes<vcg::Use<CoreVertex>::AsVertexType, vcg::Use<CoreFace>::AsFaceType>
{
};
// Only what the core uses (normal estimation needs vertex normals and marks, the boundary
// steps face-face adjacency): a million-sample scan at a fine lattice makes millions of faces.
class CoreVertex : public vcg::Vertex<CoreUsedTypes, vcg::vertex::Coord3d, vcg::vertex::Normal3d,
                                      vcg::vertex::BitFlags, vcg::vertex::Mark>
{
};
class CoreFace : public vcg::Face<CoreUsedTypes, vcg::face::VertexRef, vcg::face::BitFlags, vcg::face::FFAdj>
{
};
class CoreMesh : public vcg::tri::TriMesh<std::vector<CoreVertex>, std::vector<CoreFace>>
{
};

} // namespace ib
