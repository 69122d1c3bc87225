// D-optimal choice of attitudes for a tensor campaign (fit/tensor_plan.h).
#include "fit/tensor_plan.h"

#include "base/option_check.h"
#include "base/text_format.h"
#include "base/units.h"
#include "fit/tensor.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <tuple>

namespace bifilar {
namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kMaxMomentKgM2 = 1e100;  // bound of any moment or std (kg m^2)

using Row = std::array<double, kTensorComponents>;

// One reachable attitude: its axis, its design row and its weight.
struct Candidate {
  double roll_deg = 0.0;
  double pitch_deg = 0.0;
  std::array<double, 3> n = {0, 0, 1};
  Row row = {};
  double inertia_kg_m2 = kNaN;  // guessed moment about n
  double swing_var = 0.0;       // per-swing variance (absolute and relative parts)
  double tilt_var = 0.0;        // variance of the moment from the attitude error
};

// lo, lo + step, ... and hi itself; {lo} when the range has no width.
std::vector<double> GridValues(double lo, double hi, double step) {
  std::vector<double> v;
  for (int i = 0; lo + i * step < hi - 1e-9 * step; ++i) v.push_back(lo + i * step);
  v.push_back(hi);
  return v;
}

Eigen::Matrix3d TensorMatrix(const Row& c) {
  Eigen::Matrix3d j;
  j << c[0], -c[3], -c[4], -c[3], c[1], -c[5], -c[4], -c[5], c[2];
  return j;
}

// n and -n are one swing axis: a key equal for both, to 1e-9.
std::tuple<long long, long long, long long> AxisKey(const std::array<double, 3>& n) {
  double s = 1.0;
  for (double c : n) {
    if (std::fabs(c) > 1e-12) {
      s = c > 0 ? 1.0 : -1.0;
      break;
    }
  }
  return {std::llround(s * n[0] * 1e9), std::llround(s * n[1] * 1e9), std::llround(s * n[2] * 1e9)};
}

// The orientation means' weights 1 / (swing_var / trials + tilt_var), as a vector.
Eigen::VectorXd Weights(const std::vector<Candidate>& c, const std::vector<int>& chosen,
                        double trials) {
  Eigen::VectorXd w(chosen.size());
  for (size_t i = 0; i < chosen.size(); ++i) {
    const Candidate& k = c[chosen[i]];
    w[i] = 1.0 / (k.swing_var / trials + k.tilt_var);
  }
  return w;
}

// Covariance (6 x 6, NaN rows/columns for unobservable components) of the chosen design with
// weights w, on the observable subspace spanned by the columns of basis.
Eigen::MatrixXd Covariance6(const Eigen::MatrixXd& reduced_rows, const std::vector<int>& chosen,
                            const Eigen::VectorXd& w, const Eigen::MatrixXd& basis,
                            const std::array<bool, kTensorComponents>& observable,
                            double* log_det) {
  const int r = static_cast<int>(basis.cols());
  Eigen::MatrixXd info = Eigen::MatrixXd::Zero(r, r);
  for (size_t i = 0; i < chosen.size(); ++i) {
    const Eigen::VectorXd b = reduced_rows.row(chosen[i]).transpose();
    info += w[i] * b * b.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(info);
  if (log_det != nullptr) {
    *log_det = 0.0;
    for (int k = 0; k < r; ++k) *log_det += std::log(eig.eigenvalues()[k]);
  }
  const Eigen::MatrixXd inv = eig.eigenvectors() * eig.eigenvalues().cwiseInverse().asDiagonal() *
                              eig.eigenvectors().transpose();
  Eigen::MatrixXd cov = basis * inv * basis.transpose();
  for (int k = 0; k < kTensorComponents; ++k) {
    if (observable[k]) continue;
    cov.row(k).setConstant(kNaN);
    cov.col(k).setConstant(kNaN);
  }
  return cov;
}

}  // namespace

Row TensorDesignRow(const std::array<double, 3>& axis) {
  // Scaled by the largest component first: no square of a huge or tiny component overflows.
  const double big = std::max({std::fabs(axis[0]), std::fabs(axis[1]), std::fabs(axis[2])});
  const double a = axis[0] / big, b = axis[1] / big, c = axis[2] / big;
  const double len = std::sqrt(a * a + b * b + c * c);
  const double x = a / len, y = b / len, z = c / len;
  return {x * x, y * y, z * z, -2 * x * y, -2 * x * z, -2 * y * z};
}

bool TensorPlanOptions::Check(std::string* why) const {
  CheckFailure f;
  return Check(&f) || FailWith(f, why);
}

bool TensorPlanOptions::Check(CheckFailure* failure) const {
  CheckFailure& f = *failure;
  // 1e100 kg m^2 bounds every moment and std, as the tensor fit's inputs: their squares (the
  // covariance) stay finite. Small stds need no bound: the plan works in units of the largest.
  constexpr double kMax = kMaxMomentKgM2;
  bool ok =
      CheckIn("roll_min_deg", roll_min_deg, -180, 180, Ends::kClosed, &f) &&
      CheckIn("roll_max_deg", roll_max_deg, -180, 180, Ends::kClosed, &f) &&
      CheckLe("roll_min_deg", roll_min_deg, "roll_max_deg", roll_max_deg, &f) &&
      CheckIn("pitch_min_deg", pitch_min_deg, -90, 90, Ends::kClosed, &f) &&
      CheckIn("pitch_max_deg", pitch_max_deg, -90, 90, Ends::kClosed, &f) &&
      CheckLe("pitch_min_deg", pitch_min_deg, "pitch_max_deg", pitch_max_deg, &f) &&
      CheckIn("grid_step_deg", grid_step_deg, 0.5, 90, Ends::kClosed, &f) &&
      CheckIn("n_orientations", n_orientations, 1, 100, Ends::kClosed, &f) &&
      CheckIn("trials_per_orientation", trials_per_orientation, 1, 1000000, Ends::kClosed, &f) &&
      CheckIn("sigma_kg_m2", sigma_kg_m2, 0, kMax, Ends::kClosed, &f) &&
      CheckIn("sigma_relative", sigma_relative, 0, 1, Ends::kClosedOpen, &f) &&
      (sigma_kg_m2 != 0 || sigma_relative != 0 ||
       CheckFail("sigma_kg_m2", sigma_kg_m2,
                 "> 0 when sigma_relative = 0 (a per-swing std, absolute or relative)", &f)) &&
      CheckIn("attitude_std_deg", attitude_std_deg, 0, 10, Ends::kClosed, &f) &&
      ((sigma_relative == 0 && attitude_std_deg == 0) || guess_given ||
       CheckFailText("guess_kg_m2", "not given",
                     "given (at least Ixx, Iyy, Izz) with a relative swing std or an attitude "
                     "error",
                     &f));
  static const char* const kGuessNames[kTensorComponents] = {"guess_kg_m2 Ixx", "guess_kg_m2 Iyy",
                                                             "guess_kg_m2 Izz", "guess_kg_m2 Ixy",
                                                             "guess_kg_m2 Ixz", "guess_kg_m2 Iyz"};
  for (int k = 0; ok && k < kTensorComponents; ++k) {
    ok = CheckIn(kGuessNames[k], guess_kg_m2[k], -kMax, kMax, Ends::kClosed, &f);
  }
  ok = ok &&
       (target_std_kg_m2 == 0 ||
        CheckIn("target_std_kg_m2 (0: none)", target_std_kg_m2, 0, kMax, Ends::kOpenClosed, &f)) &&
       CheckIn("rank_tolerance", rank_tolerance, 0, 1, Ends::kOpen, &f);
  if (ok && guess_given) {
    // The guessed tensor is positive definite.
    const Eigen::Vector3d eig =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(TensorMatrix(guess_kg_m2)).eigenvalues();
    // Shown to 6 digits: a derived value, its last digits are rounding.
    ok = eig[0] > 0 ||
         CheckFail("smallest principal moment of guess_kg_m2", RoundedToDigits(eig[0], 6),
                   "> 0 (check the products' signs and sizes)", &f);
  }
  return ok;
}

namespace {

// The stds of a candidate (kg m^2): absolute, relative and from the attitude error.
struct Stds {
  double absolute = 0.0, relative = 0.0, tilt = 0.0;
};

// The reachable axes and what the design can see of the tensor.
struct Subspace {
  Eigen::MatrixXd a;        // candidates' design rows (n_cand x 6)
  Eigen::MatrixXd basis;    // row space of a (6 x rank)
  Eigen::MatrixXd reduced;  // candidates' rows in row-space coordinates (n_cand x rank)
  int rank = 0;
};

// 1. Candidates: the grid, one per distinct axis, the easiest attitude (smallest |roll| +
// |pitch|) kept for each, with their stds.
std::vector<Candidate> CandidateAttitudes(const TensorPlanOptions& options,
                                          const Eigen::Matrix3d& j_guess, std::vector<Stds>* stds) {
  std::vector<Candidate> all;
  for (double roll :
       GridValues(options.roll_min_deg, options.roll_max_deg, options.grid_step_deg)) {
    for (double pitch :
         GridValues(options.pitch_min_deg, options.pitch_max_deg, options.grid_step_deg)) {
      Candidate c;
      c.roll_deg = roll;
      c.pitch_deg = pitch;
      c.n = DownInBodyFromAttitude(roll, pitch);
      all.push_back(c);
    }
  }
  std::stable_sort(all.begin(), all.end(), [](const Candidate& a, const Candidate& b) {
    const double ea = std::fabs(a.roll_deg) + std::fabs(a.pitch_deg);
    const double eb = std::fabs(b.roll_deg) + std::fabs(b.pitch_deg);
    if (ea != eb) return ea < eb;
    return std::fabs(a.roll_deg) < std::fabs(b.roll_deg);
  });
  std::vector<Candidate> cand;
  std::map<std::tuple<long long, long long, long long>, int> seen;
  const double tilt_std_rad = options.attitude_std_deg * kRadPerDeg;
  for (Candidate& c : all) {
    if (!seen.emplace(AxisKey(c.n), static_cast<int>(cand.size())).second) continue;
    c.row = TensorDesignRow(c.n);
    Stds s;
    s.absolute = options.sigma_kg_m2;
    if (options.guess_given) {
      const Eigen::Vector3d n(c.n[0], c.n[1], c.n[2]);
      const Eigen::Vector3d jn = j_guess * n;
      c.inertia_kg_m2 = n.dot(jn);
      s.relative = options.sigma_relative * c.inertia_kg_m2;
      // dI/d(tilt) = 2 (1 - n n^T) J n: the moment's rate of change per radian of tilt; an
      // isotropic tilt error of std s per axis moves I by s |that| (first order).
      s.tilt = tilt_std_rad * 2.0 * (jn - n * n.dot(jn)).stableNorm();
    }
    stds->push_back(s);
    cand.push_back(c);
  }
  return cand;
}

// Every variance is held in units of scale^2, scale the largest std of any candidate: the
// choice (D-optimal is blind to one factor on every weight) and the stds (which scale with it)
// come out the same for a sigma of 1e-160 or 1e200 kg m^2, whose squares would underflow to
// 0 (infinite weights) or overflow to inf (zero weights). Stds are scaled back at the end.
bool ScaledVariances(const TensorPlanOptions& options, const std::vector<Stds>& stds,
                     std::vector<Candidate>* cand, double* scale_out, std::string* error) {
  double scale = 0.0;
  for (const Stds& s : stds) scale = std::max({scale, s.absolute, s.relative, s.tilt});
  *scale_out = scale;
  // Below 1e-300 kg m^2 the stds themselves (about the per-swing std) would be subnormal or 0.
  if (!(scale >= 1e-300) || !std::isfinite(scale)) {
    *error = "the per-swing std (absolute " + Fmt("%g", options.sigma_kg_m2) +
             " kg m^2, relative " + Fmt("%g", options.sigma_relative) +
             ") gives no std of a moment in [1e-300, 1e100] "
             "kg m^2 (largest " +
             Fmt("%g", scale) + "): too small to compute with";
    return false;
  }
  for (size_t i = 0; i < cand->size(); ++i) {
    Candidate& c = (*cand)[i];
    const Stds& s = stds[i];
    c.swing_var = std::pow(s.absolute / scale, 2) + std::pow(s.relative / scale, 2);
    c.tilt_var = std::pow(s.tilt / scale, 2);
    // The smallest variance used is that of the floor, at 1e12 trials: it must stay a normal
    // number, so every weight is finite. Only a relative std at an axis whose moment is 139
    // decades below the largest std, and no attitude error there, fails this.
    if (!(c.swing_var / 1e12 + c.tilt_var >= 1e-290)) {
      *error = "the per-swing std at roll " + Fmt("%g", c.roll_deg) + " deg, pitch " +
               Fmt("%g", c.pitch_deg) + " deg is below 1e-139 of the largest (" + Fmt("%g", scale) +
               " kg m^2): give an absolute --sigma too, or check the guessed tensor";
      return false;
    }
  }
  return true;
}

// 2. What the reachable axes can observe: the row space of their design.
bool ObservableSubspace(const std::vector<Candidate>& cand, const TensorPlanOptions& options,
                        TensorPlan* plan, Subspace* space, std::string* error) {
  const int n_cand = static_cast<int>(cand.size());
  Eigen::MatrixXd& a = space->a;
  a.resize(n_cand, kTensorComponents);
  for (int i = 0; i < n_cand; ++i) {
    for (int k = 0; k < kTensorComponents; ++k) a(i, k) = cand[i].row[k];
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeThinV);
  const Eigen::VectorXd sv = svd.singularValues();
  int rank = 0;
  while (rank < sv.size() && sv[rank] > options.rank_tolerance * sv[0]) ++rank;
  plan->rank = rank;
  space->rank = rank;
  space->basis = svd.matrixV().leftCols(rank);  // 6 x r
  int n_observable = 0;
  for (int k = 0; k < kTensorComponents; ++k) {
    // e_k lies in the row space when its projection keeps its length.
    const double in_space = space->basis.row(k).squaredNorm();
    plan->observable[k] = 1.0 - in_space < 1e-12;
    if (plan->observable[k]) {
      ++n_observable;
    } else {
      plan->unobservable.push_back(TensorComponentName(k));
    }
  }
  plan->n_combinations = rank - n_observable;
  space->reduced = a * space->basis;
  if (!plan->unobservable.empty()) {
    std::string names;
    for (const std::string& u : plan->unobservable) names += (names.empty() ? "" : ", ") + u;
    plan->warnings.push_back(
        "the reachable attitudes (roll " + Fmt("%g", options.roll_min_deg) + ".." +
        Fmt("%g", options.roll_max_deg) + " deg, pitch " + Fmt("%g", options.pitch_min_deg) + ".." +
        Fmt("%g", options.pitch_max_deg) + " deg) cannot observe " + names +
        ": no reachable swing axis separates them from the rest; widen the roll or pitch range "
        "(a rig that holds roll at 0 keeps every axis in the body x-z plane: Iyy, Ixy, Iyz)");
  }
  if (n_observable == 0) {
    *error =
        "the reachable attitudes determine no single component, only combinations of them; "
        "widen the roll or pitch range";
    return false;
  }
  return true;
}

// The number of orientations to plan: at most the distinct axes, at least the rank.
bool OrientationCount(int n_cand, int rank, const TensorPlanOptions& options, TensorPlan* plan,
                      int* n_out, std::string* error) {
  int n = options.n_orientations;
  if (n > n_cand) {
    plan->warnings.push_back("the grid holds only " + std::to_string(n_cand) +
                             " distinct swing axes, so " + std::to_string(n_cand) +
                             " orientations are planned instead of " + std::to_string(n));
    n = n_cand;
  }
  *n_out = n;
  if (n < rank) {
    *error = std::to_string(n) + " orientation(s) cannot determine the " + std::to_string(rank) +
             " components (or combinations) the rig can observe; plan "
             "at least " +
             std::to_string(rank);
    return false;
  }
  return true;
}

// The candidate not in the design with the largest variance function d(c) = w_c b_c^T M^-1 b_c
// (adding c multiplies det M by 1 + d(c)), or -1.
int BestAddition(const Eigen::MatrixXd& m, const Eigen::MatrixXd& reduced,
                 const Eigen::VectorXd& w_all, const std::vector<char>& in_design, int rank,
                 double* best_d) {
  const int n_cand = static_cast<int>(in_design.size());
  const Eigen::MatrixXd m_inv = m.ldlt().solve(Eigen::MatrixXd::Identity(rank, rank));
  int best = -1;
  *best_d = -1.0;
  for (int c = 0; c < n_cand; ++c) {
    if (in_design[c]) continue;
    const Eigen::VectorXd b = reduced.row(c).transpose();
    const double d = w_all[c] * b.dot(m_inv * b);
    if (d > *best_d * (1 + 1e-12) + 1e-300) {
      *best_d = d;
      best = c;
    }
  }
  return best;
}

// Fedorov exchange: swap a chosen orientation for a candidate while det M grows. Removing j
// leaves M_j; det(M_j + w_c b_c b_c^T) / det(M) = (1 + d_j(c)) / (1 + d_j(j)).
void FedorovExchange(const Eigen::MatrixXd& reduced, const Eigen::VectorXd& w_all, int rank,
                     Eigen::MatrixXd* info, std::vector<int>* chosen, std::vector<char>* in_design,
                     TensorPlan* plan) {
  const int n = static_cast<int>(chosen->size());
  for (int sweep = 0; sweep < 100; ++sweep) {
    bool improved = false;
    for (int p = 0; p < n; ++p) {
      const int j = (*chosen)[p];
      const Eigen::VectorXd bj = reduced.row(j).transpose();
      const Eigen::MatrixXd m_j = *info - w_all[j] * bj * bj.transpose();
      (*in_design)[j] = 0;
      double d_best = 0.0;
      const int c = BestAddition(m_j, reduced, w_all, *in_design, rank, &d_best);
      const Eigen::MatrixXd m_j_inv = m_j.ldlt().solve(Eigen::MatrixXd::Identity(rank, rank));
      const double d_j = w_all[j] * bj.dot(m_j_inv * bj);
      if (c >= 0 && c != j && (1 + d_best) > (1 + d_j) * (1 + 1e-9)) {
        (*chosen)[p] = c;
        (*in_design)[c] = 1;
        const Eigen::VectorXd bc = reduced.row(c).transpose();
        *info = m_j + w_all[c] * bc * bc.transpose();
        improved = true;
      } else {
        (*in_design)[j] = 1;
      }
    }
    plan->exchange_sweeps = sweep + 1;
    if (!improved) break;
  }
}

// 3. D-optimal choice of n orientations: greedy, then Fedorov exchange. Weights of the
// orientation means at the planned trials (in 1/scale^2, so between 1 / (1 + 2 / trials) and
// 1e290: finite).
bool ChooseDOptimal(const std::vector<Candidate>& cand, const Subspace& space, double trials, int n,
                    TensorPlan* plan, std::vector<int>* chosen, std::string* error) {
  const int n_cand = static_cast<int>(cand.size());
  const int rank = space.rank;
  const Eigen::MatrixXd& reduced = space.reduced;
  Eigen::VectorXd w_all(n_cand);
  for (int i = 0; i < n_cand; ++i) w_all[i] = 1.0 / (cand[i].swing_var / trials + cand[i].tilt_var);
  double largest = 0.0;
  for (int i = 0; i < n_cand; ++i) {
    largest = std::max(largest, w_all[i] * reduced.row(i).squaredNorm());
  }
  // A ridge of 1e-10 of the largest single contribution keeps the information matrix invertible
  // while fewer than `rank` orientations are chosen; it only breaks ties among them.
  const Eigen::MatrixXd ridge = 1e-10 * largest * Eigen::MatrixXd::Identity(rank, rank);
  std::vector<char> in_design(n_cand, 0);
  Eigen::MatrixXd info = ridge;
  for (int k = 0; k < n; ++k) {
    double d = 0.0;
    const int c = BestAddition(info, reduced, w_all, in_design, rank, &d);
    if (c < 0) {  // every weight is finite and positive (above), so a candidate always adds
      *error = "internal: no orientation adds information to the plan (variance function " +
               Fmt("%g", d) + "); please report this with the command line";
      return false;
    }
    chosen->push_back(c);
    in_design[c] = 1;
    const Eigen::VectorXd b = reduced.row(c).transpose();
    info += w_all[c] * b * b.transpose();
  }
  FedorovExchange(reduced, w_all, rank, &info, chosen, &in_design, plan);
  return true;
}

// The chosen design's std of component k at t trials per orientation (kg m^2).
double StdAt(const std::vector<Candidate>& cand, const std::vector<int>& chosen,
             const Subspace& space, const TensorPlan& plan, double scale, double t, int k) {
  const Eigen::MatrixXd c = Covariance6(space.reduced, chosen, Weights(cand, chosen, t),
                                        space.basis, plan.observable, nullptr);
  return scale * std::sqrt(c(k, k));
}

// 4. The chosen design's covariance, condition and floor (the attitude error alone).
bool DesignCovariance(const std::vector<Candidate>& cand, const std::vector<int>& chosen,
                      const Subspace& space, const TensorPlanOptions& options, double scale,
                      TensorPlan* plan, std::string* error) {
  const int n = static_cast<int>(chosen.size());
  const int rank = space.rank;
  Eigen::MatrixXd chosen_rows(n, kTensorComponents);
  for (int i = 0; i < n; ++i) chosen_rows.row(i) = space.a.row(chosen[i]);
  const Eigen::VectorXd chosen_sv = Eigen::JacobiSVD<Eigen::MatrixXd>(chosen_rows).singularValues();
  if (!(chosen_sv[rank - 1] > options.rank_tolerance * chosen_sv[0])) {
    *error = "internal: the chosen orientations do not span what the rig can observe";
    return false;
  }
  plan->condition_number = chosen_sv[0] / chosen_sv[rank - 1];
  const double trials = options.trials_per_orientation;
  const Eigen::VectorXd w = Weights(cand, chosen, trials);
  const Eigen::MatrixXd cov = Covariance6(space.reduced, chosen, w, space.basis, plan->observable,
                                          &plan->log_det_information);
  // Back from units of scale^2: the information matrix is 1/scale^2 of the one computed.
  plan->log_det_information -= 2.0 * rank * std::log(scale);
  for (int k = 0; k < kTensorComponents; ++k) {
    plan->std_kg_m2[k] = plan->observable[k] ? scale * std::sqrt(cov(k, k)) : kNaN;
    for (int l = 0; l < kTensorComponents; ++l) {
      plan->covariance[k][l] = cov(k, l) * scale * scale;
    }
  }
  for (int k = 0; k < kTensorComponents; ++k) {
    // The floor: the attitude error alone, as the trials grow without bound (1e12 stands for
    // infinity; an axis along a principal axis of the guess does not feel a tilt at first order
    // and keeps a finite weight there).
    plan->floor_std_kg_m2[k] = !plan->observable[k] ? kNaN
                               : options.attitude_std_deg > 0
                                   ? StdAt(cand, chosen, space, *plan, scale, 1e12, k)
                                   : 0.0;
  }
  return true;
}

// Trials per orientation each observable component needs to reach the target std (-1: never).
void TrialsNeeded(const std::vector<Candidate>& cand, const std::vector<int>& chosen,
                  const Subspace& space, double target, double scale, TensorPlan* plan) {
  const auto std_at = [&](double t, int k) {
    return StdAt(cand, chosen, space, *plan, scale, t, k);
  };
  plan->trials_needed_all = 1;
  for (int k = 0; k < kTensorComponents; ++k) {
    if (!plan->observable[k]) continue;
    constexpr int kMaxTrials = 1000000;
    int needed = -1;
    if (plan->floor_std_kg_m2[k] < target && std_at(kMaxTrials, k) <= target) {
      int lo = 1, hi = kMaxTrials;  // std_at decreases with t: the smallest t reaching target
      while (lo < hi) {
        const int mid = lo + (hi - lo) / 2;
        if (std_at(mid, k) <= target) {
          hi = mid;
        } else {
          lo = mid + 1;
        }
      }
      needed = lo;
    }
    plan->trials_needed[k] = needed;
    if (needed < 0 || plan->trials_needed_all < 0) {
      plan->trials_needed_all = -1;
    } else {
      plan->trials_needed_all = std::max(plan->trials_needed_all, needed);
    }
  }
}

// Every observable component has a finite, positive predicted std.
bool CheckPredictedStds(const TensorPlan& plan, std::string* error) {
  for (int k = 0; k < kTensorComponents; ++k) {
    if (plan.observable[k] && !(std::isfinite(plan.std_kg_m2[k]) && plan.std_kg_m2[k] > 0)) {
      *error = std::string("internal: the predicted std of ") + TensorComponentName(k) + " is " +
               Fmt("%g", plan.std_kg_m2[k]) + "; please report this with the command line";
      return false;
    }
  }
  return true;
}

// The chosen orientations listed by roll, then pitch: the order a crew re-rigs in.
void SortForCrew(const std::vector<Candidate>& cand, const std::vector<Stds>& stds,
                 std::vector<int> chosen, double trials, double scale, TensorPlan* plan) {
  std::sort(chosen.begin(), chosen.end(), [&cand](int x, int y) {
    if (cand[x].roll_deg != cand[y].roll_deg) return cand[x].roll_deg < cand[y].roll_deg;
    return cand[x].pitch_deg < cand[y].pitch_deg;
  });
  for (int i : chosen) {
    const Candidate& c = cand[i];
    TensorPlanOrientation o;
    o.roll_deg = c.roll_deg;
    o.pitch_deg = c.pitch_deg;
    o.axis_in_body = c.n;
    o.inertia_kg_m2 = c.inertia_kg_m2;
    o.swing_std_kg_m2 = std::hypot(stds[i].absolute, stds[i].relative);
    o.mean_std_kg_m2 = scale * std::sqrt(c.swing_var / trials + c.tilt_var);
    plan->orientations.push_back(o);
  }
}

}  // namespace

bool PlanTensor(const TensorPlanOptions& options, TensorPlan* plan, std::string* why) {
  if (!options.Check(why)) return false;
  *plan = TensorPlan();
  std::string error;
  const auto fail = [why, &error]() {
    if (why != nullptr) *why = error;
    return false;
  };
  const Eigen::Matrix3d j_guess = TensorMatrix(options.guess_kg_m2);
  std::vector<Stds> stds;
  std::vector<Candidate> cand = CandidateAttitudes(options, j_guess, &stds);
  double scale = 0.0;
  if (!ScaledVariances(options, stds, &cand, &scale, &error)) return fail();
  const int n_cand = static_cast<int>(cand.size());
  plan->n_candidates = n_cand;
  Subspace space;
  if (!ObservableSubspace(cand, options, plan, &space, &error)) return fail();
  int n = 0;
  if (!OrientationCount(n_cand, space.rank, options, plan, &n, &error)) return fail();
  const double trials = options.trials_per_orientation;
  std::vector<int> chosen;
  if (!ChooseDOptimal(cand, space, trials, n, plan, &chosen, &error)) return fail();
  if (!DesignCovariance(cand, chosen, space, options, scale, plan, &error)) return fail();
  if (options.target_std_kg_m2 > 0) {
    TrialsNeeded(cand, chosen, space, options.target_std_kg_m2, scale, plan);
  }
  if (!CheckPredictedStds(*plan, &error)) return fail();
  plan->n_points = n * options.trials_per_orientation;
  SortForCrew(cand, stds, chosen, trials, scale, plan);
  return true;
}

}  // namespace bifilar
