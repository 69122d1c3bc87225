// The amplitude-sweep figure (pipeline/figures/sweep_plot.h, issue 8 item 3): written beside the
// fit figure for a trace whose sweep was evaluated, listed in the record's figures (and its JSON),
// and for a trace too short for a sweep, no file and no entry. Traces are simulated with `bifilar
// simulate` (PRANDTL-D-like rig, seed 1): 40 s of swing holds ~15 cycles (5 bands of 3), 9 s holds
// < 6.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pipeline/config/config.h"
#include "pipeline/figures/sweep_plot.h"
#include "pipeline/records/results_json.h"
#include "pipeline/trace/trace_process.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;

std::string TempDir() {
  char tmpl[] = "/tmp/bifilar_sweep_figure_XXXXXX";
  return mkdtemp(tmpl);
}

// One simulated log of `duration_s` of free swing (I = 4 kg m^2, m = 6.75 kg, L = 2, D = 1.8 m).
std::string Simulate(const std::string& dir, const std::string& name, double duration_s) {
  const std::string path = dir + "/" + name + ".csv";
  const std::string command = std::string(BIFILAR_BINARY) + " simulate --trace " + path +
                              " --inertia-kg-m2 4.0 --mass-kg 6.75 -L 2 -D 1.8 --seed 1" +
                              " --duration-s " + std::to_string(duration_s) + " > /dev/null";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  return path;
}

CampaignConfig Config(const std::string& dir) {
  const std::string path = dir + "/c.yaml";
  std::ofstream(path) << "rig: {filar_length_m: 2.0, filar_separation_m: 1.8, mass_kg: 6.75}\n";
  ConfigLoadOptions options;
  options.require_runs = false;
  return LoadCampaignConfig(path, options);
}

bool Contains(const nlohmann::json& list, const std::string& item) {
  for (const auto& entry : list) {
    if (entry == item) return true;
  }
  return false;
}

TEST(SweepFigure, WrittenAndListedForATraceWithASweep) {
  const std::string dir = TempDir();
  const std::string log = Simulate(dir, "long", 40.0);
  TraceProcessOptions options;
  options.figure_paths = {dir + "/long.svg"};
  options.sweep_figure_paths = {dir + "/long_sweep.svg", dir + "/long_sweep.png"};
  const TraceRecord r = ProcessTrace(Config(dir), log, options);
  ASSERT_EQ(r.status, TraceStatus::kOk) << r.message;
  ASSERT_TRUE(r.sweep.evaluated) << r.sweep.note;
  for (const std::string& path : options.sweep_figure_paths) {
    ASSERT_TRUE(fs::exists(path)) << path;
    // a drawn page, not an empty one (the SVG's text is text: a few kB)
    EXPECT_GT(fs::file_size(path),
              path.size() > 4 && path.substr(path.size() - 4) == ".svg" ? 3000u : 10000u)
        << path;
  }
  // The SVG is a figure with its title (the trend's z) in it, as text.
  std::ifstream svg(dir + "/long_sweep.svg");
  const std::string text((std::istreambuf_iterator<char>(svg)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("<svg"), std::string::npos);
  EXPECT_NE(text.find("trend z = "), std::string::npos);
  const nlohmann::json j = TraceRecordToJson(r, false);
  EXPECT_TRUE(Contains(j["figures"], dir + "/long.svg"));
  EXPECT_TRUE(Contains(j["figures"], dir + "/long_sweep.svg"));
  EXPECT_TRUE(Contains(j["figures"], dir + "/long_sweep.png"));
  for (const std::string& flag : r.flags) EXPECT_NE(flag, "figure_failed");
  fs::remove_all(dir);
}

TEST(SweepFigure, NoneForATraceTooShortForASweep) {
  const std::string dir = TempDir();
  const std::string log = Simulate(dir, "short", 9.0);
  TraceProcessOptions options;
  options.figure_paths = {dir + "/short.svg"};
  options.sweep_figure_paths = {dir + "/short_sweep.svg"};
  const TraceRecord r = ProcessTrace(Config(dir), log, options);
  ASSERT_EQ(r.status, TraceStatus::kOk) << r.message;
  EXPECT_FALSE(r.sweep.evaluated);
  EXPECT_FALSE(r.sweep.note.empty());
  EXPECT_TRUE(fs::exists(dir + "/short.svg"));         // the fit figure is still drawn
  EXPECT_FALSE(fs::exists(dir + "/short_sweep.svg"));  // no sweep figure
  const nlohmann::json j = TraceRecordToJson(r, false);
  EXPECT_FALSE(Contains(j["figures"], dir + "/short_sweep.svg"));
  for (const std::string& w : r.warnings) {
    EXPECT_EQ(w.find("could not be written"), std::string::npos) << w;
  }
  fs::remove_all(dir);
}

TEST(SweepFigure, RefusesASweepThatWasNotEvaluated) {
  AmplitudeSweep sweep;
  sweep.note = "the window holds 2.9 cycles";
  std::string why;
  EXPECT_FALSE(WriteAmplitudeSweepFigure(sweep, 4.0, 1e-3, "/tmp/never.svg", {}, &why));
  EXPECT_NE(why.find("2.9 cycles"), std::string::npos) << why;
  EXPECT_FALSE(fs::exists("/tmp/never.svg"));
}

}  // namespace
}  // namespace bifilar
