#include "filter_implicit_boundaries.h"

#include "core/implicit/mesh_distance.h"
#include "core/reconstruct.h"

#include <vcg/complex/algorithms/update/selection.h>
#include <vcg/complex/append.h>

#include <optional>

namespace {

// The first two match ib::Reconstruction::NormalSource; the third is Estimate with the viewpoint.
const QStringList kNormalSources = {"Use layer normals", "Estimate", "Estimate, facing the viewpoint"};
const int kNormalsFacingViewpoint = 2;
// Order matches ib::Reconstruction::Occupancy.
const QStringList kOccupancies = {"Tangent disks", "Sample cells (paper)"};
// Order matches ib::Reconstruction::Implicit.
const QStringList kImplicits = {"PU-RBF (paper)", "Hoppe signed distance", "Mesh layer (signed distance)"};
// Order matches ib::GatedMarchingCubes::Extraction.
const QStringList kExtractions = {"SODS-driven", "Full lattice, gated", "Plain marching cubes"};

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

/// Which layers oriented estimated normals by what (facingMatrix).
struct FacingSources
{
	int cameras = 0, triangles = 0, viewpoint = 0;
};

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

/// How estimated normals were oriented, for the log: "facing each layer's camera", ...
QString orientation(const FacingSources& used, const std::optional<Eigen::Vector3d>& viewpoint, int layers)
{
	QStringList by;
	if (used.cameras)
		by << QString("towards the camera of %1 layer(s)").arg(used.cameras);
	if (used.triangles)
		by << QString("along the triangles of %1 layer(s)").arg(used.triangles);
	if (used.viewpoint)
		by << QString("towards the viewpoint (%1, %2, %3)").arg((*viewpoint)[0]).arg((*viewpoint)[1]).arg((*viewpoint)[2]);
	const int rest = layers - used.cameras - used.triangles - used.viewpoint;
	if (by.isEmpty())
		return "by propagation";
	if (rest > 0)
		by << QString("as their neighbours for the %1 other layer(s)").arg(rest);
	return by.join(", ");
}

Eigen::VectorXd toVector(const std::vector<double>& v)
{
	return Eigen::Map<const Eigen::VectorXd>(v.data(), Eigen::Index(v.size()));
}

QString loopSummary(const std::vector<ib::BoundaryLoop>& loops)
{
	QStringList sizes;
	for (const auto& l : loops)
		sizes << QString::number(l.Edges());
	return loops.empty() ? QString("none") : sizes.join(", ");
}

/// The layer offered as the implicit mesh: the most recent layer with faces other than the
/// current one (the output of Screened Poisson run on the points), else the current one.
unsigned int defaultImplicitMesh(const MeshDocument& md)
{
	unsigned int id = md.mm() ? md.mm()->id() : 0;
	for (const MeshModel& m : md.meshIterator())
		if (m.cm.fn > 0 && &m != md.mm())
			id = m.id();
	return id;
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
	// Read around deleted elements rather than compacting: the user's layer stays untouched.
	const CMeshO& cm = model->cm;
	std::vector<int> row(cm.vert.size(), -1);
	ib::Points V(cm.vn, 3);
	int n = 0;
	for (size_t i = 0; i < cm.vert.size(); ++i)
		if (!cm.vert[i].IsD()) {
			V.row(n) << cm.vert[i].cP()[0], cm.vert[i].cP()[1], cm.vert[i].cP()[2];
			row[i] = n++;
		}
	Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor> F(cm.fn, 3);
	int m = 0;
	for (const auto& f : cm.face)
		if (!f.IsD()) {
			for (int k = 0; k < 3; ++k)
				F(m, k) = row[vcg::tri::Index(cm, f.cV(k))];
			++m;
		}
	try {
		return std::make_unique<ib::MeshDistance>(V, F);
	}
	catch (const std::invalid_argument& e) {
		throw MLException(QString("The implicit mesh layer '%1' cannot be used: %2.").arg(model->label(), e.what()));
	}
}

} // namespace

FilterImplicitBoundariesPlugin::FilterImplicitBoundariesPlugin()
{
	typeList = {IMPLICIT_RECONSTRUCTION_WITH_BOUNDARIES};
	for (ActionIDType tt : types())
		actionList.push_back(new QAction(filterName(tt), this));
}

