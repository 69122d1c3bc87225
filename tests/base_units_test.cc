// base/units.h: the one definition of each unit fact. The constants are the very doubles the
// sites they replaced computed (bit for bit, so no result moves), and the display-units table
// gives ToString, Parse and the allowed-values text from one place.
#include "base/units.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

namespace bifilar {
namespace {

TEST(Units, ConstantsAreTheDoublesTheyReplaced) {
  EXPECT_EQ(kPi, M_PI);
  EXPECT_EQ(kDegPerRad, 180.0 / M_PI);
  EXPECT_EQ(kDegPerRad, 57.29577951308232);  // the literal log_inspect.cc had
  EXPECT_EQ(kRadPerDeg, M_PI / 180.0);
  EXPECT_EQ(kStandardGravityMps2, 9.80665);
  EXPECT_EQ(kKgM2PerSlugFt2, 1.35581795);
  EXPECT_EQ(kSlugFt2PerKgM2, 1.0 / 1.35581795);
}

TEST(Units, DisplayUnitsTableGivesNamesParseAndAllowedValues) {
  EXPECT_STREQ(ToString(DisplayUnits::kSi), "si");
  EXPECT_STREQ(ToString(DisplayUnits::kImperial), "imperial");
  for (DisplayUnits u : {DisplayUnits::kSi, DisplayUnits::kImperial}) {
    DisplayUnits parsed = u == DisplayUnits::kSi ? DisplayUnits::kImperial : DisplayUnits::kSi;
    ASSERT_TRUE(ParseDisplayUnits(ToString(u), &parsed));
    EXPECT_EQ(parsed, u);
  }
  DisplayUnits unchanged = DisplayUnits::kImperial;
  EXPECT_FALSE(ParseDisplayUnits("metric", &unchanged));
  EXPECT_FALSE(ParseDisplayUnits("SI", &unchanged));
  EXPECT_EQ(unchanged, DisplayUnits::kImperial);
  EXPECT_EQ(DisplayUnitsAllowedValues(), "si or imperial");
  EXPECT_STREQ(InertiaUnitName(DisplayUnits::kSi), "kg m^2");
  EXPECT_STREQ(InertiaUnitName(DisplayUnits::kImperial), "slug ft^2");
}

TEST(Units, InertiaToDisplayAndToSiAreInverse) {
  EXPECT_EQ(InertiaToDisplay(2.5, DisplayUnits::kSi), 2.5);
  EXPECT_EQ(InertiaToSi(DisplayUnits::kSi), 1.0);
  EXPECT_EQ(InertiaToDisplay(1.35581795, DisplayUnits::kImperial), 1.35581795 * (1.0 / 1.35581795));
  EXPECT_NEAR(InertiaToDisplay(3.0 * InertiaToSi(DisplayUnits::kImperial), DisplayUnits::kImperial),
              3.0, 1e-15);
}

TEST(Units, SiTextInDisplayUnitsConvertsOnlyNumbersInKgM2) {
  const std::string text = "I = 1.35581795 kg m^2, drift 0.5 deg, kg m^2 alone";
  EXPECT_EQ(SiTextInDisplayUnits(text, DisplayUnits::kSi), text);
  EXPECT_EQ(SiTextInDisplayUnits(text, DisplayUnits::kImperial),
            "I = 1 slug ft^2, drift 0.5 deg, kg m^2 alone");
}

}  // namespace
}  // namespace bifilar
