#pragma once
/// \file gated_mc.h
/// Marching cubes gated by the SODS (paper §3.2) and the hole triangles (paper §3.3).
///
/// Surface triangles are extracted only in SODS cells, evaluating the implicit function only
/// at the corners of those cells (the "SODS-driven" extraction of paper §3.4: Θ(k) in the
/// number of SODS cells instead of Θ(m) in the lattice size). Hole triangles are then found by
/// a breadth-first search from the SODS cells through empty cells that the implicit surface
/// crosses, stepping only across cell faces the surface crosses (so only the cells along the
/// surface are evaluated, not the shell of empty cells around the SODS); they are extracted with the same walker, so they share vertices
/// with the surface and surface + holes is the closed marching cubes surface. Each connected
/// set of hole cells is a hole region; a region is closed when the search finished it away
/// from the lattice border (the implicit surface closes it), open otherwise (the surface runs
/// off, as at a cut, or the search hit its cap).
///
/// Two more extractions serve as references (paper §3.4): the paper's own implementation,
/// which evaluates every lattice corner and then extracts only in SODS cells (same triangles,
/// Θ(m) evaluations), and plain marching cubes over the whole lattice (no gate, no holes: the
/// closed surface the paper compares against).
///
/// Uses VCGlib's topologically consistent vcg::tri::MarchingCubes tables with our own walker,
/// which serves corner values from batch evaluations and welds the edge vertices of neighbours.

#include "implicit/implicit_function.h"
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