QString FilterImplicitBoundariesPlugin::pluginName() const
{
	return "FilterImplicitBoundaries";
}

QString FilterImplicitBoundariesPlugin::filterName(ActionIDType filter) const
{
	switch (filter) {
	case IMPLICIT_RECONSTRUCTION_WITH_BOUNDARIES: return "Implicit reconstruction with boundaries";
	default: assert(0); return QString();
	}
}

QString FilterImplicitBoundariesPlugin::pythonFilterName(ActionIDType filter) const
{
	switch (filter) {
	case IMPLICIT_RECONSTRUCTION_WITH_BOUNDARIES:
		return "generate_surface_reconstruction_implicit_with_boundaries";
	default: assert(0); return QString();
	}
}

QString FilterImplicitBoundariesPlugin::filterInfo(ActionIDType filter) const
{
	switch (filter) {
	case IMPLICIT_RECONSTRUCTION_WITH_BOUNDARIES:
		return "Reconstructs a surface <b>with its real boundaries</b> from a point cloud with normals "
			   "(estimated when the layer has none). An implicit function is fitted to the samples "
			   "(by default the paper's partition-of-unity RBF; or Hoppe's signed distance to tangent planes, or the "
			   "signed distance to a closed mesh layer such as Screened Poisson's output) and extracted "
			   "by marching cubes, but only in the cells of a <i>spatial occupancy data structure</i> "
			   "(SODS): the lattice cells covered by the samples' tangent disks. Where the scan has no "
			   "samples (the underside of an object on a table, a cut) no surface is made, unlike "
			   "Screened Poisson, which closes every hole. Holes with short boundaries are "
			   "undersampling and are filled; the others are kept, trimmed to the scan's edge and "
			   "smoothed. The boundary loops are reported (edge counts, lengths) and their vertices "
			   "left selected; the hole triangles can go to their own layer.<br>Method: "
			   "<i>Reconstructing implicit surfaces with boundaries</i> (SODS-gated marching cubes), "
			   "see the plugin's README.";
	default: assert(0); return QString();
	}
}

FilterPlugin::FilterClass FilterImplicitBoundariesPlugin::getClass(const QAction*) const
{
	return FilterPlugin::Remeshing;
}

FilterPlugin::FilterArity FilterImplicitBoundariesPlugin::filterArity(const QAction*) const
{
	return SINGLE_MESH;
}

int FilterImplicitBoundariesPlugin::getPreConditions(const QAction*) const
{
	return MeshModel::MM_NONE;
}

int FilterImplicitBoundariesPlugin::postCondition(const QAction*) const
{
	return MeshModel::MM_NONE;
}

RichParameterList FilterImplicitBoundariesPlugin::initParameterList(const QAction* action, const MeshDocument& md)
{
	switch (ID(action)) {
	case IMPLICIT_RECONSTRUCTION_WITH_BOUNDARIES: return reconstructionParameters(md);
	default: assert(0); return RichParameterList();
	}
}

