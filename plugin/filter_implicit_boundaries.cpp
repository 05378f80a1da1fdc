#include "filter_implicit_boundaries.h"
#include "filter_parameters.h"
#include "input_layers.h"

#include "core/reconstruct.h"

#include <vcg/complex/algorithms/update/selection.h>
#include <vcg/complex/append.h>

#include <optional>

namespace {

using ib_plugin::FacingSources;
using ib_plugin::faceMatrix;
using ib_plugin::facingMatrix;
using ib_plugin::implicitMesh;
using ib_plugin::inputLayers;
using ib_plugin::kExtractions;
using ib_plugin::kImplicits;
using ib_plugin::kNormalsFacingViewpoint;
using ib_plugin::stackedMatrix;

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

/// How close the hole size decisions were, and which min_boundary_edges would change them.
QString holeMargins(const ib::BoundaryStage::Result& b, int minEdges)
{
	QStringList what;
	if (b.largest_hole_filled > 0)
		what << QString("the largest hole filled had a loop of %1 edges (min_boundary_edges %2 or less keeps it "
						"open)").arg(b.largest_hole_filled).arg(b.largest_hole_filled);
	if (b.smallest_hole_kept > 0)
		what << QString("the smallest hole kept open, %1 edges (min_boundary_edges %2 fills it)")
					.arg(b.smallest_hole_kept).arg(b.smallest_hole_kept + 1);
	return QString("Closest hole decisions at min_boundary_edges %1: %2.").arg(minEdges).arg(what.join("; "));
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
	p.sods_occupancy = ib::Reconstruction::Occupancy(par.getEnum("sods_occupancy"));
	p.sample_radius = par.getFloat("sample_radius");
	p.extraction = ib::GatedMarchingCubes::Extraction(par.getEnum("extraction"));
	p.implicit = ib::Reconstruction::Implicit(par.getEnum("implicit"));
	p.rbf.min_samples = par.getInt("rbf_min_samples");
	p.rbf.max_samples = par.getInt("rbf_max_samples");
	p.rbf.overlap = par.getFloat("rbf_overlap");
	p.rbf.off_surface = par.getFloat("rbf_off_surface");
	p.memory_limit = 1e9 * par.getFloat("memory_limit");
	p.tile = ib_plugin::tileParameters(par);

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
	if (layers.size() == 1 && par.getBool("keep_mesh_holes"))
		p.faces = faceMatrix(layers[0]->cm);
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
	if (r.covered_scan_edges > 0)
		log("Left %zu samples on the edges of scans out of the implicit function's fit: other scans cover them "
			"(a scan's edge is its least reliable part).", r.covered_scan_edges);
	log("Implicit function: %s%s, built in %.2f s.", qUtf8Printable(kImplicits[int(p.implicit)]),
		r.rbf_cells > 0 ? qUtf8Printable(QString(" (%1 local RBF fits)").arg(r.rbf_cells)) : "", r.seconds_implicit);
	log("Lattice %dx%dx%d, cell %g (resolution %d%s, sample spacing %g).",
		r.lattice_cells[0], r.lattice_cells[1], r.lattice_cells[2], r.cell_size, r.resolution,
		r.resolution_automatic ? ", automatic" : "", r.sample_spacing);
	if (p.tile.Fixed())
		log("A tile on the fixed lattice of cell %g from (%g, %g, %g): %s.", p.tile.cell, p.tile.origin[0],
			p.tile.origin[1], p.tile.origin[2], p.tile.block.isEmpty() ? "every face kept" : "kept the faces whose centre lies in its block");
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
	if (r.boundary.largest_hole_filled > 0 || r.boundary.smallest_hole_kept > 0)
		log("%s", qUtf8Printable(holeMargins(r.boundary, p.min_boundary_edges)));
	if (r.openings.closed > 0)
		log("Closed %d openings among samples (a thin part or a crease the gate opened: no point of their span "
			"is farther from a sample than %g median spacing or the surface around them is).", r.openings.closed,
			ib::CoveredOpenings::kReach);
	if (r.openings.closest_kept > 0)
		log("The opening kept that came closest to being closed reaches %.2f times as far from the samples as "
			"the rule allows (the surface around it, at least one median spacing).", r.openings.closest_kept);
	if (r.faces_not_manifold > 0 || r.vertices_split > 0)
		log("Made the surface a 2-manifold: removed %zu faces from edges shared by more than two faces, split %zu "
			"vertices where separate fans met.", r.faces_not_manifold, r.vertices_split);
	if (holeLayer && holes.fn == 0)
		log("No hole triangles to show (every hole was filled, or none closes): no holes layer added.");
	if (p.faces.rows() > 0)
		log("The layer's %lld faces keep its holes open: cut %zu faces of the surface where it passed over none of "
			"them.", (long long)p.faces.rows(), r.boundary.faces_cut_at_mesh_holes);
	if (r.seam_points > 0)
		log("The normals flip between neighbouring samples at %zu places (a one-sided surface, or a region "
			"oriented inside out): cut the surface there (%zu faces) into a boundary. If that region should "
			"not be cut, estimate normals facing the scanner's viewpoint.",
			r.seam_points, r.boundary.faces_cut_at_seams);
	log("%s extraction: %zu SODS cells, %zu hole cells%s; %zu implicit evaluations (the full "
		"lattice has %.0f corners, the cells the surface crosses %zu).",
		qUtf8Printable(kExtractions[int(p.extraction)]), r.sods_cells, r.hole_cells,
		r.hole_search_capped ? " (search capped: larger holes kept open)" : "", r.implicit_evaluations,
		r.full_lattice_evaluations, r.crossed_cell_corners);

	std::map<std::string, QVariant> res;
	res["boundary_loops"] = int(r.loops.size());
	res["boundary_loop_edges"] = QVariant::fromValue(toVector(edges));
	res["boundary_loop_lengths"] = QVariant::fromValue(toVector(lengths));
	res["boundary_loop_vertices"] = QVariant::fromValue(toVector(loopVertices));
	res["boundary_loops_before_filling"] = QVariant::fromValue(toVector(
		std::vector<double>(r.boundary.loops_before_filling.begin(), r.boundary.loops_before_filling.end())));
	res["holes_filled"] = r.boundary.holes_filled;
	res["openings_closed"] = r.openings.closed;
	res["closest_opening_kept"] = r.openings.closest_kept;
	res["largest_hole_filled_edges"] = r.boundary.largest_hole_filled;
	res["smallest_hole_kept_edges"] = r.boundary.smallest_hole_kept;
	res["hole_faces"] = holes.fn;
	res["hole_cells"] = double(r.hole_cells);
	res["faces_trimmed"] = double(r.boundary.faces_trimmed);
	res["boundary_vertices_fitted"] = double(r.boundary.boundary_vertices_fitted);
	res["seam_points"] = double(r.seam_points);
	res["covered_scan_edges"] = double(r.covered_scan_edges);
	res["faces_cut_at_seams"] = double(r.boundary.faces_cut_at_seams);
	res["faces_cut_at_mesh_holes"] = double(r.boundary.faces_cut_at_mesh_holes);
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
	res["implicit_evaluations"] = double(r.implicit_evaluations);
	res["full_lattice_evaluations"] = double(r.full_lattice_evaluations);
	res["crossed_cell_corners"] = double(r.crossed_cell_corners);
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
