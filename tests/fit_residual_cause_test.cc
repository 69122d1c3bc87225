// issue 25 item 6: the residual warning names the likely cause from the residual's shape, and
// every warning of the fit says what to do. Three simulated shapes, each with known cause:
//   - white but large: a clean trace fitted with a noise estimate 5x below the true noise;
//   - coherent and growing with amplitude: the full model's swing, decaying 40 -> ~15 deg,
//     fitted with the linear model (a rig that departs from the fitted model);
//   - a step: the same clean trace with a 0.05 rad/s gyro step half-way (a glitch).
// And a parameter at its bound: a swing with no air drag (K_D = 0) is flagged with its action.
#include <algorithm>
#include <string>

#include <gtest/gtest.h>

#include "fit/trace_fit.h"
#include "fit/trace_synth.h"
#include "pipeline/records/trace_record.h"

namespace bifilar {
namespace {

// The docs/physics.md §2 example rig (period ~2.8 s), as in fit_trace_fit_test.cc.
SyntheticTraceOptions Truth(double amplitude_deg) {
  return ExampleRigTraceOptions(amplitude_deg, 7);
}

bool HasFlag(const TraceFitResult& r, const std::string& flag) {
  return std::find(r.flags.begin(), r.flags.end(), flag) != r.flags.end();
}

// The rms_above_noise warning's text (empty when none).
std::string ResidualWarning(const TraceFitResult& r) {
  for (const std::string& w : r.warnings) {
    if (w.rfind("residual ", 0) == 0) return w;
  }
  return "";
}

TEST(ResidualCause, WhiteButLargeIsNoiseAndSaysRaiseTheThreshold) {
  TraceFitInput in;
  ASSERT_TRUE(MakeSyntheticTrace(Truth(20.0), &in));
  in.noise_rad_per_s /= 5.0;  // the rest segment said 5x less noise than the swing has
  const TraceFitResult r = FitTrace(in, TraceFitOptions());
  ASSERT_TRUE(r.IsUsable()) << r.message;
  EXPECT_GT(r.rms_over_noise, 3.0);
  EXPECT_TRUE(HasFlag(r, "residual_noise")) << r.BriefReport();
  const std::string w = ResidualWarning(r);
  EXPECT_NE(WarningSummary(w).find("raise fit.quality.max_rms_over_noise"), std::string::npos) << w;
  EXPECT_NE(WarningSummary(w).find("(noise)"), std::string::npos) << w;
}

TEST(ResidualCause, CoherentAndGrowingWithAmplitudeIsTheModelAndSaysSwingLower) {
  SyntheticTraceOptions truth = Truth(40.0);
  truth.params.drag_coeff_kg_m2 = 0.03;  // decays to about a third over the window
  truth.noise_deg_per_s = 0.05;
  TraceFitInput in;
  ASSERT_TRUE(MakeSyntheticTrace(truth, &in));
  TraceFitOptions options;
  options.model = PendulumModel::kLinear;  // the rig departs from the fitted model
  const TraceFitResult r = FitTrace(in, options);
  ASSERT_TRUE(r.HasFit()) << r.message;
  EXPECT_GT(r.amplitude_start_deg, 2.0 * r.amplitude_end_deg) << r.BriefReport();
  EXPECT_TRUE(HasFlag(r, "residual_model")) << r.BriefReport();
  // The line the console and the report show: the summary, and the action when it was cut.
  const std::string summary = LineOfWarning(ResidualWarning(r)).Text();
  EXPECT_NE(summary.find("the rig departs from the model"), std::string::npos) << summary;
  EXPECT_NE(summary.find("fit.max_amplitude_deg (--max-amplitude)"), std::string::npos) << summary;
  EXPECT_EQ(summary.find("raise fit.quality"), std::string::npos) << summary;
}

TEST(ResidualCause, StepIsAGlitchAndSaysWhere) {
  TraceFitInput in;
  ASSERT_TRUE(MakeSyntheticTrace(Truth(20.0), &in));
  const double t_step = 0.5 * (in.t_s.front() + in.t_s.back());
  for (size_t k = 0; k < in.t_s.size(); ++k) {
    if (in.t_s[k] > t_step) in.rate_rad_per_s[k] += 0.05;
  }
  const TraceFitResult r = FitTrace(in, TraceFitOptions());
  ASSERT_TRUE(r.HasFit()) << r.message;
  EXPECT_TRUE(HasFlag(r, "residual_glitch")) << r.BriefReport();
  const std::string summary = WarningSummary(ResidualWarning(r));
  EXPECT_NE(summary.find("step or spike near t = "), std::string::npos) << summary;
  EXPECT_NE(summary.find("--window"), std::string::npos) << summary;
  // Where: within a second of the step.
  const double said = std::stod(summary.substr(summary.find("near t = ") + 9));
  EXPECT_NEAR(said, t_step, 1.0) << summary;
}

TEST(ResidualCause, SpikeIsAGlitch) {
  TraceFitInput in;
  ASSERT_TRUE(MakeSyntheticTrace(Truth(20.0), &in));
  const size_t k = in.t_s.size() / 3;
  in.rate_rad_per_s[k] += 2.0;  // one reading 2 rad/s off
  const TraceFitResult r = FitTrace(in, TraceFitOptions());
  ASSERT_TRUE(r.HasFit()) << r.message;
  if (r.rms_over_noise > 3.0) {
    EXPECT_TRUE(HasFlag(r, "residual_glitch")) << r.BriefReport();
  } else {
    ADD_FAILURE() << "a 2 rad/s spike should lift the residual above 3x the noise: "
                  << r.BriefReport();
  }
}

// A clean trace: no residual warning at all.
TEST(ResidualCause, CleanTraceRaisesNoResidualWarning) {
  TraceFitInput in;
  ASSERT_TRUE(MakeSyntheticTrace(Truth(20.0), &in));
  const TraceFitResult r = FitTrace(in, TraceFitOptions());
  ASSERT_TRUE(r.IsUsable()) << r.message;
  EXPECT_EQ(ResidualWarning(r), "") << r.BriefReport();
}

// K_D = 0 in the truth: the fit holds it at its bound and says so, with what to do.
TEST(ParameterAtBound, NoAirDragIsFlaggedWithItsAction) {
  SyntheticTraceOptions truth = Truth(20.0);
  truth.params.drag_coeff_kg_m2 = 0.0;
  int flagged = 0;
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    truth.seed = seed;
    TraceFitInput in;
    ASSERT_TRUE(MakeSyntheticTrace(truth, &in));
    const TraceFitResult r = FitTrace(in, TraceFitOptions());
    ASSERT_TRUE(r.IsUsable()) << r.message;
    const bool at_bound = r.params.drag_coeff_kg_m2 == 0.0;
    EXPECT_EQ(HasFlag(r, "drag_at_bound"), at_bound) << r.BriefReport();
    if (!at_bound) continue;
    ++flagged;
    bool said = false;
    for (const std::string& w : r.warnings) {
      said = said || (WarningSummary(w).rfind("K_D = 0 (air drag at its bound)", 0) == 0 &&
                      WarningSummary(w).find("fit a longer window") != std::string::npos);
    }
    EXPECT_TRUE(said) << r.BriefReport();
  }
  // About half the seeds want a negative K_D when the truth is 0.
  EXPECT_GT(flagged, 0);
}

// Every warning's summary is one line of at most 160 characters and its first sentence.
TEST(WarningSummary, FirstSentenceCutAtAWord) {
  EXPECT_EQ(WarningSummary("a short warning; do this. Details 1.5 here."),
            "a short warning; do this");
  EXPECT_EQ(WarningSummary("no detail at all"), "no detail at all");
  EXPECT_EQ(WarningSummary("is it a footer? Then ignore it"), "is it a footer?");
  EXPECT_EQ(WarningSummary("values 1.06 and e.g. more. Then"), "values 1.06 and e.g. more");
  const std::string long_text(200, 'x');
  EXPECT_LE(WarningSummary(long_text + " y").size(), 160u);
  const std::string words = "word " + std::string(10, 'w');
  std::string many;
  for (int i = 0; i < 30; ++i) many += words + " ";
  const std::string s = WarningSummary(many);
  EXPECT_LE(s.size(), 160u);
  EXPECT_EQ(s.substr(s.size() - 4), " ...");
}

}  // namespace
}  // namespace bifilar