RichParameterList FilterImplicitBoundariesPlugin::reconstructionParameters(const MeshDocument& md) const
{
	const ib::Reconstruction::Param d;
	RichParameterList par;
	par.addParam(RichInt(
		"resolution", d.resolution, "Resolution (cells, 0 = automatic)",
		QString("Marching cubes cells along the longest side of the bounding box; the SODS uses the "
				"same lattice. 0 chooses it from the sample spacing (a cell of 0.6 times the typical "
				"distance between neighbouring samples) and logs the value. Raise it for more detail "
				"and tighter boundaries; lower it to close more undersampled gaps and run faster. "
				"Allowed: 0 or %1..%2.")
			.arg(ib::Reconstruction::kMinResolution)
			.arg(ib::Reconstruction::kMaxResolution)));
	par.addParam(RichEnum(
		"implicit", int(d.implicit), kImplicits, "Implicit function",
		"The implicit surface that is extracted. 'PU-RBF (paper)': local radial basis functions "
		"fitted to the samples and their normals in overlapping octree cells, blended by a "
		"partition of unity (Tobor et al. 2006): smooth and close to the samples. 'Hoppe signed "
		"distance': blended distance to the nearest samples' tangent planes (Hoppe et al. 1992): "
		"no fitting, follows noise more closely. 'Mesh layer (signed distance)': the closed mesh "
		"chosen below, e.g. the output of Screened Poisson, gets the scan's real boundaries."));
	par.addParam(RichMesh(
		"implicit_mesh", defaultImplicitMesh(md), &md, "Implicit mesh layer",
		"With 'Mesh layer (signed distance)': the closed triangle mesh whose surface is extracted "
		"where the point layer has samples (run Screened Poisson on the points first). Ignored "
		"by the other implicit functions."));
	par.addParam(RichInt(
		"rbf_min_samples", d.rbf.min_samples, "PU-RBF: min samples per cell",
		"Each local RBF sees at least this many samples (its support grows where the scan is "
		"sparse). Raise it for noisy scans (smoother), lower it for fine detail.",
		true));
	par.addParam(RichInt(
		"rbf_max_samples", d.rbf.max_samples, "PU-RBF: max samples per cell",
		"Octree cells holding more samples are split. Larger cells fit slower but smoother.",
		true));
	par.addParam(RichFloat(
		"rbf_overlap", d.rbf.overlap, "PU-RBF: overlap",
		"Support box side over cell side: how far neighbouring local functions overlap and "
		"blend. 1 = no overlap (seams); raise it if the surface shows ridges between cells.",
		true));
	par.addParam(RichFloat(
		"rbf_off_surface", d.rbf.off_surface, "PU-RBF: off-surface distance (spacings)",
		"Distance along the normals of the off-surface constraints (+e outside, -e inside), in "
		"local sample spacings. Lower it for thin parts whose sides are closer than two spacings.",
		true));
	par.addParam(RichEnum(
		"sods_occupancy", int(d.occupancy), kOccupancies, "SODS occupancy",
		"Which lattice cells the samples mark in the spatial occupancy data structure (SODS); "
		"the surface is only extracted in marked cells. 'Tangent disks': each sample marks the "
		"cells crossed by a disk in its tangent plane whose radius follows the local sample "
		"spacing, so sparse regions stay covered while real holes stay open. 'Sample cells "
		"(paper)': the cell holding each sample, meant to be used with a dilation of 1."));
	par.addParam(RichFloat(
		"sample_radius", d.sample_radius, "Tangent disk radius (spacings)",
		"Radius of each sample's tangent disk, in units of the local sample spacing (distance "
		"between neighbouring samples). Raise it if the result has small spurious holes where "
		"the scan is sparse; lower it to keep narrow real holes open.",
		true));
	par.addParam(RichInt(
		"sods_dilation", d.sods_dilation, "SODS dilation (rings)",
		"Rings of 26-neighbour cells added around the marked cells. 0 suits tangent disks; the "
		"paper uses 1 with sample cells. Raise it if the result has spurious small holes (noisy "
		"scans); each ring extends the surface by about one cell across real boundaries and "
		"closes holes narrower than two cells.",
		true));
	par.addParam(RichInt(
		"min_boundary_edges", d.min_boundary_edges, "Min boundary edges",
		"A hole whose boundary loop has fewer edges is taken as undersampling and filled with "
		"its hole triangles (the implicit surface across it); larger holes are kept as real "
		"boundaries. 0 keeps every hole. Raise it to fill more gaps of a sparse scan; lower it "
		"to keep small real holes. Counts grow with the resolution."));
	par.addParam(RichInt(
		"boundary_smoothing", d.boundary_smoothing, "Boundary smoothing (iterations)",
		"Passes of the paper's collinearity moves along each boundary loop, after which the "
		"boundary is put back on the implicit surface (moves that would fold a face are undone). "
		"Marching cubes boundaries are jagged; 4 to 6 passes make them smooth. 0 = off."));
	par.addParam(RichFloat(
		"boundary_trim", d.boundary_trim, "Boundary trim (spacings)",
		"Faces at the boundary farther than this many local sample spacings from every sample "
		"are peeled off, removing the margin the occupancy adds past the scan's edge; the "
		"boundary fit then moves the boundary out onto the last samples. Raise it if the trim "
		"opens spurious holes in sparse regions; 0 = no trim.",
		true));
	par.addParam(RichBool(
		"boundary_fit", d.boundary_fit, "Fit boundary to the samples' edge",
		"Moves each boundary vertex along the surface onto the outermost samples beside it, so "
		"the boundary follows the scan's edge instead of the lattice's cells (measured: the "
		"boundary distance to the true one drops by a third). Turn it off to see the boundary "
		"the trim leaves.",
		true));
	par.addParam(RichBool(
		"merge_visible_layers", false, "Merge visible layers",
		"Reconstruct one surface from the vertices of every visible layer, each through its own "
		"transformation matrix: several range scans aligned with the Align tool. Overlapping scans "
		"are averaged by the implicit function. Off: the current layer only."));
	par.addParam(RichBool(
		"hole_layer", false, "Hole triangles in their own layer",
		"Also add a layer '<input> holes' with the triangles that close the kept holes: showing "
		"both layers gives the closed surface, hiding it the surface with boundaries."));
	par.addParam(RichBool(
		"outlier_layer", false, "Outliers in their own layer",
		"Also add a layer '<input> outliers' with the samples left out as outliers: samples that "
		"no other sample has among its 8 nearest (stray points off the surface). They never "
		"shape the surface, the lattice or the boundaries; the log says how many there were."));
	par.addParam(RichEnum(
		"normals", int(d.normals), kNormalSources, "Normals",
		"Where the oriented normals that define inside and outside come from. 'Use layer normals' "
		"takes the layer's own (a scan's normals are usually best), estimates the zero or NaN ones "
		"among them facing the way their neighbours face, and all of them when the layer has none; 'Estimate' always fits them (PCA over neighbours). "
		"Estimated normals of each layer face its camera when it has one (a scan imported with its "
		"scanner's position), else follow its triangles when it has faces (a range grid faces its "
		"scanner), else, with 'Estimate, facing the viewpoint', face the viewpoint below; the rest "
		"are oriented by propagation, which can flip whole regions of a thin or sparse scan (the "
		"surface then comes out inside-out there, with a seam of boundary where the flipped region "
		"meets the rest). The log says when and how normals were estimated."));
	par.addParam(RichPosition(
		"viewpoint", Point3m(0, 0, 0), "Viewpoint",
		"With 'Estimate, facing the viewpoint': the position the scan was taken from; every "
		"estimated normal of a layer without camera or faces is turned to face it."));
	par.addParam(RichEnum(
		"extraction", int(d.extraction), kExtractions, "Extraction",
		"'SODS-driven' evaluates the implicit function only at the corners of occupied cells "
		"(fast, memory grows with the surface). 'Full lattice, gated' evaluates every lattice "
		"corner first, as the paper's implementation did: same surface, slower. 'Plain marching "
		"cubes' ignores the occupancy and extracts the whole implicit surface (closed, no "
		"boundaries): the reference the method is compared with.",
		true));
	par.addParam(RichFloat(
		"memory_limit", d.memory_limit, "Memory limit (GB, 0 = half the RAM)",
		"A run estimated to need more memory than this is refused before it starts, with a "
		"message, instead of exhausting the machine. 0 uses half of the physical memory. Lower "
		"the resolution rather than raising the limit if you can.",
		true));
	par.addParam(RichInt(
		"normal_neighbours", d.normal_neighbours, "Normal estimation neighbours",
		"Samples used to fit each tangent plane when normals are estimated. Raise it for noisy "
		"scans, lower it for thin details.",
		true));
	return par;
}

