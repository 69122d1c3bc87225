// The probability distributions behind the fits' intervals and tests, in one place for the
// ellipse, tensor, physical-check and amplitude-sweep code: quantiles of the standard normal,
// Student's t and chi^2 distributions, and upper tails of chi^2 and F (F through the regularized
// incomplete beta). Computed by Boost.Math (double precision, about 1e-15 relative), never by a
// hand-written approximation. Every edge case has a stated answer, none a NaN from a valid
// probability and none an exception: dof <= 0, NaN or infinite gives the normal limit for t, and
// the other cases are named at each function.
#pragma once

namespace bifilar {

// z with P(Z <= z) = p for a standard normal Z. p <= 0 gives -inf, p >= 1 +inf, NaN gives NaN.
double NormalQuantile(double p);

// t with P(T <= t) = p for Student's t with `dof` degrees of freedom (dof need not be an
// integer). dof infinite, NaN or <= 0 (no scale estimated from the data) gives the normal
// quantile. p as for NormalQuantile.
double StudentQuantile(double p, double dof);

// q with P(X <= q) = p for chi^2 with `dof` degrees of freedom (dof need not be an integer).
// p <= 0 gives 0, p >= 1 +inf; dof infinite, NaN or <= 0 gives +inf (no finite statistic exceeds
// it: no test is made); NaN p gives NaN.
double ChiSquareQuantile(double p, double dof);

// P(X > x) for chi^2 with `dof` degrees of freedom. x <= 0 or NaN gives 1, x = +inf 0; dof
// infinite, NaN or <= 0 gives 1 (no evidence against the model).
double ChiSquareUpperTail(double x, double dof);

// P(F > f) for F with (d1, d2) degrees of freedom (either may be fractional). f <= 0 or NaN gives
// 1, f = +inf 0; d1 or d2 NaN or <= 0 gives 1 (no evidence); an infinite d1 or d2 is the chi^2
// limit of F (d2 infinite: chi^2_d1 / d1; both infinite: the point mass at 1).
double FUpperTail(double f, double d1, double d2);

}  // namespace bifilar
