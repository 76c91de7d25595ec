#include "partsim/core/check.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "error_of.h"
#include "partsim/core/constants.h"

namespace partsim {
namespace {

using ::testing::HasSubstr;

using partsim::testing::ErrorOf;

TEST(FormatNumberTest, SmallNumbersKeepTheirValue) {
  // std::to_string prints this as "0.000000"
  EXPECT_EQ(FormatNumber(1e-7), "1e-07");
  EXPECT_EQ(FormatNumber(-2.5e-12), "-2.5e-12");
}

TEST(FormatNumberTest, ShortestTextThatReadsBack) {
  EXPECT_EQ(FormatNumber(0.1), "0.1");
  EXPECT_EQ(FormatNumber(1e300), "1e+300");
  EXPECT_EQ(FormatNumber(0.30000000000000004), "0.30000000000000004");
  for (double v : {kPi, 1.0 / 3.0, 123456.789, 6.02214076e23, 4.9e-324})
    EXPECT_EQ(std::strtod(FormatNumber(v).c_str(), nullptr), v) << FormatNumber(v);
}

TEST(FormatNumberTest, IntegersHaveNoDecimals) {
  EXPECT_EQ(FormatNumber(0.0), "0");
  EXPECT_EQ(FormatNumber(3.0), "3");
  EXPECT_EQ(FormatNumber(-42.0), "-42");
  EXPECT_EQ(FormatNumber(100.0), "100");
  EXPECT_EQ(FormatNumber(16384.0), "16384");
  EXPECT_EQ(FormatNumber(-1e6), "-1000000");
  EXPECT_EQ(FormatNumber(120.5), "120.5");
}

TEST(FormatNumberTest, SpecialValues) {
  EXPECT_EQ(FormatNumber(-0.0), "-0");
  EXPECT_EQ(FormatNumber(kInf), "inf");
  EXPECT_EQ(FormatNumber(-kInf), "-inf");
  EXPECT_EQ(FormatNumber(std::numeric_limits<double>::quiet_NaN()), "nan");
}

TEST(FormatVectorTest, VectorsAndMatrices) {
  EXPECT_EQ(FormatVector(Eigen::Vector3d(1, 0.5, 1e-7)), "[1, 0.5, 1e-07]");
  EXPECT_EQ(FormatVector(Eigen::RowVector2d(2, -3)), "[2, -3]");
  EXPECT_EQ(FormatVector(Eigen::Vector3f(0.25f, 0, 1)), "[0.25, 0, 1]");
  Eigen::Matrix2d m;
  m << 1, 2, 3, 4;
  EXPECT_EQ(FormatVector(m), "[[1, 2], [3, 4]]");
  EXPECT_EQ(FormatVector(Eigen::VectorXd()), "[]");
}

TEST(ConstantsTest, PiAndInfinity) {
  EXPECT_EQ(kPi, std::acos(-1.0));
  EXPECT_TRUE(std::isinf(kInf));
  EXPECT_GT(kInf, 0);
}

TEST(ThrowUnlessTest, MessageAndConditionText) {
  const int width = -3;
  std::string message = ErrorOf(
      [&] { PARTSIM_THROW_UNLESS(width > 0, "width must be > 0, got " + std::to_string(width)); });
  EXPECT_EQ(message, "width must be > 0, got -3 (failed: width > 0)");
  EXPECT_EQ(ErrorOf([&] { PARTSIM_THROW_UNLESS(width < 0, "unused"); }), "");
}

TEST(ThrowUnlessTest, MessageIsBuiltOnlyOnFailure) {
  int built = 0;
  auto message = [&built] {
    ++built;
    return std::string("m");
  };
  PARTSIM_THROW_UNLESS(true, message());
  EXPECT_EQ(built, 0);
  EXPECT_THROW(PARTSIM_THROW_UNLESS(false, message()), Error);
  EXPECT_EQ(built, 1);
}

TEST(CheckFiniteTest, NamesTheArgumentAndShowsTheValue) {
  EXPECT_NO_THROW(CheckFinite("gravity", Eigen::Vector3d(0, 0, -9.81)));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(ErrorOf([&] { CheckFinite("gravity", Eigen::Vector3d(0, nan, 1e-7)); }),
            "gravity must be finite, got [0, nan, 1e-07]");
  EXPECT_EQ(ErrorOf([&] { CheckFinite("twist", Eigen::Matrix<double, 6, 1>::Constant(kInf)); }),
            "twist must be finite, got [inf, inf, inf, inf, inf, inf]");
}

TEST(CheckPoseTest, NamesTheArgumentAndShowsThePose) {
  EXPECT_NO_THROW(CheckPose("X_WB", Pose(Eigen::Vector3d(1, 2, 3))));
  Pose not_unit(Eigen::Vector3d::Zero(), Eigen::Quaterniond(2, 0, 0, 0));
  std::string message = ErrorOf([&] { CheckPose("X_WB", not_unit); });
  EXPECT_THAT(message, HasSubstr("X_WB must hold finite numbers and a unit quaternion, got "));
  EXPECT_THAT(message, HasSubstr(not_unit.ToString()));
  Pose not_finite(Eigen::Vector3d(kInf, 0, 0));
  EXPECT_THAT(ErrorOf([&] { CheckPose("local_pose", not_finite); }), HasSubstr("local_pose"));
}

TEST(DemandDeathTest, AbortsWithFileLineAndCondition) {
  const int count = 2;
  EXPECT_DEATH(PARTSIM_DEMAND(count == 3), "check_test\\.cc:[0-9]+: demand failed: count == 3");
  PARTSIM_DEMAND(count == 2);  // holds: nothing happens
}

}  // namespace
}  // namespace partsim
