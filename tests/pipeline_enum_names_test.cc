// Every enumeration has one name table (base/enum_names.h): its ToString, Parse, names list and
// "allowed values" text all come from that table, so each name reads back as its value, every
// value has a distinct name, and the text of messages lists exactly the names Parse accepts.
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/enum_names.h"
#include "base/units.h"
#include "fit/ellipse.h"
#include "pendulum/integrator.h"
#include "pendulum/model.h"
#include "pendulum/simulate.h"
#include "pipeline/config/config.h"
#include "pipeline/logs/imu_format.h"
#include "pipeline/records/trace_record.h"
#include "pipeline/report/export.h"

namespace bifilar {
namespace {

// The names the allowed-values text lists ("a, b or c" -> {a, b, c}).
std::vector<std::string> Listed(const std::string& allowed) {
  std::vector<std::string> names;
  std::string rest = allowed;
  const size_t last = rest.rfind(" or ");
  std::string tail;
  if (last != std::string::npos) {
    tail = rest.substr(last + 4);
    rest = rest.substr(0, last);
  }
  size_t start = 0;
  while (start <= rest.size()) {
    const size_t comma = rest.find(", ", start);
    names.push_back(rest.substr(start, comma - start));
    if (comma == std::string::npos) break;
    start = comma + 2;
  }
  if (!tail.empty()) names.push_back(tail);
  return names;
}

// Every value: ToString names it distinctly, the name parses back to it, the allowed-values text
// lists exactly those names, and a name not in the table is refused.
template <typename Enum, typename ToName, typename Parse>
void ExpectOneTable(const std::vector<Enum>& values, ToName to_name, Parse parse,
                    const std::string& allowed) {
  std::vector<std::string> names;
  for (Enum v : values) {
    const std::string name = to_name(v);
    Enum back{};
    ASSERT_TRUE(parse(name, &back)) << name;
    EXPECT_EQ(back, v) << name;
    names.push_back(name);
  }
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size());
  EXPECT_EQ(Listed(allowed), names) << allowed;
  Enum untouched = values.back();
  EXPECT_FALSE(parse("no-such-name", &untouched));
  EXPECT_FALSE(parse("", &untouched));
  EXPECT_FALSE(parse(names.front() + " ", &untouched));  // exact names only
  EXPECT_EQ(untouched, values.back());
}

TEST(EnumNames, EveryTableReadsBackAndListsWhatItParses) {
  ExpectOneTable<TimeUnit>(
      {TimeUnit::kSeconds, TimeUnit::kMilliseconds, TimeUnit::kMicroseconds},
      [](TimeUnit v) { return ToString(v); }, ParseTimeUnit, TimeUnitAllowedValues());
  ExpectOneTable<RateUnit>(
      {RateUnit::kRadPerS, RateUnit::kDegPerS, RateUnit::kMilliradPerS},
      [](RateUnit v) { return ToString(v); }, ParseRateUnit, RateUnitAllowedValues());
  ExpectOneTable<AccelUnit>(
      {AccelUnit::kMetresPerS2, AccelUnit::kStandardGravity},
      [](AccelUnit v) { return ToString(v); }, ParseAccelUnit, AccelUnitAllowedValues());
  ExpectOneTable<LogContainer>(
      {LogContainer::kAuto, LogContainer::kCsv, LogContainer::kUlog},
      [](LogContainer v) { return ToString(v); }, ParseLogContainer, LogContainerAllowedValues());
  ExpectOneTable<PitchSource>(
      {PitchSource::kNominal, PitchSource::kMeasured}, [](PitchSource v) { return ToString(v); },
      ParsePitchSource, PitchSourceAllowedValues());
  ExpectOneTable<ExportFormat>({ExportFormat::kUrdf, ExportFormat::kSdf, ExportFormat::kJsbsim,
                                ExportFormat::kCsv, ExportFormat::kMjcf, ExportFormat::kArdupilot},
                               ExportFormatName, ParseExportFormat, ExportFormatAllowedValues());
  ExpectOneTable<IntegratorMethod>(
      {IntegratorMethod::kRungeKutta, IntegratorMethod::kCvodes},
      [](IntegratorMethod v) { return ToString(v); }, ParseIntegratorMethod,
      IntegratorMethodAllowedValues());
  ExpectOneTable<PendulumModel>(
      {PendulumModel::kFull, PendulumModel::kJardin, PendulumModel::kLinear},
      [](PendulumModel v) { return ToString(v); }, ParsePendulumModel,
      PendulumModelAllowedValues());
  ExpectOneTable<DisplayUnits>(
      {DisplayUnits::kSi, DisplayUnits::kImperial}, [](DisplayUnits v) { return ToString(v); },
      ParseDisplayUnits, DisplayUnitsAllowedValues());
  ExpectOneTable<EllipseCovariance>({EllipseCovariance::kAuto, EllipseCovariance::kPointResiduals,
                                     EllipseCovariance::kAngleMeans, EllipseCovariance::kAbsolute},
                                    EllipseCovarianceName, ParseEllipseCovariance,
                                    EllipseCovarianceAllowedValues());
  ExpectOneTable<TraceStatus>(
      {TraceStatus::kOk, TraceStatus::kRejected, TraceStatus::kError},
      [](TraceStatus v) { return ToString(v); }, ParseTraceStatus, TraceStatusAllowedValues());
  ExpectOneTable<SampleSteps>(
      {SampleSteps::kRegular, SampleSteps::kLogNormal}, [](SampleSteps v) { return ToString(v); },
      ParseSampleSteps, SampleStepsAllowedValues());
  ExpectOneTable<TraceRole>(
      {TraceRole::kAircraft, TraceRole::kTare, TraceRole::kCalibration},
      [](TraceRole v) { return ToString(v); }, ParseTraceRole, TraceRoleAllowedValues());
}

TEST(EnumNames, ExportFrameTable) {
  ExportFrame frame = ExportFrame::kFlu;
  ASSERT_TRUE(ParseExportFrame("frd", &frame));
  EXPECT_EQ(frame, ExportFrame::kFrd);
  EXPECT_FALSE(ParseExportFrame("FRD", &frame));
  EXPECT_EQ(ExportFrameAllowedValues(), "flu or frd");
}

// The template itself: a table with a row type of its own (extra columns), an unknown value.
enum class Fruit { kApple, kPear, kPlum };
struct FruitRow {
  Fruit value;
  const char* name;
  int calories;
};
constexpr FruitRow kFruits[] = {{Fruit::kApple, "apple", 52}, {Fruit::kPear, "pear", 57}};

TEST(EnumNames, TemplateOnARowTypeOfItsOwn) {
  EXPECT_STREQ(EnumToString(kFruits, Fruit::kPear), "pear");
  EXPECT_STREQ(EnumToString(kFruits, Fruit::kPlum), "unknown");
  EXPECT_STREQ(EnumToString(kFruits, Fruit::kPlum, "?"), "?");
  Fruit f = Fruit::kPlum;
  EXPECT_TRUE(ParseEnum(kFruits, "apple", &f));
  EXPECT_EQ(f, Fruit::kApple);
  EXPECT_EQ(EnumNames(kFruits), (std::vector<std::string>{"apple", "pear"}));
  EXPECT_EQ(EnumAllowedValues(kFruits), "apple or pear");
  EXPECT_EQ(JoinAllowedValues({"a"}), "a");
  EXPECT_EQ(JoinAllowedValues({"a", "b", "c"}), "a, b or c");
}

}  // namespace
}  // namespace bifilar
