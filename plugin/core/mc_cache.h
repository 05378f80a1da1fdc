#pragma once
/// \file mc_cache.h
/// What marching cubes reads and makes while it walks lattice cells, each computed once: the
/// implicit function's values at the lattice corners (CornerValues) and the surface vertices
/// on the lattice edges (MarchingCubesWalker, which serves both to VCG's
/// vcg::tri::MarchingCubes).
///
/// The values come from batch evaluations (ImplicitFunction::Eval on many points at a time,
/// which the implicit functions parallelise), not one corner at a time as VCG asks for them.
/// An edge's vertex is made by the first cell that crosses the edge and shared by the other
/// cells around it, so the cells' triangles are welded into one mesh whatever order the cells
/// are visited in (gated_mc.h visits the SODS cells, then the hole cells).

#include "implicit/implicit_function.h"
#include "lattice.h"
#include "mesh.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <vector>

namespace ib {

/// Values by lattice key (a corner's PackIndex, or an edge's): an open-addressing hash table
/// (linear probing, Fibonacci hashing, at most 70% full). Why not std::unordered_map: a node
/// per key costs a heap allocation and ~50 bytes, and each lookup chases a pointer; marching
/// cubes looks every corner up about a dozen times (perf on bun_zipper: the map's finds were
/// 7% of the run, and the extraction takes a fifth less without them). A slot keeps its place
/// until the table grows, so a block of new keys can be inserted first and valued after.
template <class Value>
class KeyTable
{
public:
    static constexpr size_t kNone = ~size_t(0);

    size_t Size() const { return size_; }
    /// Slots (a power of two, or 0 before the first Reserve): the range of slot numbers.
    size_t Slots() const { return keys_.size(); }

    /// Room for `more` keys beyond Size(): no growth (slots stay put) until they are in.
    void Reserve(size_t more)
    {
        if (double(size_ + more) <= kMaxLoad * double(keys_.size()))
            return;
        size_t size = std::max<size_t>(keys_.size(), 1024);
        while (double(size_ + more) > kMaxLoad * double(size))
            size *= 2;
        std::vector<uint64_t> keys(size, kEmpty);
        std::vector<Value> values(size);
        keys.swap(keys_);
        values.swap(values_);
        shift_ = 64;
        for (size_t n = size; n > 1; n >>= 1)
            --shift_;
        for (size_t i = 0; i < keys.size(); ++i)
            if (keys[i] != kEmpty) {
                const size_t s = Probe(keys[i]);
                keys_[s] = keys[i];
                values_[s] = values[i];
            }
    }

    /// The slot of `key`, which it gets if it is new (then `inserted`; the table grows if it
    /// is full, which moves the slots, unless room was reserved).
    size_t Insert(uint64_t key, bool& inserted)
    {
        Reserve(1);
        const size_t s = Probe(key);
        inserted = keys_[s] == kEmpty;
        if (inserted) {
            keys_[s] = key;
            ++size_;
        }
        return s;
    }

    /// The slot of `key`, or kNone.
    size_t Find(uint64_t key) const
    {
        if (keys_.empty())
            return kNone;
        const size_t s = Probe(key);
        return keys_[s] == kEmpty ? kNone : s;
    }

    Value& At(size_t slot) { return values_[slot]; }
    const Value& At(size_t slot) const { return values_[slot]; }

private:
    static constexpr uint64_t kEmpty = ~uint64_t(0);  // no key: PackIndex(x, y, z) < 2^60
    static constexpr double kMaxLoad = 0.7;

    /// The slot holding `key`, or the empty one where it would go.
    size_t Probe(uint64_t key) const
    {
        const size_t mask = keys_.size() - 1;
        size_t s = size_t((key * 0x9E3779B97F4A7C15ull) >> shift_);
        while (keys_[s] != key && keys_[s] != kEmpty)
            s = (s + 1) & mask;
        return s;
    }

    std::vector<uint64_t> keys_;
    std::vector<Value> values_;
    size_t size_ = 0;
    int shift_ = 64;  ///< 64 - log2(Slots()): the hash's top bits name the slot
};

/// Implicit function values at lattice corners, evaluated in batches, each corner once:
/// sparse (a KeyTable filled cell set by cell set) or dense (every corner, EvaluateAll).
/// Corners are named by their key PackIndex(x, y, z), x in [0, lattice.cells[0]] and so on.
class CornerValues
{
public:
    /// l: the lattice; f: the implicit function. Both are kept by reference (outlive this).
    CornerValues(const Lattice& l, const ImplicitFunction& f) : lattice_(l), f_(f) {}

    /// Evaluates every lattice corner, one z-slab per batch (the full-lattice extractions).
    /// cb: progress from 10 to 60, or nullptr.
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

