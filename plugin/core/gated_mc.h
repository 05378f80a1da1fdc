#pragma once
/// \file gated_mc.h
/// Marching cubes gated by the SODS (paper §3.2) and the hole triangles (paper §3.3).
///
/// Surface triangles are extracted only in SODS cells, evaluating the implicit function only
/// at the corners of those cells (the "SODS-driven" extraction of paper §3.4: Θ(k) in the
/// number of SODS cells instead of Θ(m) in the lattice size). Hole triangles are then found by
/// a breadth-first search from the SODS cells through empty cells that the implicit surface
/// crosses, stepping only across cell faces the surface crosses (so only the cells along the
/// surface are evaluated, not the shell of empty cells around the SODS); they are extracted
/// with the same walker, so they share vertices with the surface and surface + holes is the
/// closed marching cubes surface. Each connected set of hole cells is a hole region; a region
/// is closed when the search finished it away from the lattice border (the implicit surface
/// closes it), open otherwise (the surface runs off, as at a cut, or the search hit its cap).
///
/// Two more extractions serve as references (paper §3.4): the paper's own implementation,
/// which evaluates every lattice corner and then extracts only in SODS cells (same triangles,
/// Θ(m) evaluations), and plain marching cubes over the whole lattice (no gate, no holes: the
/// closed surface the paper compares against).
///
/// Uses VCGlib's topologically consistent vcg::tri::MarchingCubes tables with our own walker,
/// which serves corner values from batch evaluations and welds the edge vertices of neighbours
/// (mc_cache.h).

#include "implicit/implicit_function.h"
#include "mc_cache.h"
#include "mesh.h"
#include "sods.h"

// GCC 12 reports -Wmaybe-uninitialized inside VCG's MarchingCubes::TestFace (its switch over the
// six face codes has no initialising default) although the header is a system include: the
// warning is issued where the template is instantiated for our walker. Silenced for this header
// only; the code is VCG's.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <vcg/complex/algorithms/create/marching_cubes.h>
#pragma GCC diagnostic pop

#include <optional>
#include <unordered_map>
#include <unordered_set>

namespace ib {

class GatedMarchingCubes
{
public:
    enum class Extraction {
        SodsDriven,        ///< evaluate only the corners of SODS (and hole) cells
        FullLatticeGated,  ///< evaluate every lattice corner, extract in SODS cells (the paper's code)
        Plain              ///< evaluate every lattice corner, extract everywhere (no gate, no holes)
    };

    struct Param
    {
        Extraction extraction = Extraction::SodsDriven;
        bool holes = true;           ///< also extract the hole triangles (not with Plain)
        size_t max_hole_cells = 0;   ///< cap of the hole search; 0 = max(SODS cells, 4096)
    };

    /// What Compute made besides the mesh. Faces [0, surface_faces) lie in SODS cells; face
    /// surface_faces + i lies in hole region face_region[i].
    struct Result
    {
        size_t surface_faces = 0;
        std::vector<int> face_region;     ///< (mesh faces - surface_faces): hole region of each hole face
        std::vector<char> region_closed;  ///< per hole region: 1 closed, 0 open (see the file comment)
        size_t sods_cells = 0, hole_cells = 0;
        size_t evaluations = 0;           ///< corners at which f was evaluated
        /// Distinct corners of the SODS and hole cells the surface crosses: the fewest
        /// evaluations any extractor of the gated surface and its holes must make.
        size_t crossed_corners = 0;
        bool hole_search_capped = false;
    };

