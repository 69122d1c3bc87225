// report.html for each kind of campaign (issue 25 item 3): planar pitch, a full tensor (roll and
// pitch) and three separate axes, each from a fast fake fit with known moments. Each page shows
// only the sections its campaign has; the page's details (issue 25 item 4); and every
// results.json key the report reads is one that ResultsToJson writes (issue 24 item 5).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "fit/tensor.h"
#include "pipeline/campaign/campaign.h"
#include "pipeline/records/results_reader.h"
#include "pipeline/records/trace_record.h"
#include "pipeline/report/export.h"
#include "pipeline/report/report.h"
#include "test_support.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;
using test_support::ReadFile;
using test_support::TempDir;
using test_support::WriteFile;

// Truth (kg m^2, products positive) and the rig.
const std::array<double, 6> kTruth = {0.20, 0.30, 0.45, 0.008, 0.010, -0.009};
constexpr double kRig = 0.02;
// Each log's stated std; trials are +-kTrialOffset about the truth, beyond that std, so the
// scatter between logs exceeds their stds and the report must name the logs behind it.
constexpr double kLogStd = 6.16e-5;
constexpr double kTrialOffset = 4e-4;
const char* kWarning =
    "I depends on the amplitude beyond its statistical error (trend 0.3 % per 10 deg); I is "
    "taken from the lowest-amplitude band with a model-inadequacy std of 0.0058 kg m^2; lower "
    "the release amplitude or set fit.max_amplitude_deg";

