#include "partsim/core/pose.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <limits>
#include <string>

namespace partsim {
namespace {

TEST(PoseTest, ToStringPrintsNumbersThatReadBack) {
  EXPECT_EQ(Pose().ToString(), "Pose([0, 0, 0], [1, 0, 0, 0])");
  // ostream's 6 significant digits printed 1e-07 and 0.1234567 as 1e-07 and 0.123457
  Pose pose(Eigen::Vector3d(0.1234567, -2.5, 1e-7), Eigen::Quaterniond(0, 1, 0, 0));
  EXPECT_EQ(pose.ToString(), "Pose([0.1234567, -2.5, 1e-07], [0, 1, 0, 0])");
  // whole numbers in full, not 1e+06
  EXPECT_EQ(Pose(Eigen::Vector3d(1e6, 0, 0)).ToString(), "Pose([1000000, 0, 0], [1, 0, 0, 0])");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(Pose(Eigen::Vector3d(nan, 0, 0)).ToString(), "Pose([nan, 0, 0], [1, 0, 0, 0])");
}

TEST(PoseTest, ToStringRoundTripsTheQuaternion) {
  // a unit quaternion's entries need all 17 digits: each reads back to the same double
  const Eigen::Quaterniond q = Eigen::Quaterniond(0.3, -0.1, 0.7, 0.2).normalized();
  const std::string text = Pose(Eigen::Vector3d::Zero(), q).ToString();
  const size_t start = text.find("], [") + 4;
  const char* s = text.c_str() + start;
  for (double expected : {q.w(), q.x(), q.y(), q.z()}) {
    char* end = nullptr;
    EXPECT_EQ(std::strtod(s, &end), expected) << text;
    s = end + 2;  // past ", "
  }
}

}  // namespace
}  // namespace partsim
