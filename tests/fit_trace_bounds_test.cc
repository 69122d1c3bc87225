// The bounds of one trace fit (TraceFitOptions::max_total_iterations, max_integrator_steps), its
// last-resort time guard (time_guard_cpu_seconds) and its interrupt flag (issue 23 item 5, issue
// 33 item 6): a window over a whole simulated log (rest, twist, hold and swing) that
// Levenberg-Marquardt cannot fit stops at a work bound with a message saying so, after the same
// work on any machine; the time guard is an error of its own; a raised flag stops a fit with an
// `interrupted` error; none changes a normal fit. Nothing here depends on the machine's speed:
// the work bounds count iterations and steps, and the guard's test sets it so low that it trips
// before any work and checks only that it is reported as the guard.
#include <atomic>
#include <string>

#include <gtest/gtest.h>

#include "fit/trace_fit.h"
#include "pendulum/simulate.h"

namespace bifilar {
namespace {

// A simulated log at 100 Hz: 3 s rest, 1 s twist, 1.5 s hold, then 30 s of free swing (the same
// setup as `bifilar simulate --trace`). `whole` true: every sample, rest and twist included (a
// window `fit --window 0:END` would give); false: the free swing only.
TraceFitInput Simulated(bool whole) {
  TraceSetup setup;
  setup.geometry.filar_length_m = 1.0;
  setup.geometry.filar_separation_m = 0.4;
  setup.geometry.mass_kg = 1.5;
  setup.params.inertia_kg_m2 = 0.05;
  setup.params.drag_coeff_kg_m2 = 0.002;
  setup.params.viscous_coeff_kg_m2_per_s = 0.0005;
  setup.amplitude_rad = 0.35;
  SimulationOptions options;
  options.timeline = FixedTimeline(3.0, 1.0, 1.5, 30.0);
  SimulatedTrace trace;
  std::string why;
  EXPECT_TRUE(SimulateTrace(setup, options, 7, &trace, &why)) << why;
  TraceFitInput input;
  input.geometry = setup.geometry;
  input.label = "sim.csv";
  const double release_s = trace.imu.t_s.front() + 5.5;
  for (size_t k = 0; k < trace.imu.size(); ++k) {
    if (!whole && trace.imu.t_s[k] < release_s + 1.0) continue;
    input.t_s.push_back(trace.imu.t_s[k]);
    input.rate_rad_per_s.push_back(trace.imu.gyro_in_imu[k].z());
  }
  return input;
}

TEST(TraceFitBounds, IterationBoundStopsAHostileWindowWithAMessage) {
  const TraceFitInput input = Simulated(true);
  TraceFitOptions options;
  options.max_total_iterations = 3;
  options.time_guard_cpu_seconds = 1e9;  // the work bound alone decides, however slow the machine
  const TraceFitResult r = FitTrace(input, options);
  EXPECT_EQ(r.status, TraceFitStatus::kRejected) << r.BriefReport();
  EXPECT_TRUE(r.solver_bound);
  EXPECT_FALSE(r.time_guard);
  EXPECT_FALSE(r.interrupted);
  EXPECT_FALSE(r.HasFit()) << "a stopped fit reports no inertia";
  EXPECT_EQ(r.iterations, 3);
  EXPECT_EQ(r.message.rfind("sim.csv: the solver was stopped after 3 iterations and ", 0), 0u)
      << r.message;
  EXPECT_NE(r.message.find(" integrator steps (bound reached: 3 iterations per fit; the other: "
                           "20000000 integrator steps)"),
            std::string::npos)
      << r.message;
  ASSERT_FALSE(r.flags.empty());
  EXPECT_EQ(r.flags.back(), "solver_bound");
}

// The step bound counts work: the same fit stops at the same point twice, after at least the
// bound's steps, and says so in the same words.
TEST(TraceFitBounds, IntegratorStepBoundStopsTheFitAfterTheSameWork) {
  const TraceFitInput input = Simulated(true);
  TraceFitOptions options;
  options.max_integrator_steps = 3000;
  options.time_guard_cpu_seconds = 1e9;
  const TraceFitResult r = FitTrace(input, options);
  EXPECT_EQ(r.status, TraceFitStatus::kRejected) << r.BriefReport();
  EXPECT_TRUE(r.solver_bound);
  EXPECT_FALSE(r.time_guard);
  EXPECT_GE(r.integrator_steps, 3000);
  EXPECT_NE(r.message.find("integrator steps (bound reached: 3000 integrator steps per fit; the "
                           "other: 500 iterations)"),
            std::string::npos)
      << r.message;
  const TraceFitResult again = FitTrace(input, options);
  EXPECT_EQ(again.iterations, r.iterations);
  EXPECT_EQ(again.integrator_steps, r.integrator_steps);
  EXPECT_EQ(again.message, r.message);
}

// The time guard is not a work bound: an error with its own flag and message, never
// `solver_bound`. Set below any fit's CPU time, it trips at the first check; only that is
// checked, never how far the fit got.
TEST(TraceFitBounds, TimeGuardIsAnErrorOfItsOwn) {
  const TraceFitInput input = Simulated(true);
  TraceFitOptions options;
  options.time_guard_cpu_seconds = 1e-12;
  const TraceFitResult r = FitTrace(input, options);
  EXPECT_EQ(r.status, TraceFitStatus::kError) << r.BriefReport();
  EXPECT_TRUE(r.time_guard);
  EXPECT_FALSE(r.solver_bound);
  EXPECT_FALSE(r.interrupted);
  EXPECT_FALSE(r.HasFit());
  EXPECT_EQ(r.message.rfind("sim.csv: abandoned by the time guard after ", 0), 0u) << r.message;
  EXPECT_NE(r.message.find("(guard: 1e-12 s per fit;"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("depends on the machine's speed"), std::string::npos) << r.message;
  ASSERT_FALSE(r.flags.empty());
  EXPECT_EQ(r.flags.back(), "time_guard");
}

TEST(TraceFitBounds, RaisedInterruptFlagStopsTheFitAsInterrupted) {
  const TraceFitInput input = Simulated(true);
  std::atomic<bool> flag{true};
  TraceFitOptions options;
  options.interrupt = &flag;
  const TraceFitResult r = FitTrace(input, options);
  EXPECT_EQ(r.status, TraceFitStatus::kError) << r.BriefReport();
  EXPECT_TRUE(r.interrupted);
  EXPECT_FALSE(r.solver_bound);
  EXPECT_EQ(r.message.rfind("sim.csv: interrupted after 0 iterations", 0), 0u) << r.message;
  ASSERT_FALSE(r.flags.empty());
  EXPECT_EQ(r.flags.back(), "interrupted");
}

// On the free swing the bounds and an unraised flag change nothing, bit for bit: the budget's
// callback reads no solver state.
TEST(TraceFitBounds, BoundsAndFlagLeaveANormalFitUnchanged) {
  const TraceFitInput input = Simulated(false);
  TraceFitOptions loose;
  loose.max_total_iterations = 1000000;
  loose.max_integrator_steps = 1L << 50;
  loose.time_guard_cpu_seconds = 1e9;
  const TraceFitResult reference = FitTrace(input, loose);
  ASSERT_EQ(reference.status, TraceFitStatus::kOk) << reference.BriefReport();
  EXPECT_LT(reference.iterations, 100);
  EXPECT_LT(reference.integrator_steps, 1000000) << "far below the default step bound";
  std::atomic<bool> flag{false};
  TraceFitOptions options;  // default bounds
  options.interrupt = &flag;
  const TraceFitResult r = FitTrace(input, options);
  ASSERT_EQ(r.status, TraceFitStatus::kOk) << r.BriefReport();
  EXPECT_EQ(r.params.inertia_kg_m2, reference.params.inertia_kg_m2);
  EXPECT_EQ(r.inertia_std_kg_m2, reference.inertia_std_kg_m2);
  EXPECT_EQ(r.iterations, reference.iterations);
  EXPECT_EQ(r.integrator_steps, reference.integrator_steps);
  EXPECT_FALSE(r.solver_bound);
  EXPECT_FALSE(r.interrupted);
}

// Timestamps too large for a double to resolve the steps: an error naming them, not Ceres'
// "Residual and Jacobian evaluation failed".
TEST(TraceFitBounds, HugeTimestampsAreAnErrorBeforeTheSolver) {
  TraceFitInput input = Simulated(false);
  for (double& t : input.t_s) t += 1e12;
  const TraceFitResult r = FitTrace(input, TraceFitOptions());
  EXPECT_EQ(r.status, TraceFitStatus::kError);
  EXPECT_EQ(r.message.rfind("sim.csv: timestamps near 1e+12 s are too large for samples", 0), 0u)
      << r.message;
}

TEST(TraceFitBounds, OptionsCheckNamesTheBounds) {
  TraceFitOptions options;
  std::string why;
  options.max_total_iterations = 0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "max_total_iterations = 0; must be >= 1");
  options = TraceFitOptions();
  options.max_integrator_steps = 0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "max_integrator_steps = 0; must be >= 1");
  options = TraceFitOptions();
  options.time_guard_cpu_seconds = NAN;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "time_guard_cpu_seconds = nan; must be finite and > 0");
  options = TraceFitOptions();
  options.min_amplitude_deg = 20;
  options.max_amplitude_deg = 10;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "max_amplitude_deg = 10; must be > min_amplitude_deg = 20");
  options = TraceFitOptions();
  options.mass_std_kg = -0.5;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "mass_std_kg = -0.5; must be finite and >= 0");
}

}  // namespace
}  // namespace bifilar
