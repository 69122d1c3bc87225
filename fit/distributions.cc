// The distributions of fit/distributions.h on Boost.Math. The inputs Boost would refuse (a
// probability outside (0, 1), degrees of freedom that are not positive and finite) are answered
// here before Boost sees them; the policy below turns what is left of Boost's errors (an overflow
// at the far tail, a series that did not converge) into its best value instead of an exception,
// so no fit can stop on one.
#include "fit/distributions.h"

#include <cmath>
#include <limits>

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/complement.hpp>
#include <boost/math/distributions/fisher_f.hpp>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <boost/math/policies/policy.hpp>

namespace bifilar {
namespace {

namespace bm = boost::math;
namespace bmp = boost::math::policies;
// Overflow gives +-inf; domain and evaluation errors give Boost's value (NaN or its best
// estimate) instead of throwing. The inputs are checked first, so a domain error cannot occur.
using NoThrowPolicy =
    bmp::policy<bmp::domain_error<bmp::ignore_error>, bmp::overflow_error<bmp::ignore_error>,
                bmp::evaluation_error<bmp::ignore_error>>;

constexpr double kDistInf = std::numeric_limits<double>::infinity();
constexpr double kDistNaN = std::numeric_limits<double>::quiet_NaN();

// True for degrees of freedom that make a distribution: positive and finite (NaN fails both).
bool ProperDof(double dof) { return dof > 0.0 && std::isfinite(dof); }

}  // namespace

double NormalQuantile(double p) {
  if (std::isnan(p)) return kDistNaN;
  if (p <= 0.0) return -kDistInf;
  if (p >= 1.0) return kDistInf;
  return bm::quantile(bm::normal_distribution<double, NoThrowPolicy>(0.0, 1.0), p);
}

double StudentQuantile(double p, double dof) {
  if (!ProperDof(dof)) return NormalQuantile(p);
  if (std::isnan(p)) return kDistNaN;
  if (p <= 0.0) return -kDistInf;
  if (p >= 1.0) return kDistInf;
  return bm::quantile(bm::students_t_distribution<double, NoThrowPolicy>(dof), p);
}

double ChiSquareQuantile(double p, double dof) {
  if (std::isnan(p)) return kDistNaN;
  if (!ProperDof(dof) || p >= 1.0) return kDistInf;
  if (p <= 0.0) return 0.0;
  return bm::quantile(bm::chi_squared_distribution<double, NoThrowPolicy>(dof), p);
}

double ChiSquareUpperTail(double x, double dof) {
  if (!ProperDof(dof) || !(x > 0.0)) return 1.0;
  if (std::isinf(x)) return 0.0;
  return bm::cdf(bm::complement(bm::chi_squared_distribution<double, NoThrowPolicy>(dof), x));
}

double FUpperTail(double f, double d1, double d2) {
  if (!(d1 > 0.0) || !(d2 > 0.0) || !(f > 0.0)) return 1.0;
  if (std::isinf(f)) return 0.0;
  if (std::isinf(d1) && std::isinf(d2)) return f < 1.0 ? 1.0 : 0.0;  // F = 1
  if (std::isinf(d2)) return ChiSquareUpperTail(d1 * f, d1);         // F = chi^2_d1 / d1
  if (std::isinf(d1)) {                                              // F = d2 / chi^2_d2
    return bm::cdf(bm::chi_squared_distribution<double, NoThrowPolicy>(d2), d2 / f);
  }
  return bm::cdf(bm::complement(bm::fisher_f_distribution<double, NoThrowPolicy>(d1, d2), f));
}

}  // namespace bifilar
