// base/option_check.h: every helper names the field, the value and the bound in the one format
// "<field> = <value>; must be <allowed>", NaN fails every bound and reads "nan", infinities
// read "inf" / "-inf", and a passing value leaves the failure untouched.
#include "base/option_check.h"

#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

namespace bifilar {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The message of the failure `check` reports; "" when it passes.
template <typename F>
std::string MessageOf(F check) {
  CheckFailure failure;
  failure.field = "untouched";
  if (check(&failure)) {
    EXPECT_EQ(failure.field, "untouched");  // a passing bound leaves *failure as it was
    return "";
  }
  return failure.Message();
}

TEST(OptionCheck, ValuesReadBackExactly) {
  EXPECT_EQ(FormatCheckValue(-1), "-1");
  EXPECT_EQ(FormatCheckValue(0.0), "0");
  EXPECT_EQ(FormatCheckValue(-0.0), "0");
  EXPECT_EQ(FormatCheckValue(1000000), "1000000");
  EXPECT_EQ(FormatCheckValue(0.01), "0.01");
  EXPECT_EQ(FormatCheckValue(1e100), "1e+100");
  EXPECT_EQ(FormatCheckValue(1e-300), "1e-300");
  // Shortest text that reads back to the same double: a value just over a bound is not shown
  // as the bound itself ("%g" would print 1 for both).
  EXPECT_EQ(FormatCheckValue(1.0000001), "1.0000001");
  EXPECT_EQ(std::stod(FormatCheckValue(0.1 + 0.2)), 0.1 + 0.2);
  EXPECT_EQ(FormatCheckValue(std::nan("")), "nan");
  EXPECT_EQ(FormatCheckValue(-std::nan("")), "nan");
  EXPECT_EQ(FormatCheckValue(kInf), "inf");
  EXPECT_EQ(FormatCheckValue(-kInf), "-inf");
}

TEST(OptionCheck, OneMessageFormat) {
  EXPECT_EQ(CheckMessage("window.min_period_s", -1, "> 0"),
            "window.min_period_s = -1; must be > 0");
  CheckFailure f{"min_period_s", -1, "> 0"};
  EXPECT_EQ(f.Message(), "min_period_s = -1; must be > 0");
  std::string why;
  EXPECT_FALSE(FailWith(f, &why, "window: "));
  EXPECT_EQ(why, "window: min_period_s = -1; must be > 0");
  EXPECT_FALSE(FailWith(f, nullptr));  // why may be null
}

TEST(OptionCheck, ComparisonsAtTheBound) {
  const auto gt = [](double v) {
    return MessageOf([v](CheckFailure* f) { return CheckGt("a", v, 0, f); });
  };
  const auto ge = [](double v) {
    return MessageOf([v](CheckFailure* f) { return CheckGe("a", v, 0, f); });
  };
  const auto lt = [](double v) {
    return MessageOf([v](CheckFailure* f) { return CheckLt("a", v, 1, f); });
  };
  const auto le = [](double v) {
    return MessageOf([v](CheckFailure* f) { return CheckLe("a", v, 1, f); });
  };
  EXPECT_EQ(gt(1e-300), "");
  EXPECT_EQ(gt(0), "a = 0; must be > 0");
  EXPECT_EQ(ge(0), "");
  EXPECT_EQ(ge(-1e-300), "a = -1e-300; must be >= 0");
  EXPECT_EQ(lt(0.5), "");
  EXPECT_EQ(lt(1), "a = 1; must be < 1");
  EXPECT_EQ(le(1), "");
  EXPECT_EQ(le(1.5), "a = 1.5; must be <= 1");
  // Plain comparisons let an infinity through on its open side, and stop it on the other.
  EXPECT_EQ(gt(kInf), "");
  EXPECT_EQ(gt(-kInf), "a = -inf; must be > 0");
  EXPECT_EQ(le(kInf), "a = inf; must be <= 1");
}

TEST(OptionCheck, NanFailsEveryBound) {
  const double nan = std::nan("");
  CheckFailure f;
  EXPECT_FALSE(CheckGt("a", nan, 0, &f));
  EXPECT_EQ(f.Message(), "a = nan; must be > 0");
  EXPECT_FALSE(CheckGe("a", nan, 0, &f));
  EXPECT_FALSE(CheckLt("a", nan, 0, &f));
  EXPECT_FALSE(CheckLe("a", nan, 0, &f));
  EXPECT_FALSE(CheckFinite("a", nan, &f));
  EXPECT_FALSE(CheckFiniteGt("a", nan, 0, &f));
  EXPECT_FALSE(CheckFiniteGe("a", nan, 0, &f));
  EXPECT_FALSE(CheckGt("a", nan, "b", 0, &f));
  EXPECT_FALSE(CheckIn("a", nan, -kInf, kInf, Ends::kClosed, &f));
  EXPECT_EQ(f.Message(), "a = nan; must be in [-inf, inf]");
  EXPECT_FALSE(CheckGe("a", nan, 0, nullptr));  // failure may be null
}

TEST(OptionCheck, FiniteVariantsRefuseInfinities) {
  CheckFailure f;
  EXPECT_TRUE(CheckFiniteGt("a", 1e308, 0, &f));
  EXPECT_FALSE(CheckFiniteGt("a", kInf, 0, &f));
  EXPECT_EQ(f.Message(), "a = inf; must be finite and > 0");
  EXPECT_FALSE(CheckFiniteGe("a", -kInf, 0, &f));
  EXPECT_EQ(f.Message(), "a = -inf; must be finite and >= 0");
  EXPECT_FALSE(CheckFiniteGe("a", -1, 0, &f));
  EXPECT_EQ(f.Message(), "a = -1; must be finite and >= 0");
  EXPECT_FALSE(CheckFinite("a", kInf, &f));
  EXPECT_EQ(f.Message(), "a = inf; must be finite");
}

TEST(OptionCheck, CrossFieldBoundsNameBothFieldsAndValues) {
  CheckFailure f;
  EXPECT_TRUE(CheckGt("max_period_s", 3, "min_period_s", 2, &f));
  EXPECT_FALSE(CheckGt("max_period_s", 2, "min_period_s", 2, &f));
  EXPECT_EQ(f.Message(), "max_period_s = 2; must be > min_period_s = 2");
  EXPECT_EQ(f.field, "max_period_s");
  EXPECT_EQ(f.value, 2);
  EXPECT_EQ(f.allowed, "> min_period_s = 2");
  EXPECT_FALSE(CheckGe("reject", 0.1, "max", 0.5, &f));
  EXPECT_EQ(f.Message(), "reject = 0.1; must be >= max = 0.5");
  EXPECT_FALSE(CheckLt("D", 2, "L", 1.5, &f));
  EXPECT_EQ(f.Message(), "D = 2; must be < L = 1.5");
  EXPECT_FALSE(CheckLe("min", 3, "max", 2, &f));
  EXPECT_EQ(f.Message(), "min = 3; must be <= max = 2");
}

TEST(OptionCheck, IntervalsWithEachKindOfEnd) {
  CheckFailure f;
  EXPECT_TRUE(CheckIn("a", 0, 0, 1, Ends::kClosed, &f));
  EXPECT_TRUE(CheckIn("a", 1, 0, 1, Ends::kClosed, &f));
  EXPECT_FALSE(CheckIn("a", 1.5, 0, 1, Ends::kClosed, &f));
  EXPECT_EQ(f.Message(), "a = 1.5; must be in [0, 1]");
  EXPECT_FALSE(CheckIn("a", 0, 0, 1, Ends::kOpen, &f));
  EXPECT_EQ(f.Message(), "a = 0; must be in (0, 1)");
  EXPECT_FALSE(CheckIn("a", 1, 0, 1, Ends::kOpen, &f));
  EXPECT_TRUE(CheckIn("a", 1, 0, 1, Ends::kOpenClosed, &f));
  EXPECT_FALSE(CheckIn("a", 0, 0, 1, Ends::kOpenClosed, &f));
  EXPECT_EQ(f.Message(), "a = 0; must be in (0, 1]");
  EXPECT_TRUE(CheckIn("a", 0, 0, 1, Ends::kClosedOpen, &f));
  EXPECT_FALSE(CheckIn("a", 1, 0, 1, Ends::kClosedOpen, &f));
  EXPECT_EQ(f.Message(), "a = 1; must be in [0, 1)");
  // Finite ends refuse infinities; an infinite end reads "inf".
  EXPECT_FALSE(CheckIn("a", kInf, 0, 1e9, Ends::kClosed, &f));
  EXPECT_EQ(f.Message(), "a = inf; must be in [0, 1000000000]");
  EXPECT_TRUE(CheckIn("a", kInf, 0, kInf, Ends::kClosed, &f));
  EXPECT_FALSE(CheckIn("a", kInf, 0, kInf, Ends::kClosedOpen, &f));
  EXPECT_EQ(f.Message(), "a = inf; must be in [0, inf)");
  EXPECT_EQ(IntervalText(1e-300, 1e100, Ends::kClosed), "[1e-300, 1e+100]");
}

TEST(OptionCheck, FreeFormBoundsAndTextValues) {
  CheckFailure f;
  EXPECT_FALSE(CheckFail("body_from_imu |R^T R - I|", 0.5, "<= 1e-06 (a rotation)", &f));
  EXPECT_EQ(f.Message(), "body_from_imu |R^T R - I| = 0.5; must be <= 1e-06 (a rotation)");
  EXPECT_FALSE(CheckFailText("out_dir", "", "a folder", &f));
  EXPECT_EQ(f.Message(), "out_dir = \"\"; must be a folder");
  EXPECT_TRUE(f.text);
}

}  // namespace
}  // namespace bifilar
