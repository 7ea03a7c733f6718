#include "iblkit/lights/nnls.h"

#include <gtest/gtest.h>

namespace ibl::lights {
namespace {

constexpr double kTol = 1e-10;  // well-conditioned small systems: rounding only

TEST(LightsNnls, InteriorSolutionIsTheLinearSolve) {
  Eigen::MatrixXd H(2, 2);
  H << 2, 1, 1, 3;
  Eigen::VectorXd b(2);
  b << 3, 4;  // H x = b at x = (1, 1) > 0
  Eigen::VectorXd x;
  auto rep = nnls(H, b, x);
  EXPECT_TRUE(rep.kkt);
  EXPECT_NEAR(x(0), 1, kTol);
  EXPECT_NEAR(x(1), 1, kTol);
}

TEST(LightsNnls, BoundVariableAndKkt) {
  // min ½xᵀHx − bᵀx, H = diag-dominant; the unconstrained solution has x1 < 0, so x1 = 0 and
  // x0 = b0 / H00 (closed form), with the gradient of x1 pointing out of the feasible set.
  Eigen::MatrixXd H(2, 2);
  H << 2, 1, 1, 2;
  Eigen::VectorXd b(2);
  b << 2, -1;
  for (double warm : {0.0, 5.0}) {  // cold and a wrong warm start reach the same answer
    Eigen::VectorXd x = Eigen::VectorXd::Constant(2, warm);
    auto rep = nnls(H, b, x);
    EXPECT_TRUE(rep.kkt);
    EXPECT_NEAR(x(0), 1, kTol);
    EXPECT_EQ(x(1), 0);
    EXPECT_LE(b(1) - (H * x)(1), 0);
  }
}

TEST(LightsNnls, DuplicateColumnsDoNotBreakIt) {
  // Two identical columns (two lights in one direction): H singular; any split of the sum is optimal.
  Eigen::MatrixXd A(3, 2);
  A << 1, 1, 2, 2, 0.5, 0.5;
  Eigen::VectorXd y(3);
  y << 2, 4, 1;  // = A·(1, 1)
  Eigen::MatrixXd H = A.transpose() * A;
  Eigen::VectorXd b = A.transpose() * y, x;
  auto rep = nnls(H, b, x);
  EXPECT_TRUE(rep.kkt);
  EXPECT_GE(x.minCoeff(), 0);
  constexpr double kRidgeTol = 1e-9;  // the 1e-13 relative ridge shifts the sum by ~1e-13
  EXPECT_NEAR(x.sum(), 2, kRidgeTol);
}

}  // namespace
}  // namespace ibl::lights