    /// Extracts into `mesh` (cleared first) the zero set of f inside the cells of `sods`, then
    /// (param.holes) in the hole cells. Faces point towards positive values of f.
    ///
    /// lattice: the cells and their corners' positions; sods: the cells to extract in (a subset
    /// of the lattice's); f: the implicit function, evaluated at lattice corners only;
    /// mesh: receives the vertices (one per crossed lattice edge) and faces, surface faces
    /// first; cb: progress from 10 to 90 (nullptr: none).
    static Result Compute(const Lattice& lattice, const Sods& sods, const ImplicitFunction& f, CoreMesh& mesh,
                          const Param& param, vcg::CallBackPos* cb = nullptr)
    {
        Result r;
        CornerValues values(lattice, f);
        const std::vector<Index3> cells = sods.Cells();
        r.sods_cells = cells.size();
        if (param.extraction == Extraction::SodsDriven) {
            if (cb) cb(10, "Evaluating the implicit function at SODS corners");
            values.Evaluate(cells);
        } else {
            values.EvaluateAll(cb);
        }
        // The hole cells are found before any triangle is made, so the mesh is reserved once
        // for both: a vector outgrowing its reserve copies every face made so far (on a large
        // run the peak memory of the whole filter).
        std::optional<HoleSearch> search;
        if (param.holes && param.extraction != Extraction::Plain) {
            if (cb) cb(60, "Searching hole cells");
            const size_t cap = param.max_hole_cells ? param.max_hole_cells : std::max<size_t>(cells.size(), 4096);
            search.emplace(lattice, sods, values, cells, cap);
        }
        if (param.extraction != Extraction::Plain) {
            // Measured: about 1.5 faces and 0.75 vertices per SODS cell (hole cells alike).
            const size_t all = cells.size() + (search ? search->cells.size() : 0);
            mesh.face.reserve(all * 8 / 5);
            mesh.vert.reserve(all * 4 / 5);
        }
        MarchingCubesWalker walker(lattice, mesh, values);
        vcg::tri::MarchingCubes<CoreMesh, MarchingCubesWalker> mc(mesh, walker);
        mc.Initialize();
        if (param.extraction == Extraction::Plain)
            ExtractAll(mc, lattice, cb);
        else
            Extract(mc, cells, cb);
        r.surface_faces = mesh.face.size();
        std::vector<Index3> crossed = cells;  // and the hole cells, which all are crossed

        if (search) {
            if (cb) cb(90, "Extracting hole triangles");
            r.hole_cells = search->cells.size();
            r.hole_search_capped = search->capped;
            r.region_closed = search->closed;
            for (size_t i = 0; i < search->cells.size(); ++i) {
                const size_t before = mesh.face.size();
                Process(mc, search->cells[i]);
                r.face_region.insert(r.face_region.end(), mesh.face.size() - before, search->region[i]);
            }
            crossed.insert(crossed.end(), search->cells.begin(), search->cells.end());
        }
        r.crossed_corners = values.CornerCount(crossed, true);
        mc.Finalize();
        r.evaluations = values.Count();
        return r;
    }

    /// Compute with the default Param (surface and holes).
    static Result Compute(const Lattice& lattice, const Sods& sods, const ImplicitFunction& f, CoreMesh& mesh)
    {
        return Compute(lattice, sods, f, mesh, Param());
    }

private:
    /// Marching cubes over `cells` (sorted), with progress from 60 to 90.
    template <class MarchingCubes>
    static void Extract(MarchingCubes& mc, const std::vector<Index3>& cells, vcg::CallBackPos* cb)
    {
        const size_t step = std::max<size_t>(1, cells.size() / 20);
        for (size_t i = 0; i < cells.size(); ++i) {
            Process(mc, cells[i]);
            if (cb && i % step == 0) cb(60 + int(30 * i / cells.size()), "Marching cubes over SODS cells");
        }
    }

    /// Marching cubes over every lattice cell, in the same (z, y, x) order as sorted SODS cells.
    template <class MarchingCubes>
    static void ExtractAll(MarchingCubes& mc, const Lattice& lattice, vcg::CallBackPos* cb)
    {
        for (int z = 0; z < lattice.cells[2]; ++z) {
            if (cb) cb(60 + 30 * z / lattice.cells[2], "Marching cubes over the whole lattice");
            for (int y = 0; y < lattice.cells[1]; ++y)
                for (int x = 0; x < lattice.cells[0]; ++x)
                    Process(mc, Index3(x, y, z));
        }
    }

