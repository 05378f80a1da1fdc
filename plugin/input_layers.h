#ifndef INPUT_LAYERS_H
#define INPUT_LAYERS_H

// Reading the user's layers into the core's matrices: the samples of the current layer or of
// every visible one (each through its transformation matrix), the directions estimated normals
// face, and a mesh layer as the implicit function.

#include <common/plugins/interfaces/filter_plugin.h>

#include "core/implicit/mesh_distance.h"
#include "core/lattice.h"

#include <memory>
#include <optional>
#include <vector>

namespace ib_plugin {

/// Which layers oriented estimated normals by what (facingMatrix).
struct FacingSources
{
	int cameras = 0, triangles = 0, viewpoint = 0;
};

/// The current layer, or every visible layer with vertices when `merge`; their matrices checked.
std::vector<const MeshModel*> inputLayers(const MeshDocument& md, bool merge);
/// The vertices (normals = false) or normals of `layers`, one after the other.
ib::Points stackedMatrix(const std::vector<const MeshModel*>& layers, bool normals);
/// The faces of layer `m` (rows as the vertices of stackedMatrix: deleted ones skipped).
ib::Faces faceMatrix(const CMeshO& m);
/// Per vertex of `layers`, the direction its estimated normal must face (zero: unknown).
ib::Points facingMatrix(const std::vector<const MeshModel*>& layers, const std::optional<Eigen::Vector3d>& viewpoint,
						FacingSources& used);
/// The signed distance to the mesh layer `id`, or an MLException saying why it cannot be one.
std::unique_ptr<ib::MeshDistance> implicitMesh(MeshDocument& md, unsigned int id);

} // namespace ib_plugin

#endif