#include <array>
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
        std::vector<int> face_region;
        std::vector<char> region_closed;  ///< per hole region
        size_t sods_cells = 0, hole_cells = 0, evaluations = 0;
        /// Distinct corners of the SODS and hole cells the surface crosses: the fewest
        /// evaluations any extractor of the gated surface and its holes must make.
        size_t crossed_corners = 0;
        bool hole_search_capped = false;
    };

    /// Extracts into `mesh` (cleared first) the zero set of f inside the cells of `sods`, then
    /// (param.holes) in the hole cells. Faces point towards positive values of f.
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
        Walker walker(lattice, mesh, values);
        vcg::tri::MarchingCubes<CoreMesh, Walker> mc(mesh, walker);
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

    static std::array<uint64_t, 8> CornerKeys(const Index3& c)
    {
        std::array<uint64_t, 8> k;
        for (int i = 0; i < 8; ++i)
            k[i] = PackIndex(c[0] + (i & 1), c[1] + ((i >> 1) & 1), c[2] + (i >> 2));
        return k;
    }

    /// Implicit function values at lattice corners, evaluated in batches, each corner once:
    /// sparse (a hash map filled cell set by cell set) or dense (every corner, EvaluateAll).
    class CornerValues
    {
    public:
        CornerValues(const Lattice& l, const ImplicitFunction& f) : lattice_(l), f_(f) {}

        /// Evaluates every lattice corner, one z-slab per batch (the full-lattice extractions).
        void EvaluateAll(vcg::CallBackPos* cb)
        {
            const Index3 n = lattice_.cells + Index3::Ones();
            dense_.resize(size_t(n[0]) * size_t(n[1]) * size_t(n[2]));
            Points Q(Eigen::Index(n[0]) * n[1], 3);
            for (int z = 0; z < n[2]; ++z) {
                if (cb) cb(10 + 50 * z / n[2], "Evaluating the implicit function on the whole lattice");
                for (int y = 0; y < n[1]; ++y)
                    for (int x = 0; x < n[0]; ++x)
                        Q.row(Eigen::Index(y) * n[0] + x) = lattice_.Corner(x, y, z).transpose();
                f_.Eval(Q, Eigen::Map<Eigen::VectorXd>(dense_.data() + size_t(z) * size_t(Q.rows()), Q.rows()));
            }
        }

        /// Evaluates the corners of `cells` that have no value yet, a block of cells per batch
        /// call (so the keys and query points of a large run are never all in memory at once).
        void Evaluate(const std::vector<Index3>& cells)
        {
            if (!dense_.empty())
                return;
            constexpr size_t kBlock = 1 << 16;
            std::vector<uint64_t> keys;
            Points Q;
            Eigen::VectorXd out;
            for (size_t begin = 0; begin < cells.size(); begin += kBlock) {
                keys.clear();
                for (size_t i = begin; i < std::min(cells.size(), begin + kBlock); ++i)
                    for (uint64_t k : CornerKeys(cells[i]))
                        if (!values_.count(k))
                            keys.push_back(k);
                std::sort(keys.begin(), keys.end());
                keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
                Q.resize(Eigen::Index(keys.size()), 3);
                for (size_t i = 0; i < keys.size(); ++i) {
                    const Index3 v = UnpackIndex(keys[i]);
                    Q.row(Eigen::Index(i)) = lattice_.Corner(v[0], v[1], v[2]).transpose();
                }
                out.resize(Q.rows());
                f_.Eval(Q, out);
                values_.reserve(values_.size() + keys.size());
                for (size_t i = 0; i < keys.size(); ++i)
                    values_.emplace(keys[i], out[Eigen::Index(i)]);
            }
        }

        double operator()(uint64_t key) const
        {
            if (dense_.empty())
                return values_.at(key);
            const Index3 v = UnpackIndex(key);
            const size_t nx = size_t(lattice_.cells[0]) + 1, ny = size_t(lattice_.cells[1]) + 1;
            return dense_[(size_t(v[2]) * ny + size_t(v[1])) * nx + size_t(v[0])];
        }

        /// True when the surface crosses cell c (its corners are not all on one side).
        bool Crossed(const Index3& c) const
        {
            int positive = 0;
            for (uint64_t k : CornerKeys(c))
                positive += (*this)(k) > 0;
            return positive != 0 && positive != 8;
        }

        /// True when the surface crosses the face of cell c towards its neighbour c + step
        /// (step: a unit axis vector): the face's four corners are not all on one side.
        bool FaceCrossed(const Index3& c, const Index3& step) const
        {
            int axis = 0;
            while (step[axis] == 0)
                ++axis;
            const int a = (axis + 1) % 3, b = (axis + 2) % 3;
            Index3 v = c;
            v[axis] += step[axis] > 0;
            int positive = 0;
            for (int i = 0; i < 4; ++i) {
                Index3 corner = v;
                corner[a] += i & 1;
                corner[b] += i >> 1;
                positive += (*this)(PackIndex(corner[0], corner[1], corner[2])) > 0;
            }
            return positive != 0 && positive != 4;
        }

        /// Corners evaluated so far.
        size_t Count() const { return dense_.empty() ? values_.size() : dense_.size(); }

        /// Distinct corners of `cells` (only of the crossed ones when `crossed`). Counted one
        /// corner level z at a time, from the cells at z - 1 and z, to keep the keys small.
        size_t CornerCount(const std::vector<Index3>& cells, bool crossed) const
        {
            std::vector<uint64_t> cellKeys;
            std::vector<int> levels;
            for (const Index3& c : cells)
                if (!crossed || Crossed(c)) {
                    cellKeys.push_back(PackIndex(c[0], c[1], c[2]));
                    levels.push_back(c[2]);
                    levels.push_back(c[2] + 1);
                }
            std::sort(cellKeys.begin(), cellKeys.end());  // z first
            std::sort(levels.begin(), levels.end());
            levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
            size_t count = 0;
            std::vector<uint64_t> level;
            for (int z : levels) {
                level.clear();
                auto first = std::lower_bound(cellKeys.begin(), cellKeys.end(), PackIndex(0, 0, std::max(0, z - 1)));
                auto last = std::lower_bound(cellKeys.begin(), cellKeys.end(), PackIndex(0, 0, z + 1));
                for (auto it = first; it != last; ++it) {
                    const Index3 c = UnpackIndex(*it);
                    for (int k = 0; k < 4; ++k)
                        level.push_back(PackIndex(c[0] + (k & 1), c[1] + (k >> 1), z));
                }
                std::sort(level.begin(), level.end());
                count += size_t(std::unique(level.begin(), level.end()) - level.begin());
            }
            return count;
        }

    private:
        const Lattice& lattice_;
        const ImplicitFunction& f_;
        std::unordered_map<uint64_t, double> values_;
        std::vector<double> dense_;
    };

    /// Breadth-first search of the hole cells, level by level so that each level's new corners
    /// are evaluated in one batch; then their grouping into regions.
    struct HoleSearch
    {
        std::vector<Index3> cells;  ///< hole cells, sorted by key
        std::vector<int> region;    ///< region of each cell
        std::vector<char> closed;   ///< per region
        bool capped = false;

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

    /// Serves VCG's MarchingCubes: corner values from CornerValues, edge vertices welded by edge key.
    class Walker
    {
    public:
        Walker(const Lattice& l, CoreMesh& m, const CornerValues& values) : lattice_(l), mesh_(m), values_(values) {}

        /// Served as is, f gives faces whose normals point to f > 0 (outside); VCG's tables take
        /// f > 0 as the corner's "set" state.
        double V(int x, int y, int z) const { return values_(PackIndex(x, y, z)); }

        void GetXIntercept(const vcg::Point3i& a, const vcg::Point3i& b, CoreVertex*& v) { v = Intercept(a, b, 0); }
        void GetYIntercept(const vcg::Point3i& a, const vcg::Point3i& b, CoreVertex*& v) { v = Intercept(a, b, 1); }
        void GetZIntercept(const vcg::Point3i& a, const vcg::Point3i& b, CoreVertex*& v) { v = Intercept(a, b, 2); }

        /// Asked for the centre vertex of ambiguous cases: every crossed edge of the cell gives
        /// its crossing point, so the centre does not depend on the order cells are visited.
        /// VCG only reads the position, while it holds the new centre vertex by pointer: adding
        /// the edge vertex to the mesh here could reallocate the vertices under that pointer
        /// (a use after free found by fuzzing), so a scratch vertex carries the position.
        bool Exist(const vcg::Point3i& a, const vcg::Point3i& b, CoreVertex*& v)
        {
            const bool ina = V(a[0], a[1], a[2]) > 0, inb = V(b[0], b[1], b[2]) > 0;
            v = nullptr;
            if (ina == inb)
                return false;
            const Eigen::Vector3d p = EdgePoint(a, b);
            scratch_.P() = vcg::Point3d(p[0], p[1], p[2]);
            v = &scratch_;
            return true;
        }

    private:
        /// Where f crosses zero on the lattice edge a-b (linear interpolation).
        Eigen::Vector3d EdgePoint(const vcg::Point3i& a, const vcg::Point3i& b) const
        {
            const double fa = values_(PackIndex(a[0], a[1], a[2])), fb = values_(PackIndex(b[0], b[1], b[2]));
            const double t = fa / (fa - fb);
            const Eigen::Vector3d pa = lattice_.Corner(a[0], a[1], a[2]), pb = lattice_.Corner(b[0], b[1], b[2]);
            return pa + t * (pb - pa);
        }

        CoreVertex* Intercept(const vcg::Point3i& a, const vcg::Point3i& b, int axis)
        {
            const uint64_t ka = PackIndex(a[0], a[1], a[2]), kb = PackIndex(b[0], b[1], b[2]);
            auto [it, fresh] = edges_.try_emplace(std::min(ka, kb) << 2 | uint64_t(axis), mesh_.vert.size());
            if (fresh) {
                const Eigen::Vector3d p = EdgePoint(a, b);
                auto vi = vcg::tri::Allocator<CoreMesh>::AddVertices(mesh_, 1);
                vi->P() = vcg::Point3d(p[0], p[1], p[2]);
            }
            return &mesh_.vert[it->second];
        }

        const Lattice& lattice_;
        CoreMesh& mesh_;
        const CornerValues& values_;
        std::unordered_map<uint64_t, size_t> edges_;
        CoreVertex scratch_;
    };
};

} // namespace ib
