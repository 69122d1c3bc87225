// base/statistics.h and base/text_format.h: the small helpers that several files wrote out each
// for themselves (and that kept those files out of the unity build) give the answers the copies
// gave: the median of the window search and the glitch filter (the mean of the two middle
// values), the upper median of the period guess and inspect (a value of the sample), the mean and
// sample std of the campaign and the calibration, the log readers' echo of a file's text, and
// printf with up to four numbers.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/statistics.h"
#include "base/text_format.h"

namespace bifilar {
namespace {

TEST(Statistics, MedianAveragesTheTwoMiddleValuesOfAnEvenCount) {
  EXPECT_EQ(Median({5.0, 1.0, 3.0}), 3.0);
  EXPECT_EQ(Median({4.0, 1.0, 3.0, 2.0}), 2.5);
  EXPECT_EQ(Median({}), 0.0);
  std::vector<double> v = {9.0, 7.0, 8.0, 6.0};
  EXPECT_EQ(MedianInPlace(&v), 7.5);
  EXPECT_EQ(v.size(), 4u);  // reordered, nothing lost
}

TEST(Statistics, UpperMedianIsAValueOfTheSample) {
  EXPECT_EQ(UpperMedian({5.0, 1.0, 3.0}, 0.0), 3.0);
  EXPECT_EQ(UpperMedian({4.0, 1.0, 3.0, 2.0}, 0.0), 3.0);  // the upper of 2 and 3
  EXPECT_EQ(UpperMedian({}, 0.0), 0.0);
  EXPECT_TRUE(std::isnan(UpperMedian({}, NAN)));
}

TEST(Statistics, MeanAndSampleStd) {
  EXPECT_EQ(Mean({1.0, 2.0, 6.0}), 3.0);
  EXPECT_TRUE(std::isnan(Mean({})));
  // (1-3)^2 + (2-3)^2 + (6-3)^2 = 14 over n - 1 = 2.
  EXPECT_DOUBLE_EQ(SampleStd({1.0, 2.0, 6.0}), std::sqrt(7.0));
  EXPECT_TRUE(std::isnan(SampleStd({4.0})));
}

TEST(TextFormat, FmtTakesOneToFourNumbersAndNeverCuts) {
  EXPECT_EQ(Fmt("%g", 0.5), "0.5");
  EXPECT_EQ(Fmt("[%g, %g]", 1.0, 2.0), "[1, 2]");
  EXPECT_EQ(Fmt("%.1f %.1f %.1f", 1.0, 2.0, 3.0), "1.0 2.0 3.0");
  EXPECT_EQ(Fmt("%g%g%g%g", 1.0, 2.0, 3.0, 4.0), "1234");
  // 200 digits, '.', 3 decimals: longer than any buffer the copies had, printed whole.
  const std::string huge = Fmt("%.3f", 1e200);
  EXPECT_EQ(huge.size(), 204u);
  EXPECT_EQ(huge.substr(huge.size() - 4), ".000");
  EXPECT_EQ(Fmt("%g %.3f", 1.0, 1e200), "1 " + huge);
}

TEST(TextFormat, RoundedToDigitsDropsRoundingNoise) {
  EXPECT_EQ(RoundedToDigits(-3.9999999999999996, 6), -4.0);
  EXPECT_EQ(RoundedToDigits(120.00000000000001, 12), 120.0);
  EXPECT_EQ(RoundedToDigits(1.23456789, 3), 1.23);
  EXPECT_TRUE(std::isnan(RoundedToDigits(NAN, 6)));
  EXPECT_EQ(RoundedToDigits(-INFINITY, 6), -INFINITY);
}

TEST(TextFormat, PrintableAsciiEchoesAFilesTextSafely) {
  EXPECT_EQ(PrintableAscii("IMU", 64), "IMU");
  EXPECT_EQ(PrintableAscii(std::string("a\tb\x01\xc3\xa9", 6), 64), "a?b???");
  EXPECT_EQ(PrintableAscii("abcdef", 4), "abcd...");
  EXPECT_EQ(PrintableAscii("abcd", 4), "abcd");
}

}  // namespace
}  // namespace bifilar
