#include "input_layers.h"

namespace {

/// The layer's vertex positions (normals = false) or normals, through its transformation
/// matrix: where the user sees them (MeshLab's Align tool and "Set matrix" leave the vertices
/// as they are and change the matrix). Normals go through the matrix's inverse transpose and
/// keep their length, so that zero normals stay zero (missing).
ib::Points vertexMatrix(const CMeshO& m, bool normals)
{
	Eigen::Matrix4d tr;
	for (int i = 0; i < 4; ++i)
		for (int j = 0; j < 4; ++j)
			tr(i, j) = double(m.Tr.ElementAt(i, j));
	const Eigen::Matrix3d linear = normals ? Eigen::Matrix3d(tr.topLeftCorner<3, 3>().inverse().transpose())
										   : Eigen::Matrix3d(tr.topLeftCorner<3, 3>());
	const Eigen::Vector3d shift = normals ? Eigen::Vector3d::Zero() : Eigen::Vector3d(tr.topRightCorner<3, 1>());
	ib::Points out(m.vn, 3);
	Eigen::Index row = 0;
	for (const auto& v : m.vert) {
		if (v.IsD())
			continue;
		const auto& p = normals ? v.cN() : v.cP();
		Eigen::Vector3d q = linear * Eigen::Vector3d(p[0], p[1], p[2]) + shift;
		if (normals && q.norm() > 0)
			q *= Eigen::Vector3d(p[0], p[1], p[2]).norm() / q.norm();
		out.row(row++) = q.transpose();
	}
	return out;
}

/// Refuses a layer whose transformation matrix is not affine (a last row other than 0 0 0 1:
/// MeshLab would divide by it, vertexMatrix does not) or collapses space (no inverse for the
/// normals). Scales and shears are fine: positions and normals both follow them.
void checkMatrix(const MeshModel& m)
{
	const Matrix44m& tr = m.cm.Tr;
	Eigen::Matrix3d linear;
	for (int i = 0; i < 3; ++i)
		for (int j = 0; j < 3; ++j)
			linear(i, j) = double(tr.ElementAt(i, j));
	const bool affine = tr.ElementAt(3, 0) == 0 && tr.ElementAt(3, 1) == 0 && tr.ElementAt(3, 2) == 0 &&
						tr.ElementAt(3, 3) == 1;
	const double scale = linear.norm();
	if (!affine || !linear.allFinite() || !(std::abs(linear.determinant()) > 1e-12 * scale * scale * scale))
		throw MLException(QString("The transformation matrix of layer '%1' is not affine or cannot be inverted (it projects, or "
								  "flattens the layer): set a valid one (Filters > Normals, Curvatures and "
								  "Orientation > Matrix: Set/Copy Transformation, or Matrix: Reset Current Matrix).")
							  .arg(m.label()));
}

} // namespace

