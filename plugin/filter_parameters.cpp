// The filter's parameter list: names, labels, tooltips and defaults, in the dialog's order.

#include "filter_implicit_boundaries.h"
#include "filter_parameters.h"

#include "core/reconstruct.h"

#include <utility>

namespace {

using R = ib::Reconstruction;
using Extraction = ib::GatedMarchingCubes::Extraction;

// Each label beside the core's enum value it stands for; the dialog's index of a label is the
// value's integer, checked at compile time.
template <class E>
using Label = std::pair<E, const char*>;
constexpr Label<R::NormalSource> kNormalSourceLabels[] = {
	{R::NormalSource::LayerOrEstimate, "Use layer normals"}, {R::NormalSource::Estimate, "Estimate"}};
constexpr Label<R::Occupancy> kOccupancyLabels[] = {
	{R::Occupancy::TangentDisks, "Tangent disks"}, {R::Occupancy::SampleCells, "Sample cells (paper)"}};
constexpr Label<R::Implicit> kImplicitLabels[] = {{R::Implicit::PuRbf, "PU-RBF (paper)"},
												  {R::Implicit::Hoppe, "Hoppe signed distance"},
												  {R::Implicit::Given, "Mesh layer (signed distance)"}};
constexpr Label<Extraction> kExtractionLabels[] = {{Extraction::SodsDriven, "SODS-driven"},
												   {Extraction::FullLatticeGated, "Full lattice, gated"},
												   {Extraction::Plain, "Plain marching cubes"}};

template <class E, size_t N>
constexpr bool InValueOrder(const Label<E> (&labels)[N])
{
	for (size_t i = 0; i < N; ++i)
		if (size_t(labels[i].first) != i)
			return false;
	return true;
}
static_assert(InValueOrder(kNormalSourceLabels) && InValueOrder(kOccupancyLabels) && InValueOrder(kImplicitLabels) &&
				  InValueOrder(kExtractionLabels),
			  "an enum label is not at its value's index");

template <class E, size_t N>
QStringList Labels(const Label<E> (&labels)[N])
{
	QStringList out;
	for (const Label<E>& label : labels)
		out << label.second;
	return out;
}

} // namespace

namespace ib_plugin {

// The third is Estimate with the viewpoint (kNormalsFacingViewpoint).
const QStringList kNormalSources = Labels(kNormalSourceLabels) << "Estimate, facing the viewpoint";
const QStringList kOccupancies = Labels(kOccupancyLabels);
const QStringList kImplicits = Labels(kImplicitLabels);
const QStringList kExtractions = Labels(kExtractionLabels);

} // namespace ib_plugin

namespace {

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

} // namespace

using ib_plugin::kExtractions;
using ib_plugin::kImplicits;
using ib_plugin::kNormalSources;
using ib_plugin::kOccupancies;

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
		"sods_occupancy", int(d.sods_occupancy), kOccupancies, "SODS occupancy",
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
		"to keep small real holes. Counts grow with the resolution; among samples k times sparser "
		"than the median a loop may have k times as many edges (gaps grow with the spacing)."));
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
		"keep_mesh_holes", true, "Keep the mesh's holes",
		"When the layer has faces (a triangulated scan, a mesh to remesh), the surface is cut where "
		"it passes over none of them, so every hole of the triangulation stays open, however "
		"small its gap between vertices (as points alone the tangent disks would bridge it); "
		"openings whose loop has fewer than 'Min boundary edges' edges are still filled. Off: "
		"the faces are ignored, as for a point cloud. Merged layers always ignore faces.",
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
	addTileParameters(par);
	return par;
}

namespace {

Eigen::Vector3d toVector3(const Point3m& p)
{
	return Eigen::Vector3d(p[0], p[1], p[2]);
}

} // namespace

void FilterImplicitBoundariesPlugin::addTileParameters(RichParameterList& par)
{
	const QString tiles = "For one tile of a scan reconstructed tile by tile (the Python package's "
						  "'implicit-boundaries tiled' sets it): ";
	par.addParam(RichFloat(
		"lattice_cell", 0, "Tiles: lattice cell (0 = off)",
		tiles + "the cell of the whole scan's lattice, whose corners lie at the lattice origin plus whole "
				"cells, so that neighbouring tiles compute the corners they share from the same numbers. "
				"0: the lattice fits the layer (normal use; leave the tile parameters alone).",
		true));
	par.addParam(RichPosition(
		"lattice_origin", Point3m(0, 0, 0), "Tiles: lattice origin",
		tiles + "the whole scan's lattice corner (0, 0, 0), below every sample.", true));
	par.addParam(RichPosition(
		"lattice_end", Point3m(0, 0, 0), "Tiles: lattice end",
		tiles + "the whole scan's far lattice corner, above every sample; with the origin it also roots "
				"the PU-RBF's octree, so each tile fits the cells one run would.",
		true));
	par.addParam(RichFloat(
		"lattice_spacing", 0, "Tiles: sample spacing",
		tiles + "the whole scan's median sample spacing, which sets the tangent disks' reach and the "
				"boundary stage's scale. 0: the layer's own.",
		true));
	par.addParam(RichPosition(
		"block_min", Point3m(0, 0, 0), "Tiles: block minimum",
		tiles + "the low corner of the tile's block: only faces whose centre lies in [block minimum, "
				"block maximum) are kept. Equal corners: keep every face.",
		true));
	par.addParam(RichPosition(
		"block_max", Point3m(0, 0, 0), "Tiles: block maximum", tiles + "the high corner of the tile's block.",
		true));
}

ib::Tile ib_plugin::tileParameters(const RichParameterList& par)
{
	ib::Tile t;
	t.cell = par.getFloat("lattice_cell");
	t.origin = toVector3(par.getPoint3m("lattice_origin"));
	t.end = toVector3(par.getPoint3m("lattice_end"));
	t.spacing = par.getFloat("lattice_spacing");
	const Eigen::Vector3d lo = toVector3(par.getPoint3m("block_min")), hi = toVector3(par.getPoint3m("block_max"));
	if (lo != hi)
		t.block = Eigen::AlignedBox3d(lo, hi);
	return t;
}