std::string Number(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

// Fake logs "I=<total>"; one log carries an amplitude warning.
CampaignOptions FakeOptions(const std::string& out) {
  CampaignOptions o;
  o.out_dir = out;
  o.jobs = 2;
  o.figures = true;
  o.fit_function = [](const CampaignConfig&, const std::string& path,
                      const TraceProcessOptions& options) {
    TraceRecord r;
    r.file = options.display_name;
    r.status = TraceStatus::kOk;
    std::sscanf(ReadFile(path).c_str(), "I=%lf", &r.inertia_total_kg_m2);
    r.inertia_total_std_kg_m2 = kLogStd;
    r.period_s = 2.5;
    r.model = "full";
    if (path.find("log_1.") != std::string::npos) r.warnings.push_back(kWarning);
    return r;
  };
  return o;
}

// A campaign of `attitudes` (roll, pitch) x 2 trials, written as a runs table.
std::string WriteCampaign(const TempDir& dir, const std::vector<std::array<double, 2>>& attitudes) {
  std::string table = "path,roll_deg,pitch_deg\n";
  int k = 0;
  for (const auto& a : attitudes) {
    for (int t = 0; t < 2; ++t) {
      const std::string name = "log_" + std::to_string(k++) + ".csv";
      const double moment = TensorMoment(kTruth, DownInBodyFromAttitude(a[0], a[1]));
      WriteFile(dir.path + "/logs/" + name,
                "I=" + Number(moment + kRig + (t ? kTrialOffset : -kTrialOffset)) + "\n");
      table += name + "," + Number(a[0]) + "," + Number(a[1]) + "\n";
    }
  }
  WriteFile(dir.path + "/runs.csv", table);
  return WriteFile(dir.path + "/campaign.yaml",
                   "rig: {filar_length_m: 2, filar_separation_m: 1, mass_kg: 1, inertia: "
                   "{inertia_kg_m2: 0.02}}\naircraft: {mass_kg: 3}\n"
                   "runs: {root: logs, table: runs.csv}\nellipse: {bootstrap: 100}\n");
}

struct Page {
  std::string html;
  nlohmann::json results;
  std::string out;
};

Page RunFake(const TempDir& dir, const std::vector<std::array<double, 2>>& attitudes) {
  const std::string config = WriteCampaign(dir, attitudes);
  Page p;
  p.out = dir.path + "/out";
  RunCampaign(LoadCampaignConfig(config), FakeOptions(p.out));
  p.html = ReadFile(p.out + "/report.html");
  p.results = nlohmann::json::parse(ReadFile(p.out + "/results.json"));
  return p;
}

const std::vector<std::array<double, 2>> kPlanar = {{0, -80}, {0, -10}, {0, 0}, {0, 10}, {0, 90}};
const std::vector<std::array<double, 2>> kTensor = {
    {0, 0}, {0, 45}, {0, -45}, {0, -90}, {45, 0}, {-45, 0}, {90, 0}, {45, 45}, {-45, 45}, {90, 45}};
const std::vector<std::array<double, 2>> kThreeAxes = {{0, 0}, {0, -90}, {90, 0}};

size_t Find(const std::string& html, const std::string& needle) { return html.find(needle); }

// What every kind's page shares: no error colour for a section that does not apply, no empty
// figure section, no e-notation in the tables, a roll column, wide tables in a scrolling box.
void ExpectCommonDetails(const Page& p) {
  const std::string page = p.html.substr(0, p.html.find("<h2>Config used</h2>"));
  EXPECT_EQ(Find(page, "not fitted"), std::string::npos);
  EXPECT_EQ(Find(page, "(no figure)"), std::string::npos);
  EXPECT_EQ(Find(page, "class=\"bad\""), std::string::npos);
  std::string text = page;  // without embedded images (base64 may hold any letters)
  for (size_t at = text.find("data:"); at != std::string::npos; at = text.find("data:", at)) {
    const size_t end = text.find('"', at);
    text.erase(at, end == std::string::npos ? std::string::npos : end - at);
    if (end == std::string::npos) break;
    ++at;
  }
  for (const char* e : {"e-0", "e-1", "e+0"}) {
    const size_t at = Find(text, e);
    EXPECT_EQ(at, std::string::npos) << e << " in: " << text.substr(at < 120 ? 0 : at - 120, 240);
  }
  EXPECT_NE(Find(page, "<th>roll (deg)</th><th>pitch (deg)</th>"), std::string::npos);
  EXPECT_NE(
      Find(page,
           "<div class=\"scroll\"><table><tr><th class=\"l\">file</th><th class=\"l\">role</th>"),
      std::string::npos);
  // The main result first, in its box before any section.
  EXPECT_LT(Find(page, "<p class=\"result\">Result: "), Find(page, "<h2>"));
  // Table 1 before Table 2 (the paper's order) where both are shown.
  EXPECT_NE(Find(page, "Table 1: data quality"), std::string::npos);
  // The warning: the console's line (LineOfWarning: its one sentence is cut to leave room for
  // the clause that says what to do), the full text on click.
  EXPECT_NE(Find(page,
                 "<details><summary>I depends on the amplitude beyond its statistical error "
                 "(trend 0.3 % per 10 deg); ... &rarr; <b>lower the release "
                 "amplitude or set fit.max_amplitude_deg</b></summary><p>I depends"),
            std::string::npos);
  EXPECT_EQ(LineOfWarning(kWarning).Text(),
            "I depends on the amplitude beyond its statistical error (trend 0.3 % per 10 deg); "
            "... -> lower the release amplitude or set fit.max_amplitude_deg");
}

// The traces table's pitch cells in page order.
std::vector<double> TablePitches(const std::string& html) {
  std::vector<double> out;
  const size_t start = html.find("<h2>Traces</h2>"), end = html.find("</table>", start);
  for (size_t at = html.find("<tr class", start); at < end; at = html.find("<tr class", at + 1)) {
    // file, role, status, roll, pitch: the fifth cell
    size_t cell = at;
    for (int k = 0; k < 5; ++k) cell = html.find("<td", cell + 1);
    out.push_back(std::stod(html.substr(html.find('>', cell) + 1)));
  }
  return out;
}

TEST(ReportKinds, PlanarPitchShowsTheEllipseInThePapersOrder) {
  TempDir dir("bifilar_report_kinds");
  const Page p = RunFake(dir, kPlanar);
  ExpectCommonDetails(p);
  EXPECT_NE(Find(p.html, "campaign: planar pitch"), std::string::npos);
  EXPECT_LT(Find(p.html, "Table 1: data quality"), Find(p.html, "Table 2: inertia properties"));
  EXPECT_NE(Find(p.html, "Figure 3: moment of inertia against pitch"), std::string::npos);
  EXPECT_NE(Find(p.html, "Figure 4: ellipse of inertia"), std::string::npos);
  EXPECT_EQ(Find(p.html, "<h2>Inertia tensor</h2>"), std::string::npos);
  // Angles sort numerically: -80, -10, 0, 10, 90 (as text they would read -10, -80, 0, 10, 90).
  const std::vector<double> pitches = TablePitches(p.html);
  ASSERT_EQ(pitches.size(), 10u);
  for (size_t k = 1; k < pitches.size(); ++k) EXPECT_LE(pitches[k - 1], pitches[k]) << k;
  // A std of 6.16e-05 in fixed notation to two digits.
  EXPECT_NE(Find(p.html, "<td>0.000062</td>"), std::string::npos);
}

TEST(ReportKinds, FullTensorShowsItsEllipsoidAndNamesTheLogsOfTheScatter) {
  TempDir dir("bifilar_report_kinds");
  const Page p = RunFake(dir, kTensor);
  ExpectCommonDetails(p);
  EXPECT_NE(Find(p.html, "campaign: full inertia tensor"), std::string::npos);
  for (const char* absent : {"Table 2", "Figure 3", "Figure 4", "NACA"}) {
    EXPECT_EQ(Find(p.html, absent), std::string::npos) << absent;
  }
  EXPECT_LT(Find(p.html, "<h2>Inertia tensor</h2>"), Find(p.html, "<h2>Traces</h2>"));
  ASSERT_FALSE(p.results["figures"]["tensor"].get<std::string>().empty());
  EXPECT_NE(Find(p.html, "Ellipsoid of inertia"), std::string::npos);
  EXPECT_NE(Find(p.html, "alt=\"ellipsoid of inertia"), std::string::npos);
  // The trials scatter by +-4e-4 about moments whose logs say +-6.16e-5: named.
  const nlohmann::json& logs = p.results["tensor"]["scatter_logs"];
  ASSERT_FALSE(logs.empty());
  EXPECT_NE(Find(p.html, "the logs behind the scatter, residual over their own std: " +
                             logs[0]["file"].get<std::string>()),
            std::string::npos);
}

TEST(ReportKinds, ThreeSeparateAxesShowTheirMomentsAndNothingEmpty) {
  TempDir dir("bifilar_report_kinds");
  const Page p = RunFake(dir, kThreeAxes);
  ExpectCommonDetails(p);
  EXPECT_NE(Find(p.html, "campaign: separate axes"), std::string::npos);
  for (const char* absent : {"Table 2", "Figure 3", "Figure 4", "NACA", "Ellipsoid of inertia"}) {
    EXPECT_EQ(Find(p.html, absent), std::string::npos) << absent;
  }
  EXPECT_NE(Find(p.html, "I<sub>yy</sub> = 0.300"), std::string::npos);
  // Two set-ups that differ only in roll are two rows, not two "pitch 0.00".
  EXPECT_NE(Find(p.html, "<td>90.0</td><td>0.0</td>"), std::string::npos);
  EXPECT_NE(Find(p.html, "the logs behind the scatter"), std::string::npos);
}

// A results.json whose trace lacks a key (written by another version) or holds one of another
// type: `bifilar report` stops with one error naming the file, the trace, the key, the version
// that wrote it and what to do, and leaves the page as it was.
TEST(ReportKinds, ATraceOfAnotherVersionIsOneClearError) {
  TempDir dir("bifilar_report_kinds");
  const Page p = RunFake(dir, kPlanar);
  const std::string path = p.out + "/results.json";
  nlohmann::json old = p.results;
  old["version"] = "0.2.0";
  old["traces"][2].erase("period_s");
  WriteFile(path, old.dump(1));
  const std::string error = test_support::ErrorOf([&] { RunReport(p.out); });
  for (const std::string& part :
       {path + ": not a results file bifilar can read", std::string("traces[2] (log_2.csv)"),
        std::string("'period_s' is missing"), std::string("written by bifilar 0.2.0"),
        std::string("rerun `bifilar process` to rewrite it")}) {
    EXPECT_NE(error.find(part), std::string::npos) << part << " not in: " << error;
  }
  EXPECT_EQ(ReadFile(p.out + "/report.html"), p.html);  // not rewritten
  nlohmann::json mistyped = p.results;
  mistyped["traces"][0]["window_s"] = "6.8 to 46.6";
  mistyped["traces"][0]["uncertainty"]["hac_bandwidth"] = 2.5;
  WriteFile(path, mistyped.dump(1));
  EXPECT_NE(test_support::ErrorOf([&] {
              RunReport(p.out);
            }).find("traces[0] (log_0.csv): 'window_s' is not a pair of numbers (string)"),
            std::string::npos);
  mistyped["traces"][0]["window_s"] = nullptr;
  WriteFile(path, mistyped.dump(1));
  EXPECT_NE(test_support::ErrorOf([&] {
              RunReport(p.out);
            }).find("'uncertainty.hac_bandwidth' is not a whole number (number)"),
            std::string::npos);
}

TEST(ReportKinds, EveryKeyTheReportReadsIsWritten) {
  KeyLog written, read;
  for (const auto* attitudes : {&kPlanar, &kTensor, &kThreeAxes}) {
    TempDir dir("bifilar_report_kinds");
    const Page p = RunFake(dir, *attitudes);
    const KeyLog w = KeyPaths(p.results), r = ReportKeysRead(p.results, p.out);
    written.insert(w.begin(), w.end());
    read.insert(r.begin(), r.end());
    // export reads through the same reader
    ExportOptions options;
    options.results_path = p.out + "/results.json";
    KeyLog exported;
    ReadExportInertia(p.results.dump(), "results.json", options, &exported);
    EXPECT_TRUE(exported.count("tensor.Ixx_kg_m2") == 1) << "export read no tensor";
    read.insert(exported.begin(), exported.end());
  }
  // A trace's
  // uncertainty.repeat_scatter_kg_m2 and amplitude_correction are written only by `fit
  // --repeats`: the trace reader looks for them in every record, and
  // tests/pipeline_trace_record_json_test.cc checks them against the writer.
  const KeyLog only_elsewhere = {"traces[].uncertainty.repeat_scatter_kg_m2",
                                 "traces[].amplitude_correction"};
  for (const std::string& key : read) {
    EXPECT_TRUE(written.count(key) == 1 || only_elsewhere.count(key) == 1)
        << key << " is never written";
  }
  // The traces, the summary and the calibration (none here: null) are read whole by their typed
  // readers (pipeline/records/results_json.h; TraceRecordFromJson is the cache's reader too).
  EXPECT_EQ(read.count("summary.n_reused"), 1u);
  EXPECT_EQ(read.count("calibration"), 1u);
  EXPECT_EQ(read.count("traces[].period_s"), 1u);
  EXPECT_EQ(read.count("traces[].amplitude_sweep.low_band"), 1u);
  EXPECT_GT(read.size(), 80u);
}

}  // namespace
}  // namespace bifilar