namespace ib_plugin {

/// The layers whose vertices are the samples: every visible layer with vertices when merging
/// (as Screened Poisson's "Merge all visible layers": several aligned range scans), else the
/// current one.
std::vector<const MeshModel*> inputLayers(const MeshDocument& md, bool merge)
{
	std::vector<const MeshModel*> layers;
	if (!merge)
		layers.push_back(md.mm());
	else
		for (const MeshModel& m : md.meshIterator())
			if (m.isVisible() && m.cm.vn > 0)
				layers.push_back(&m);
	if (layers.empty())
		throw MLException("No visible layer has vertices: show the scans to merge (the eye icon in the layer "
						  "dialog), or turn off 'Merge visible layers' to use the current layer.");
	for (const MeshModel* m : layers)
		checkMatrix(*m);
	return layers;
}

/// The vertices (normals = false) or normals of `layers`, one after the other, each through its
/// own matrix.
ib::Points stackedMatrix(const std::vector<const MeshModel*>& layers, bool normals)
{
	Eigen::Index rows = 0;
	for (const MeshModel* m : layers)
		rows += m->cm.vn;
	ib::Points out(rows, 3);
	Eigen::Index row = 0;
	for (const MeshModel* m : layers) {
		out.middleRows(row, m->cm.vn) = vertexMatrix(m->cm, normals);
		row += m->cm.vn;
	}
	return out;
}

/// Read around deleted elements rather than compacting: the user's layer stays untouched.
ib::Faces faceMatrix(const CMeshO& m)
{
	std::vector<int> row(m.vert.size(), -1);
	int n = 0;
	for (size_t i = 0; i < m.vert.size(); ++i)
		if (!m.vert[i].IsD())
			row[i] = n++;
	ib::Faces F(m.fn, 3);
	int k = 0;
	for (const auto& f : m.face)
		if (!f.IsD()) {
			for (int c = 0; c < 3; ++c)
				F(k, c) = row[vcg::tri::Index(m, f.cV(c))];
			++k;
		}
	return F;
}

/// Per vertex of `layers` (rows as stackedMatrix), the direction its estimated normal must
/// face, in the common frame: towards the layer's camera when it has one (a scan imported with
/// its scanner's position), else along the layer's triangles around it (a range grid's
/// triangles face its scanner), else towards `viewpoint` when given; zero (unknown: oriented
/// by the neighbours) for a point layer with neither.
ib::Points facingMatrix(const std::vector<const MeshModel*>& layers, const std::optional<Eigen::Vector3d>& viewpoint,
						FacingSources& used)
{
	Eigen::Index rows = 0;
	for (const MeshModel* m : layers)
		rows += m->cm.vn;
	ib::Points out = ib::Points::Zero(rows, 3);
	Eigen::Index row = 0;
	for (const MeshModel* m : layers) {
		const ib::Points positions = vertexMatrix(m->cm, false);
		auto towards = [&](const Eigen::Vector3d& v) { out.middleRows(row, m->cm.vn) = (-positions).rowwise() + v.transpose(); };
		if (m->cm.shot.IsValid()) {
			const Point3m v = m->cm.Tr * m->cm.shot.GetViewPoint();  // the shot lies in the layer's own frame
			towards(Eigen::Vector3d(v[0], v[1], v[2]));
			++used.cameras;
		}
		else if (m->cm.fn > 0) {
			// Area-weighted normals of the triangles around each vertex (rows skip deleted
			// vertices, as vertexMatrix's), through the matrix's inverse transpose as normals go.
			std::vector<Eigen::Index> rowOf(m->cm.vert.size(), -1);
			Eigen::Index next = 0;
			for (size_t i = 0; i < m->cm.vert.size(); ++i)
				if (!m->cm.vert[i].IsD())
					rowOf[i] = next++;
			ib::Points sum = ib::Points::Zero(m->cm.vn, 3);
			for (const auto& f : m->cm.face) {
				if (f.IsD())
					continue;
				const Point3m n = vcg::TriangleNormal(f);
				for (int k = 0; k < 3; ++k)
					sum.row(rowOf[size_t(vcg::tri::Index(m->cm, f.cV(k)))]) += Eigen::RowVector3d(n[0], n[1], n[2]);
			}
			Eigen::Matrix3d linear;
			for (int i = 0; i < 3; ++i)
				for (int j = 0; j < 3; ++j)
					linear(i, j) = double(m->cm.Tr.ElementAt(i, j));
			out.middleRows(row, m->cm.vn) = sum * linear.inverse();  // rows: (M^-T n)^T = n^T M^-1
			++used.triangles;
		}
		else if (viewpoint) {
			towards(*viewpoint);
			++used.viewpoint;
		}
		row += m->cm.vn;
	}
	return out;
}

/// The signed distance to the mesh layer `id`, or an MLException saying why it cannot be one.
std::unique_ptr<ib::MeshDistance> implicitMesh(MeshDocument& md, unsigned int id)
{
	MeshModel* model = md.getMesh(id);
	if (model == nullptr)
		throw MLException("The implicit mesh layer does not exist: choose a mesh layer as 'Implicit mesh layer'.");
	if (model->cm.fn == 0)
		throw MLException(QString("The implicit mesh layer '%1' has no faces: choose a closed triangle mesh, e.g. the "
								  "output of Screened Poisson on the points.")
							  .arg(model->label()));
	const ib::Points V = vertexMatrix(model->cm, false);
	const ib::Faces F = faceMatrix(model->cm);
	try {
		return std::make_unique<ib::MeshDistance>(V, F);
	}
	catch (const std::invalid_argument& e) {
		throw MLException(QString("The implicit mesh layer '%1' cannot be used: %2.").arg(model->label(), e.what()));
	}
}

} // namespace ib_plugin
