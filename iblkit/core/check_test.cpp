// core/check.h: the checks every point, direction, box and size entering the library passes.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include "iblkit/core/check.h"

namespace ibl {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN(), kInf = std::numeric_limits<double>::infinity();

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Value);
    return e.what();
  }
  ADD_FAILURE() << "no error";
  return "";
}

TEST(CoreCheck, PointsMustBeFiniteAndWithinRange) {
  EXPECT_NO_THROW(require_point("p", {0, 1, -2}));
  EXPECT_NO_THROW(require_point("p", {kMaxCoordinate, -kMaxCoordinate, 0}));
  EXPECT_NE(message_of([] {
              require_point("capture position", {kNaN, 1, 0});
            }).find("capture position (nan, 1, 0) is not finite"),
            std::string::npos);
  EXPECT_NE(message_of([] { require_point("p", {0, kInf, 0}); }).find("not finite"), std::string::npos);
  EXPECT_NE(message_of([] { require_point("p", {1e30, 0, 0}); }).find("outside ±1e+06 m"), std::string::npos);
}

TEST(CoreCheck, DirectionsAreNormalisedAndNeverZero) {
  Vec3 d = require_direction("d", {0, 3, 4});
  EXPECT_DOUBLE_EQ(d.y, 0.6);
  EXPECT_NE(message_of([] { require_direction("d", {0, 0, 0}); }).find("zero length"), std::string::npos);
  EXPECT_NE(message_of([] { require_direction("d", {kNaN, 0, 1}); }).find("not finite"), std::string::npos);
  EXPECT_NE(message_of([] { require_direction("d", {1e30, 0, 1}); }).find("beyond"), std::string::npos);
}

TEST(CoreCheck, BoxesNumbersAndAllocations) {
  EXPECT_NO_THROW(require_box("b", {0, 0, 0}, {1, 1, 1}));
  EXPECT_NO_THROW(require_box("b", {0, 0, 0}, {0, 1, 1}));
  EXPECT_THROW(require_box("b", {0, 0, 0}, {0, 1, 1}, true), Error);
  EXPECT_THROW(require_box("b", {0, 0, 0}, {kInf, 1, 1}), Error);
  EXPECT_THROW(require_box("b", {0, 0, 0}, {1e30, 1, 1}), Error);
  EXPECT_THROW(require_box("b", {1, 0, 0}, {0, 1, 1}), Error);
  EXPECT_EQ(require_number("x", 2, 0, 3), 2);
  EXPECT_NE(message_of([] { require_number("exposure", kNaN, -20, 20); }).find("exposure = nan is not a finite number"),
            std::string::npos);
  EXPECT_THROW(require_number("x", -1, 0, 3), Error);
  EXPECT_NO_THROW(require_allocation("a", 1000, 4, "hint"));
  std::string m = message_of(
      [] { require_allocation("a 16384² cube", 6.0 * 16384 * 16384 * 16, 12, "choose a smaller size", 8e9); });
  EXPECT_NE(m.find("would allocate 309 GB (more than the 8 GB allowed); choose a smaller size"), std::string::npos)
      << m;
  EXPECT_GT(physical_memory(), 1e8);
}

}  // namespace
}  // namespace ibl
