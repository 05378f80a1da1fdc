// The implicit function interface: batch evaluation into any writable view of a vector. It
// has no code of its own; what it promises (values written into the given segment only, and
// calls on disjoint outputs from several threads at once) is checked through a tiny subclass.
#include "implicit/implicit_function.h"
#include "parallel.h"

#include <gtest/gtest.h>

#include <memory>

using namespace ib;

namespace {
/// f(q) = q.x + 2 q.y + 3 q.z - 1 (negative on the origin's side).
class Linear : public ImplicitFunction
{
public:
    void Eval(const Points& Q, Eigen::Ref<Eigen::VectorXd> values) const override
    {
        for (Eigen::Index i = 0; i < Q.rows(); ++i)
            values[i] = Q(i, 0) + 2 * Q(i, 1) + 3 * Q(i, 2) - 1;
    }
};
} // namespace

TEST(ImplicitFunction, EvaluatesIntoASegmentThroughTheInterface)
{
    const std::unique_ptr<ImplicitFunction> f = std::make_unique<Linear>();
    Points Q(3, 3);
    Q << 0, 0, 0, 1, 0, 0, 0, 1, 1;
    Eigen::VectorXd out = Eigen::VectorXd::Constant(7, -9);
    f->Eval(Q, out.segment(2, 3));
    EXPECT_EQ(out, (Eigen::VectorXd(7) << -9, -9, -1, 0, 4, -9, -9).finished());
}

TEST(ImplicitFunction, DisjointOutputsFromSeveralThreadsEqualOneBatch)
{
    const Linear f;
    Points Q(5000, 3);
    for (Eigen::Index i = 0; i < Q.rows(); ++i)
        Q.row(i) << 0.001 * double(i), std::sin(double(i)), -0.5;
    Eigen::VectorXd whole(Q.rows()), blocks(Q.rows());
    f.Eval(Q, whole);
    ParallelFor(size_t(Q.rows()), 3, [&](size_t begin, size_t end, int) {
        const Points part = Q.middleRows(Eigen::Index(begin), Eigen::Index(end - begin));
        f.Eval(part, blocks.segment(Eigen::Index(begin), Eigen::Index(end - begin)));
    }, 100);
    EXPECT_EQ(whole, blocks);
}
