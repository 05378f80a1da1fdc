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
class CoreVertex : public vcg::Vertex<CoreUsedTypes, vcg::vertex::Coord3d, vcg::vertex::Normal3d,
                                      vcg::vertex::BitFlags, vcg::vertex::VFAdj, vcg::vertex::Mark>
{
};
class CoreFace : public vcg::Face<CoreUsedTypes, vcg::face::VertexRef, vcg::face::Normal3d,
                                  vcg::face::BitFlags, vcg::face::FFAdj, vcg::face::VFAdj, vcg::face::Mark>
{
};
class CoreMesh : public vcg::tri::TriMesh<std::vector<CoreVertex>, std::vector<CoreFace>>
{
};

} // namespace ib
