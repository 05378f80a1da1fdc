// The input check: one clear message per kind of bad input; duplicates and missing normals.
// lattice.h first: input_check.h uses its Points without including it.
#include "lattice.h"
#include "input_check.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <type_traits>

using namespace ib;

namespace {
/// The message InputCheck::Samples throws, or "no error".
std::string Message(const Points& P, const Points& N = Points(), const Points& facing = Points(),
                    const std::vector<Eigen::Index>& scans = {})
{
    try {
        InputCheck::Samples(P, N, facing, scans);
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

/// n samples on the plane z = x + y, spread in x and y.
Points Plane(int n)
{
    Points P(n, 3);
    for (int i = 0; i < n; ++i)
        P.row(i) << i % 4, i / 4, i % 4 + i / 4;
    return P;
}

bool Has(const std::string& message, const std::string& part)
{
    return message.find(part) != std::string::npos;
}
} // namespace

TEST(InputCheck, AcceptsAFlatScanWithOrWithoutNormals)
{
    const Points P = Plane(InputCheck::kMinPoints);
    EXPECT_EQ(Message(P), "no error");
    EXPECT_EQ(Message(P, Points::Zero(P.rows(), 3), Points::Zero(P.rows(), 3), {4, 6}), "no error");
    static_assert(std::is_base_of_v<std::runtime_error, InputError>);
}

TEST(InputCheck, SaysWhatIsWrongWithTheSamples)
{
    EXPECT_TRUE(Has(Message(Points(0, 3)), "The layer has no vertices")) << Message(Points(0, 3));
    EXPECT_TRUE(Has(Message(Plane(9)), "only 9 vertices; at least 10 samples")) << Message(Plane(9));
    Points bad = Plane(20);
    bad(3, 1) = std::numeric_limits<double>::quiet_NaN();
    bad(7, 2) = std::numeric_limits<double>::infinity();
    EXPECT_TRUE(Has(Message(bad), "2 of 20 vertices have NaN or infinite coordinates")) << Message(bad);
    EXPECT_TRUE(Has(Message(Points::Constant(12, 3, 0.5)), "All vertices are at the same position"));
    Points line(12, 3);
    for (int i = 0; i < 12; ++i)
        line.row(i) << i, 2 * i, -i;
    EXPECT_TRUE(Has(Message(line), "All vertices lie on one line")) << Message(line);
    line(5, 0) += 1e-3;  // off the line by far more than a millionth: a (thin) surface
    EXPECT_EQ(Message(line), "no error");
}

TEST(InputCheck, SaysWhenNormalsFacingsOrScansDoNotMatch)
{
    const Points P = Plane(20);
    EXPECT_EQ(Message(P, Points::Zero(19, 3)), "There must be one normal per vertex.");
    EXPECT_EQ(Message(P, Points(), Points::Zero(5, 3)), "The facing directions have 5 rows for 20 samples.");
    EXPECT_EQ(Message(P, Points(), Points(), {10, 9}), "The scans' sizes must add up to the number of vertices.");
    EXPECT_EQ(Message(P, Points(), Points(), {10, 10}), "no error");
}

TEST(InputCheck, DistinctRowsKeepsTheFirstOfEachPosition)
{
    Points P(6, 3);
    P << 1, 2, 3,  //
        0, 0, 0,   //
        1, 2, 3,   // same as row 0
        1, 2, 3.5, //
        0, 0, 0,   // same as row 1
        -1, 0, 0;
    EXPECT_EQ(InputCheck::DistinctRows(P), (std::vector<Eigen::Index>{0, 1, 3, 5}));
    EXPECT_TRUE(InputCheck::DistinctRows(Points(0, 3)).empty());
    EXPECT_EQ(InputCheck::DistinctRows(Plane(12)).size(), 12u);
}

TEST(InputCheck, HasNormalsUnlessNoneOrAllZero)
{
    EXPECT_FALSE(InputCheck::HasNormals(Points()));
    Points N = Points::Zero(5, 3);
    EXPECT_FALSE(InputCheck::HasNormals(N));
    N(3, 1) = -1;
    EXPECT_TRUE(InputCheck::HasNormals(N));
}