    template <class MarchingCubes>
    static void Process(MarchingCubes& mc, const Index3& c)
    {
        mc.ProcessCell(vcg::Point3i(c[0], c[1], c[2]), vcg::Point3i(c[0] + 1, c[1] + 1, c[2] + 1));
    }

    /// Breadth-first search of the hole cells, level by level so that each level's new corners
    /// are evaluated in one batch; then their grouping into regions.
    struct HoleSearch
    {
        std::vector<Index3> cells;  ///< hole cells, sorted by key (PackIndex: z, then y, then x)
        std::vector<int> region;    ///< cells.size(): region of each cell, in [0, closed.size())
        std::vector<char> closed;   ///< per region: 1 when closed away from the lattice border
        bool capped = false;        ///< the search stopped at `cap` hole cells

        /// Searches from `sodsCells` (the cells of `sods`, sorted) outwards through cells not in
        /// `sods`, evaluating their corners into `values` (which must hold the SODS cells'
        /// corners), until no crossed face leads further or `cap` hole cells are found.

        HoleSearch(const Lattice& lattice, const Sods& sods, CornerValues& values, const std::vector<Index3>& sodsCells,
                   size_t cap)
        {
            static const Index3 kSteps[6] = {Index3(1, 0, 0), Index3(-1, 0, 0), Index3(0, 1, 0),
                                             Index3(0, -1, 0), Index3(0, 0, 1), Index3(0, 0, -1)};
            std::unordered_set<uint64_t> queued, examined, holes;
            std::vector<Index3> frontier;
            // The surface passes from a cell to a neighbour only through a face it crosses, so
            // only neighbours across crossed faces are visited (and evaluated): the search
            // follows the surface instead of flooding the shell around the SODS.
            auto enqueue = [&](const Index3& c, std::vector<Index3>& into) {
                for (const Index3& s : kSteps) {
                    const Index3 n = c + s;
                    if (lattice.ContainsCell(n) && !sods.Contains(n) && values.FaceCrossed(c, s) &&
                        queued.insert(Key(n)).second)
                        into.push_back(n);
                }
            };
            for (const Index3& c : sodsCells)
                enqueue(c, frontier);
            while (!frontier.empty() && !capped) {
                values.Evaluate(frontier);
                std::vector<Index3> next;
                for (const Index3& c : frontier) {
                    examined.insert(Key(c));
                    holes.insert(Key(c));  // entered through a crossed face: the surface is in it
                    if (holes.size() >= cap) {
                        capped = true;
                        break;
                    }
                    enqueue(c, next);
                }
                frontier.swap(next);
            }

            std::vector<uint64_t> keys(holes.begin(), holes.end());
            std::sort(keys.begin(), keys.end());
            std::unordered_map<uint64_t, int> label;
            for (uint64_t seed : keys) {
                if (label.count(seed))
                    continue;
                const int id = int(closed.size());
                closed.push_back(1);
                std::vector<uint64_t> stack{seed};
                label[seed] = id;
                while (!stack.empty()) {
                    const Index3 c = UnpackIndex(stack.back());
                    stack.pop_back();
                    for (const Index3& s : kSteps) {
                        if (!values.FaceCrossed(c, s))
                            continue;
                        const Index3 n = c + s;
                        // Open: the surface leaves the lattice, or goes where the search did not look.
                        if (!lattice.ContainsCell(n) || (!sods.Contains(n) && !examined.count(Key(n))))
                            closed[id] = 0;
                        if (lattice.ContainsCell(n) && holes.count(Key(n)) && label.emplace(Key(n), id).second)
                            stack.push_back(Key(n));
                    }
                }
            }
            cells.resize(keys.size());
            region.resize(keys.size());
            for (size_t i = 0; i < keys.size(); ++i) {
                cells[i] = UnpackIndex(keys[i]);
                region[i] = label[keys[i]];
            }
        }

        static uint64_t Key(const Index3& c) { return PackIndex(c[0], c[1], c[2]); }
    };
};

} // namespace ib
