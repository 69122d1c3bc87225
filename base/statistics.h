// Small statistics of a sample, one definition each: the median (two kinds), mean and sample
// standard deviation.
#pragma once

#include <vector>

namespace bifilar {

// The median of `v`, reordering it: the mean of the two middle values when the count is even;
// 0 when `v` is empty.
double MedianInPlace(std::vector<double>* v);
// The same of a copy.
double Median(std::vector<double> v);

// The upper of the two middle values (the middle one for an odd count): always a value of `v`,
// for a count of steps or a typical spacing; `if_empty` when `v` is empty.
double UpperMedian(std::vector<double> v, double if_empty);

// The mean of `v`; NaN when empty.
double Mean(const std::vector<double>& v);
// The sample standard deviation of `v` (n - 1 in the denominator); NaN for fewer than 2 values.
double SampleStd(const std::vector<double>& v);

}  // namespace bifilar