std::map<std::string, QVariant> FilterImplicitBoundariesPlugin::applyFilter(
	const QAction*           action,
	const RichParameterList& par,
	MeshDocument&            md,
	unsigned int& /*postConditionMask*/,
	vcg::CallBackPos* cb)
{
	switch (ID(action)) {
	case IMPLICIT_RECONSTRUCTION_WITH_BOUNDARIES: return reconstructWithBoundaries(md, par, cb);
	default: wrongActionCalled(action); return {};
	}
}

std::map<std::string, QVariant> FilterImplicitBoundariesPlugin::reconstructWithBoundaries(
	MeshDocument& md, const RichParameterList& par, vcg::CallBackPos* cb)
{
	MeshModel* input = md.mm();
	if (input == nullptr)
		throw MLException("No layer is selected: load a point cloud first.");

	ib::Reconstruction::Param p;
	p.resolution = par.getInt("resolution");
	p.sods_dilation = par.getInt("sods_dilation");
	const int normals = par.getEnum("normals");
	p.normals = normals == kNormalsFacingViewpoint ? ib::Reconstruction::NormalSource::Estimate
												   : ib::Reconstruction::NormalSource(normals);
	std::optional<Eigen::Vector3d> viewpoint;
	if (normals == kNormalsFacingViewpoint) {
		const Point3m v = par.getPoint3m("viewpoint");
		viewpoint = Eigen::Vector3d(v[0], v[1], v[2]);
	}
	p.normal_neighbours = par.getInt("normal_neighbours");
	p.min_boundary_edges = par.getInt("min_boundary_edges");
	p.boundary_trim = par.getFloat("boundary_trim");
	p.boundary_smoothing = par.getInt("boundary_smoothing");
	p.boundary_fit = par.getBool("boundary_fit");
	const bool holeLayer = par.getBool("hole_layer");
	const bool outlierLayer = par.getBool("outlier_layer");
	p.occupancy = ib::Reconstruction::Occupancy(par.getEnum("sods_occupancy"));
	p.sample_radius = par.getFloat("sample_radius");
	p.extraction = ib::GatedMarchingCubes::Extraction(par.getEnum("extraction"));
	p.implicit = ib::Reconstruction::Implicit(par.getEnum("implicit"));
	p.rbf.min_samples = par.getInt("rbf_min_samples");
	p.rbf.max_samples = par.getInt("rbf_max_samples");
	p.rbf.overlap = par.getFloat("rbf_overlap");
	p.rbf.off_surface = par.getFloat("rbf_off_surface");
	p.memory_limit = 1e9 * par.getFloat("memory_limit");

	std::unique_ptr<ib::MeshDistance> meshImplicit;
	if (p.implicit == ib::Reconstruction::Implicit::Given) {
		meshImplicit = implicitMesh(md, par.getMeshId("implicit_mesh"));
		p.given = meshImplicit.get();
	}

	ib::CoreMesh surface, holes;
	ib::Reconstruction::Result r;
	const std::vector<const MeshModel*> layers = inputLayers(md, par.getBool("merge_visible_layers"));
	const ib::Points positions = stackedMatrix(layers, false);
	if (layers.size() > 1)
		for (const MeshModel* m : layers)
			p.scan_sizes.push_back(m->cm.vn);
	const ib::Points layerNormals = stackedMatrix(layers, true);
	FacingSources facing;
	if (p.normals == ib::Reconstruction::NormalSource::Estimate || !layerNormals.array().isFinite().all() ||
		(layerNormals.array() == 0).all())
		p.facing = facingMatrix(layers, viewpoint, facing);
	try {
		r = ib::Reconstruction::Compute(positions, layerNormals, p, surface,
										holeLayer ? &holes : nullptr, cb);
	}
	catch (const ib::InputError& e) {
		throw MLException(QString("Implicit reconstruction with boundaries: ") + e.what());
	}
	catch (const ib::Cancelled&) {
		throw MLException("Implicit reconstruction with boundaries was cancelled: nothing was added.");
	}
	catch (const std::bad_alloc&) {
		throw MLException("Implicit reconstruction with boundaries ran out of memory: lower the resolution.");
	}
	catch (const std::exception& e) {
		throw MLException(QString("Implicit reconstruction with boundaries failed (%1); nothing was added. "
								  "Please report it with the input.").arg(e.what()));
	}

	// Layers are added only now, and removed again if filling them fails (out of memory): an
	// error never leaves a half-made layer in the user's document.
	MeshModel* out = nullptr;
	std::vector<unsigned int> added;
	const QString label = layers.size() > 1 ? QString("Merged layers") : input->label();
	try {
		out = md.addNewMesh("", label + " with boundaries", true);
		added.push_back(out->id());
		vcg::tri::Append<CMeshO, ib::CoreMesh>::MeshCopyConst(out->cm, surface);
		vcg::tri::UpdateSelection<CMeshO>::VertexClear(out->cm);
		for (const auto& loop : r.loops)
			for (int v : loop.vertices)
				out->cm.vert[v].SetS();
		out->updateBoxAndNormals();
		if (holeLayer && holes.fn > 0) {  // no empty layer when no hole is kept
			MeshModel* holeModel = md.addNewMesh("", label + " holes", false);
			added.push_back(holeModel->id());
			vcg::tri::Append<CMeshO, ib::CoreMesh>::MeshCopyConst(holeModel->cm, holes);
			holeModel->updateBoxAndNormals();
		}
		if (outlierLayer && !r.outliers.empty()) {
			MeshModel* outlierModel = md.addNewMesh("", label + " outliers", false);
			added.push_back(outlierModel->id());
			auto v = vcg::tri::Allocator<CMeshO>::AddVertices(outlierModel->cm, r.outliers.size());
			for (Eigen::Index row : r.outliers)
				(v++)->P() = Point3m(Scalarm(positions(row, 0)), Scalarm(positions(row, 1)), Scalarm(positions(row, 2)));
			outlierModel->updateBoxAndNormals();
		}
		md.setCurrentMesh(out->id());
	}
	catch (const std::bad_alloc&) {
		for (unsigned int id : added)
			md.delMesh(id);
		md.setCurrentMesh(input->id());
		throw MLException("Implicit reconstruction with boundaries ran out of memory while copying its result "
						  "into a layer; nothing was added. Lower the resolution.");
	}

	std::vector<double> edges, lengths, loopVertices;
	for (const auto& loop : r.loops) {
		edges.push_back(loop.Edges());
		lengths.push_back(loop.length);
		loopVertices.insert(loopVertices.end(), loop.vertices.begin(), loop.vertices.end());
	}

	if (layers.size() > 1)
		log("Merged %zu visible layers: %lld samples.", layers.size(), (long long)positions.rows());
	if (r.duplicates_removed > 0)
		log("Ignored %zu vertices at the same position as another one.", r.duplicates_removed);
	if (!r.outliers.empty())
		log("Left out %zu outliers: samples that no other sample has among its 8 nearest (stray points off "
			"the surface)%s.", r.outliers.size(), outlierLayer ? ", in the layer '<input> outliers'" : "");
	if (r.normals_filled > 0)
		log("%zu of the layer's vertex normals were zero or NaN: estimated them from %d neighbours, facing the way "
			"their neighbours' normals face; the other normals are the layer's.",
			r.normals_filled, p.normal_neighbours);
	if (r.normals_estimated)
		log("Input had no usable normals (or estimation was requested): estimated them from %d "
			"neighbours and oriented them %s%s; %zu turned to agree with their neighbours.",
			p.normal_neighbours, qUtf8Printable(orientation(facing, viewpoint, int(layers.size()))),
			r.normals_flipped ? " (flipped to point away from the centroid)" : "", r.normals_turned);
	log("Implicit function: %s%s, built in %.2f s.", qUtf8Printable(kImplicits[int(p.implicit)]),
		r.rbf_cells > 0 ? qUtf8Printable(QString(" (%1 local RBF fits)").arg(r.rbf_cells)) : "", r.seconds_implicit);
	log("Lattice %dx%dx%d, cell %g (resolution %d%s, sample spacing %g).",
		r.lattice_cells[0], r.lattice_cells[1], r.lattice_cells[2], r.cell_size, r.resolution,
		r.resolution_automatic ? ", automatic" : "", r.sample_spacing);
	if (r.resolution_automatic && r.resolution == ib::Reconstruction::kMaxAutoResolution)
		log("Warning: the automatic resolution was capped at %d: the longest side of the samples' box is %.0f "
			"sample spacings, which asks for %d cells; cells are %.2f spacings wide, so detail under a cell "
			"is smoothed. A large, dense scan or parts far apart cause this; a resolution set by hand (up "
			"to %d) gives finer cells, with more memory.",
			r.resolution, r.resolution_from_spacing * ib::Reconstruction::kCellPerSpacing,
			r.resolution_from_spacing, r.cell_size / r.sample_spacing, ib::Reconstruction::kMaxResolution);
	log("Surface: %d faces, %d vertices; %d boundary loops kept (edges: %s); %d small holes "
		"filled (loops under %d edges); %zu unsupported faces trimmed off the boundary, %zu "
		"boundary vertices fitted to the samples' edge.",
		out->cm.fn, out->cm.vn, int(r.loops.size()), qUtf8Printable(loopSummary(r.loops)),
		r.boundary.holes_filled, p.min_boundary_edges, r.boundary.faces_trimmed, r.boundary.boundary_vertices_fitted);
	if (r.faces_not_manifold > 0 || r.vertices_split > 0)
		log("Made the surface a 2-manifold: removed %zu faces from edges shared by more than two faces, split %zu "
			"vertices where separate fans met.", r.faces_not_manifold, r.vertices_split);
	if (holeLayer && holes.fn == 0)
		log("No hole triangles to show (every hole was filled, or none closes): no holes layer added.");
	if (r.seam_points > 0)
		log("The normals flip between neighbouring samples at %zu places (a one-sided surface, or a region "
			"oriented inside out): cut the surface there (%zu faces) into a boundary. If that region should "
			"not be cut, estimate normals facing the scanner's viewpoint.",
			r.seam_points, r.boundary.faces_cut_at_seams);
	log("%s extraction: %zu SODS cells, %zu hole cells%s; %zu implicit evaluations (the full "
		"lattice has %.0f corners, the cells the surface crosses %zu).",
		qUtf8Printable(kExtractions[int(p.extraction)]), r.sods_cells, r.hole_cells,
		r.hole_search_capped ? " (search capped: larger holes kept open)" : "", r.evaluations,
		r.lattice_corners, r.crossed_corners);

	std::map<std::string, QVariant> res;
	res["boundary_loops"] = int(r.loops.size());
	res["boundary_loop_edges"] = QVariant::fromValue(toVector(edges));
	res["boundary_loop_lengths"] = QVariant::fromValue(toVector(lengths));
	res["boundary_loop_vertices"] = QVariant::fromValue(toVector(loopVertices));
	res["boundary_loops_before_filling"] = QVariant::fromValue(toVector(
		std::vector<double>(r.boundary.loops_before_filling.begin(), r.boundary.loops_before_filling.end())));
	res["holes_filled"] = r.boundary.holes_filled;
	res["hole_faces"] = holes.fn;
	res["hole_cells"] = double(r.hole_cells);
	res["faces_trimmed"] = double(r.boundary.faces_trimmed);
	res["boundary_vertices_fitted"] = double(r.boundary.boundary_vertices_fitted);
	res["seam_points"] = double(r.seam_points);
	res["faces_cut_at_seams"] = double(r.boundary.faces_cut_at_seams);
	res["duplicates_removed"] = double(r.duplicates_removed);
	res["outliers_removed"] = double(r.outliers.size());
	res["faces_unsupported"] = double(r.boundary.faces_unsupported);
	res["faces_not_manifold"] = double(r.faces_not_manifold);
	res["vertices_split"] = double(r.vertices_split);
	res["surface_faces"] = out->cm.fn;
	res["surface_vertices"] = out->cm.vn;
	res["resolution"] = r.resolution;
	res["resolution_from_spacing"] = r.resolution_from_spacing;
	res["cell_size"] = double(r.cell_size);
	res["sample_spacing"] = double(r.sample_spacing);
	res["implicit"] = int(p.implicit);
	res["rbf_cells"] = r.rbf_cells;
	res["sods_cells"] = double(r.sods_cells);
	res["implicit_evaluations"] = double(r.evaluations);
	res["full_lattice_evaluations"] = double(r.lattice_corners);
	res["crossed_cell_corners"] = double(r.crossed_corners);
	res["memory_limit_gb"] = r.memory_limit / 1e9;
	res["memory_estimate_gb"] = r.memory_estimate / 1e9;
	res["normals_estimated"] = r.normals_estimated;
	res["normals_turned"] = double(r.normals_turned);
	res["normals_filled"] = double(r.normals_filled);
	res["seconds_normals"] = r.seconds_normals;
	res["seconds_implicit"] = r.seconds_implicit;
	res["seconds_sods"] = r.seconds_sods;
	res["seconds_extraction"] = r.seconds_extraction;
	res["seconds_boundaries"] = r.seconds_boundaries;
	return res;
}

MESHLAB_PLUGIN_NAME_EXPORTER(FilterImplicitBoundariesPlugin)

// Which MeshLab this file fits, readable from the file without loading it: `implicit-boundaries
// info` and the Python loader say so instead of MeshLab's bare "different floating point
// precision" when a user picks the wrong one.
extern "C" Q_DECL_EXPORT const char implicit_boundaries_build[] =
	"implicit_boundaries plugin for MeshLab " meshlab_xstr(MESHLAB_VERSION) " scalar=" meshlab_xstr(MESHLAB_SCALAR);
