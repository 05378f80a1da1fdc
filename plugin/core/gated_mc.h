#pragma once
/// \file gated_mc.h
/// Marching cubes gated by the SODS (paper §3.2): triangles are extracted only in SODS
/// cells, and the implicit function is evaluated only at the corners of those cells
/// (the "SODS-driven" extraction the paper proposes in §3.4; cost Θ(k) in the number of
/// SODS cells instead of Θ(m) in the lattice size). Uses VCGlib's topologically consistent
/// vcg::tri::MarchingCubes tables with our own walker, which serves corner values from one
/// batch evaluation and welds every edge vertex shared by neighbouring cells.

#include "implicit/implicit_function.h"
#include "mesh.h"
#include "sods.h"

#include <vcg/complex/algorithms/create/marching_cubes.h>

#include <unordered_map>

namespace ib {

class GatedMarchingCubes
{
public:
    struct Stats
    {
        size_t cells = 0;        ///< SODS cells visited
        size_t evaluations = 0;  ///< implicit function evaluations
    };

    /// Extracts into `mesh` (cleared first) the zero set of f inside the cells of `sods`.
    /// Faces are oriented with their normals towards positive values of f.
    static Stats Compute(const Lattice& lattice, const Sods& sods, const ImplicitFunction& f,
                         CoreMesh& mesh, vcg::CallBackPos* cb = nullptr)
    {
        Stats stats;
        const std::vector<Index3> cells = sods.Cells();
        stats.cells = cells.size();

        // Unique corners of the SODS cells, in sorted key order (deterministic).
        std::vector<uint64_t> keys;
        keys.reserve(cells.size() * 8);
        for (const Index3& c : cells)
            for (int corner = 0; corner < 8; ++corner)
                keys.push_back(PackIndex(c[0] + (corner & 1), c[1] + ((corner >> 1) & 1), c[2] + (corner >> 2)));
        std::sort(keys.begin(), keys.end());
        keys.erase(std::unique(keys.begin(), keys.end()), keys.end());

        Points Q(keys.size(), 3);
        for (size_t i = 0; i < keys.size(); ++i) {
            const Index3 v = UnpackIndex(keys[i]);
            Q.row(Eigen::Index(i)) = lattice.Corner(v[0], v[1], v[2]).transpose();
        }
        if (cb) cb(10, "Evaluating the implicit function at SODS corners");
        Eigen::VectorXd values(Q.rows());
        f.Eval(Q, values);
        stats.evaluations = size_t(Q.rows());

        Walker walker(lattice, mesh, keys, values);
        vcg::tri::MarchingCubes<CoreMesh, Walker> mc(mesh, walker);
        mc.Initialize();
        const size_t step = std::max<size_t>(1, cells.size() / 20);
        for (size_t i = 0; i < cells.size(); ++i) {
            const Index3& c = cells[i];
            mc.ProcessCell(vcg::Point3i(c[0], c[1], c[2]), vcg::Point3i(c[0] + 1, c[1] + 1, c[2] + 1));
            if (cb && i % step == 0) cb(60 + int(40 * i / cells.size()), "Marching cubes over SODS cells");
        }
        mc.Finalize();
        return stats;
    }

private:
    /// Serves VCG's MarchingCubes: corner values from the batch, edge vertices welded by edge key.
    class Walker
    {
    public:
        Walker(const Lattice& l, CoreMesh& m, const std::vector<uint64_t>& keys, const Eigen::VectorXd& values)
            : lattice_(l), mesh_(m), keys_(keys), values_(values)
        {
        }

        /// Served as is, f gives faces whose normals point to f > 0 (outside); VCG's tables take
        /// f > 0 as the corner's "set" state.
        double V(int x, int y, int z) const { return Value(PackIndex(x, y, z)); }

        void GetXIntercept(const vcg::Point3i& a, const vcg::Point3i& b, CoreVertex*& v) { v = Intercept(a, b, 0); }
        void GetYIntercept(const vcg::Point3i& a, const vcg::Point3i& b, CoreVertex*& v) { v = Intercept(a, b, 1); }
        void GetZIntercept(const vcg::Point3i& a, const vcg::Point3i& b, CoreVertex*& v) { v = Intercept(a, b, 2); }

        /// Asked for the centre vertex of ambiguous cases: every crossed edge of the cell gets
        /// its vertex, so the centre does not depend on the order cells are visited.
        bool Exist(const vcg::Point3i& a, const vcg::Point3i& b, CoreVertex*& v)
        {
            const bool ina = V(a[0], a[1], a[2]) > 0, inb = V(b[0], b[1], b[2]) > 0;
            v = ina != inb ? Intercept(a, b, a[0] != b[0] ? 0 : a[1] != b[1] ? 1 : 2) : nullptr;
            return v != nullptr;
        }

    private:
        double Value(uint64_t key) const
        {
            auto it = std::lower_bound(keys_.begin(), keys_.end(), key);
            assert(it != keys_.end() && *it == key);
            return values_[it - keys_.begin()];
        }

        CoreVertex* Intercept(const vcg::Point3i& a, const vcg::Point3i& b, int axis)
        {
            const uint64_t ka = PackIndex(a[0], a[1], a[2]), kb = PackIndex(b[0], b[1], b[2]);
            const uint64_t lo = std::min(ka, kb);
            auto [it, fresh] = edges_.try_emplace(lo << 2 | uint64_t(axis), mesh_.vert.size());
            if (fresh) {
                const double fa = Value(ka), fb = Value(kb);
                const double t = fa / (fa - fb);
                const Eigen::Vector3d pa = lattice_.Corner(a[0], a[1], a[2]), pb = lattice_.Corner(b[0], b[1], b[2]);
                const Eigen::Vector3d p = pa + t * (pb - pa);
                auto vi = vcg::tri::Allocator<CoreMesh>::AddVertices(mesh_, 1);
                vi->P() = vcg::Point3d(p[0], p[1], p[2]);
            }
            return &mesh_.vert[it->second];
        }

        const Lattice& lattice_;
        CoreMesh& mesh_;
        const std::vector<uint64_t>& keys_;
        const Eigen::VectorXd& values_;
        std::unordered_map<uint64_t, size_t> edges_;
    };
};

} // namespace ib