    /// Evaluates the corners of `cells` (lattice cells; a cell's corners are c + {0,1}^3) that
    /// have no value yet, a block of cells per batch call (so the keys and query points of a
    /// large run are never all in memory at once). Nothing to do after EvaluateAll.
    void Evaluate(const std::vector<Index3>& cells)
    {
        if (!dense_.empty())
            return;
        constexpr size_t kBlock = 1 << 16;
        std::vector<size_t> fresh;  // the block's new corners, in the order its cells give them
        Points Q;
        Eigen::VectorXd out;
        for (size_t begin = 0; begin < cells.size(); begin += kBlock) {
            const size_t end = std::min(cells.size(), begin + kBlock);
            table_.Reserve(8 * (end - begin));
            fresh.clear();
            Q.resize(Eigen::Index(8 * (end - begin)), 3);
            for (size_t i = begin; i < end; ++i)
                for (int c = 0; c < 8; ++c) {
                    const Index3 v = cells[i] + Index3(c & 1, (c >> 1) & 1, c >> 2);
                    bool inserted;
                    const size_t s = table_.Insert(PackIndex(v[0], v[1], v[2]), inserted);
                    if (inserted) {
                        Q.row(Eigen::Index(fresh.size())) = lattice_.Corner(v[0], v[1], v[2]).transpose();
                        fresh.push_back(s);
                    }
                }
            Q.conservativeResize(Eigen::Index(fresh.size()), 3);
            out.resize(Q.rows());
            f_.Eval(Q, out);
            for (size_t i = 0; i < fresh.size(); ++i)
                table_.At(fresh[i]) = out[Eigen::Index(i)];
        }
    }

    /// The value at the corner with this key, which must have been evaluated.
    double operator()(uint64_t key) const
    {
        if (dense_.empty()) {
            const size_t slot = table_.Find(key);
            if (slot == KeyTable<double>::kNone)  // a bug, but not one to crash the host over
                throw std::logic_error("a lattice corner was read before it was evaluated");
            return table_.At(slot);
        }
        return dense_[DenseIndex(key)];
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
    size_t Count() const { return dense_.empty() ? table_.Size() : dense_.size(); }

    /// Distinct corners of `cells` (only of the crossed ones when `crossed`), whose corners
    /// must have been evaluated: a flag per slot (or lattice corner) marks those counted.
    size_t CornerCount(const std::vector<Index3>& cells, bool crossed) const
    {
        std::vector<bool> counted(dense_.empty() ? table_.Slots() : dense_.size());
        size_t count = 0;
        for (const Index3& c : cells) {
            const std::array<uint64_t, 8> keys = CornerKeys(c);
            std::array<size_t, 8> where;
            int positive = 0;
            for (int i = 0; i < 8; ++i) {
                where[size_t(i)] = dense_.empty() ? table_.Find(keys[size_t(i)]) : DenseIndex(keys[size_t(i)]);
                positive += (dense_.empty() ? table_.At(where[size_t(i)]) : dense_[where[size_t(i)]]) > 0;
            }
            if (crossed && (positive == 0 || positive == 8))
                continue;
            for (size_t w : where)
                if (!counted[w]) {
                    counted[w] = true;
                    ++count;
                }
        }
        return count;
    }

private:
    /// Keys of the 8 corners of cell c; corner i is c + (i & 1, (i >> 1) & 1, i >> 2).
    static std::array<uint64_t, 8> CornerKeys(const Index3& c)
    {
        std::array<uint64_t, 8> k;
        for (int i = 0; i < 8; ++i)
            k[i] = PackIndex(c[0] + (i & 1), c[1] + ((i >> 1) & 1), c[2] + (i >> 2));
        return k;
    }

    /// The corner's place in the dense array (x fastest).
    size_t DenseIndex(uint64_t key) const
    {
        const Index3 v = UnpackIndex(key);
        const size_t nx = size_t(lattice_.cells[0]) + 1, ny = size_t(lattice_.cells[1]) + 1;
        return (size_t(v[2]) * ny + size_t(v[1])) * nx + size_t(v[0]);
    }

    const Lattice& lattice_;
    const ImplicitFunction& f_;
    KeyTable<double> table_;
    std::vector<double> dense_;
};

/// The walker VCG's vcg::tri::MarchingCubes<CoreMesh, MarchingCubesWalker> asks for corner
/// values (served from CornerValues, which must hold the corners of every cell processed) and
/// for edge vertices (added to `mesh` once per lattice edge, welded by the edge's key).
class MarchingCubesWalker
{
public:
    /// l: the lattice; m: the mesh the vertices are added to; values: the corner values. All
    /// are kept by reference.
    MarchingCubesWalker(const Lattice& l, CoreMesh& m, const CornerValues& values)
        : lattice_(l), mesh_(m), values_(values)
    {
    }

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

    /// The vertex on edge a-b (along `axis`), added to the mesh the first time it is asked for.
    /// Held by index, not pointer: adding vertices may reallocate them.
    CoreVertex* Intercept(const vcg::Point3i& a, const vcg::Point3i& b, int axis)
    {
        const uint64_t ka = PackIndex(a[0], a[1], a[2]), kb = PackIndex(b[0], b[1], b[2]);
        bool fresh;
        const size_t s = edges_.Insert(std::min(ka, kb) << 2 | uint64_t(axis), fresh);
        if (fresh) {
            edges_.At(s) = mesh_.vert.size();
            const Eigen::Vector3d p = EdgePoint(a, b);
            auto vi = vcg::tri::Allocator<CoreMesh>::AddVertices(mesh_, 1);
            vi->P() = vcg::Point3d(p[0], p[1], p[2]);
        }
        return &mesh_.vert[edges_.At(s)];
    }

    const Lattice& lattice_;
    CoreMesh& mesh_;
    const CornerValues& values_;
    KeyTable<size_t> edges_;  ///< edge key (lower corner's key << 2 | axis) -> vertex index
    CoreVertex scratch_;
};

} // namespace ib
