// report.html: self-contained (figures embedded), every section present, rebuilt from
// results.json alone, and loading in headless Chromium without console errors where Chromium is
// installed (/usr/bin/chromium; the test is skipped otherwise).
#include "base/units.h"
#include "pipeline/report/report.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <plplot/plplot.h>
#include <nlohmann/json.hpp>

#include "base/user_error.h"
#include "pipeline/campaign/campaign.h"
#include "pipeline/figures/figure.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::ReadFile;
using test_support::WriteFile;

namespace fs = std::filesystem;

TEST(Report, Base64MatchesRfc4648Vectors) {
  EXPECT_EQ(Base64(""), "");
  EXPECT_EQ(Base64("f"), "Zg==");
  EXPECT_EQ(Base64("fo"), "Zm8=");
  EXPECT_EQ(Base64("foo"), "Zm9v");
  EXPECT_EQ(Base64("foob"), "Zm9vYg==");
  EXPECT_EQ(Base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(Base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(Base64(std::string("\xff\x00\x10", 3)), "/wAQ");
}

// Every href="#id" of the page names an id="id" of the page (a shared glyph, a section).
void ExpectEveryHrefResolves(const std::string& html) {
  int refs = 0;
  for (size_t at = html.find("href=\"#"); at != std::string::npos;
       at = html.find("href=\"#", at + 1)) {
    const size_t start = at + 7, end = html.find('"', start);
    ASSERT_NE(end, std::string::npos);
    const std::string id = html.substr(start, end - start);
    EXPECT_NE(html.find("id=\"" + id + "\""), std::string::npos) << id;
    ++refs;
  }
  EXPECT_GT(refs, 0);
}

// A campaign with a fake fit that draws a small figure per trace, so the report has every kind
// of figure: 4 angles x 2 trials, one log that fails.
std::string MakeCampaign() {
  char tmpl[] = "/tmp/bifilar_report_test_XXXXXX";
  const std::string dir = mkdtemp(tmpl);
  for (double p : {-45.0, 0.0, 45.0, 90.0}) {
    for (int k = 1; k <= 2; ++k) {
      const double t = p * kRadPerDeg;
      const double inertia = 3.0 * std::cos(t) * std::cos(t) + 2.0 * std::sin(t) * std::sin(t) +
                             0.05 * std::sin(2 * t) + 0.5 + (k == 1 ? 1e-3 : -1e-3);
      std::ostringstream name;
      name << dir << "/logs/pitch_" << p << "/trial_" << k << ".csv";
      WriteFile(name.str(), std::to_string(inertia));
    }
  }
  WriteFile(dir + "/logs/pitch_0/trial_<3>.csv", "broken & <bad>");
  WriteFile(
      dir + "/c.yaml",
      "rig: {filar_length_m: 2, filar_separation_m: 1, mass_kg: 1, inertia: {inertia_kg_m2: 0.5}}\n"
      "aircraft: {mass_kg: 5}\nruns: {root: logs, pattern: \"pitch_{pitch_deg}/*.csv\"}\n"
      "units: imperial\n");
  CampaignOptions options;
  options.out_dir = dir + "/out";
  options.jobs = 2;
  options.fit_function = [](const CampaignConfig&, const std::string& path,
                            const TraceProcessOptions& o) {
    TraceRecord r;
    const std::string text = ReadFile(path);
    if (text.find("broken") != std::string::npos) throw UserError("not a number in " + path);
    r.status = TraceStatus::kOk;
    r.inertia_total_kg_m2 = std::stod(text);
    r.inertia_total_std_kg_m2 = 1e-4;
    r.window_s = {2.0, 40.0};
    r.amplitude_deg = {20.0, 8.0};
    r.period_s = 2.5;
    r.frequency_hz = 0.4;
    r.small_angle_inertia_total_kg_m2 = r.inertia_total_kg_m2 * 1.01;
    // One fitted trace with a warning (as the sample's pitch_20/trial_2), in SI as the fit
    // writes it; and the assumed-inputs warning every trace carries, which the report states
    // once (Table 2), not per trace.
    if (path.find("pitch_45/trial_2") != std::string::npos) {
      r.warnings.push_back(
          "I depends on the amplitude beyond its statistical error; I is taken "
          "from the lowest-amplitude band with a model-inadequacy std of "
          "0.0058 kg m^2");
    }
    std::string why;
    WriteFigure(
        o.figure_paths.at(0), FigureOptions{400, 300},
        [] {
          PLFLT x[2] = {0, 1}, y[2] = {0, 1};
          plenv(0, 1, 0, 1, 0, 0);
          pllab("t (s)", "rate", "fake fit");
          plline(2, x, y);
        },
        &why);
    // Trial 1 of each angle has an amplitude sweep (and its figure), trial 2 is too short.
    if (path.find("trial_1") != std::string::npos) {
      r.sweep.evaluated = true;
      WriteFigure(
          o.sweep_figure_paths.at(0), FigureOptions{400, 300},
          [] {
            plenv(0, 1, 0, 1, 0, 0);
            pllab("amplitude (deg)", "I", "fake sweep");
          },
          &why);
    } else {
      r.sweep.note = "the window holds 4.0 cycles";
    }
    return r;
  };
  RunCampaign(LoadCampaignConfig(dir + "/c.yaml"), options);
  return dir + "/out";
}

TEST(Report, HasEverySectionAndEmbedsEveryFigure) {
  const std::string out = MakeCampaign();
  const std::string html = ReadFile(out + "/report.html");
  for (const char* section :
       {"Table 2: inertia properties", "Table 1: data quality",
        "Figure 3: moment of inertia against pitch", "Figure 4: ellipse of inertia",
        "NACA Report 467 comparison", "Per-angle statistics", "Rejected and failed traces",
        "Fit and residual of every trace", "Config used", "slug ft"}) {
    EXPECT_NE(html.find(section), std::string::npos) << section;
  }
  // 8 trace figures (inline SVG) + Fig. 3 + Fig. 4 (PNG data URIs); no reference to another file.
  auto count = [&](const std::string& needle) {
    int n = 0;
    for (size_t at = html.find(needle); at != std::string::npos; at = html.find(needle, at + 1))
      ++n;
    return n;
  };
  EXPECT_EQ(count("<svg class=\"trace\""), 8);
  // I against amplitude beside the fit of the 4 traces with a sweep; a note for the 4 without.
  EXPECT_EQ(count("<svg class=\"sweep\""), 4);
  EXPECT_EQ(count("no amplitude sweep (the window holds 4.0 cycles)"), 4);
  EXPECT_EQ(html.find("missing)"), std::string::npos);
  {
    std::ifstream in(out + "/results.json");
    const nlohmann::json results = nlohmann::json::parse(in);
    int with_sweep = 0;
    for (const auto& t : results["traces"]) {
      const std::string name = t.value("sweep_figure", "");
      if (name.empty()) continue;
      ++with_sweep;
      EXPECT_TRUE(fs::exists(out + "/figures/" + name)) << name;
      EXPECT_NE(t.value("file", "").find("trial_1"), std::string::npos) << name;
    }
    EXPECT_EQ(with_sweep, 4);
  }
  EXPECT_EQ(count("src=\"data:image/png;base64,"), 2);
  // The figures' text is text (issue 25: PLplot's svg driver), no glyph outlines; every <use>
  // of every figure points at an id that exists in the page.
  EXPECT_EQ(html.find("<symbol"), std::string::npos);
  EXPECT_NE(html.find("<text"), std::string::npos);
  ExpectEveryHrefResolves(html);
  EXPECT_EQ(html.find("src=\"figures/"), std::string::npos);
  EXPECT_EQ(html.find("(no figure)"), std::string::npos);
  // The failed log is listed with its reason, escaped.
  EXPECT_NE(html.find("trial_&lt;3&gt;.csv"), std::string::npos);
  EXPECT_EQ(html.find("trial_<3>.csv"), std::string::npos);
  // Warnings (issue 18): the warned trace says so in the status column, is listed in the
  // Warnings section with its text, and its caption carries the text; under units: imperial
  // the text's 0.0058 kg m^2 is shown as 0.0058 / 1.35582 = 0.00428 slug ft^2.
  EXPECT_EQ(count(">ok (warned)</a>"), 1);
  EXPECT_EQ(count("<tr class=\"warned\">"), 2);  // the Warnings row and the traces row
  const size_t warnings = html.find("<h2 id=\"warnings\">Warnings</h2>");
  ASSERT_NE(warnings, std::string::npos);
  const size_t after = html.find("<h2>", warnings + 1);
  const std::string section = html.substr(warnings, after - warnings);
  EXPECT_NE(section.find("1 fitted trace raised warnings"), std::string::npos) << section;
  EXPECT_NE(section.find("pitch_45/trial_2.csv"), std::string::npos) << section;
  EXPECT_NE(section.find("model-inadequacy std of 0.00428 slug ft^2"), std::string::npos)
      << section;
  EXPECT_EQ(html.find("None: every trace passed"), std::string::npos);
  EXPECT_EQ(count("warning: I depends on the amplitude"), 1);  // the trace's caption
  // One unit system: nothing in kg m^2 outside the config text (which names its SI keys).
  const std::string page = html.substr(0, html.find("<h2>Config used</h2>"));
  EXPECT_EQ(page.find("kg m"), std::string::npos);
  // The period and the small-angle inertia in each trace caption, in display units:
  // 1.01 * I_total / 1.35581795 slug ft^2.
  EXPECT_EQ(count(" &middot; T = 2.5000 s, small-angle I = "), 8);
  // `bifilar report` rebuilds the same page from results.json alone.
  fs::remove(out + "/report.html");
  RunReport(out);
  EXPECT_EQ(ReadFile(out + "/report.html"), html);
  EXPECT_THROW(RunReport(out + "/nowhere"), UserError);
  WriteFile(out + "/results.json", "{ broken");
  EXPECT_THROW(RunReport(out), UserError);
  fs::remove_all(fs::path(out).parent_path());
}

// Loads `html` in headless Chromium; fails on console errors; returns the screenshot's size.
uintmax_t ScreenshotInChromium(const std::string& html, const std::string& work_dir) {
  char tmpl[] = "/tmp/bifilar_chromium_XXXXXX";
  const std::string profile = mkdtemp(tmpl);
  const std::string shot = work_dir + "/screenshot.png", log = work_dir + "/chromium.log";
  std::error_code ec;
  fs::remove(shot, ec);
  const std::string command =
      "timeout 60 /usr/bin/chromium --headless --no-sandbox --disable-gpu --disable-quic "
      "--no-first-run --disable-background-networking --disable-component-update --disable-sync "
      "--user-data-dir=" +
      profile + " --enable-logging=stderr --v=0 --screenshot=" + shot +
      " --window-size=1200,4000 file://" + html + " > " + log + " 2>&1";
  EXPECT_EQ(std::system(command.c_str()), 0) << ReadFile(log);
  const std::string messages = ReadFile(log);
  // Console errors are logged as "CONSOLE(line)" / "Uncaught ..."; a broken data URI as
  // "Failed to load" / "ERR_".
  for (const char* bad : {"CONSOLE", "Uncaught", "Failed to load", "ERR_INVALID_URL"}) {
    EXPECT_EQ(messages.find(bad), std::string::npos) << bad << " in:\n" << messages;
  }
  fs::remove_all(profile, ec);
  return fs::exists(shot) ? fs::file_size(shot) : 0;
}

TEST(Report, LoadsInHeadlessChromiumWithoutConsoleErrors) {
  if (!fs::exists("/usr/bin/chromium")) GTEST_SKIP() << "/usr/bin/chromium not installed";
  const std::string out = MakeCampaign();
  // A 1200x4000 page with figures, not a blank one (a blank page is ~20 kB).
  EXPECT_GT(ScreenshotInChromium(out + "/report.html", out), 50000u);
  fs::remove_all(fs::path(out).parent_path());
}

TEST(Report, CommittedSampleReportLoadsInChromium) {
  const std::string html =
      std::string(BIFILAR_SOURCE_DIR) + "/sample_runs/prandtl_d/out/report.html";
  if (!fs::exists("/usr/bin/chromium")) GTEST_SKIP() << "/usr/bin/chromium not installed";
  if (!fs::exists(html)) GTEST_SKIP() << html << " not generated";
  // Every figure of the sample is embedded: 57 traces (inline SVG) + Fig. 3 + Fig. 4 (PNG).
  const std::string page = ReadFile(html);
  int traces = 0, images = 0;
  for (size_t at = page.find("<svg class=\"trace\""); at != std::string::npos;
       at = page.find("<svg class=\"trace\"", at + 1)) {
    ++traces;
  }
  for (size_t at = page.find("<img "); at != std::string::npos; at = page.find("<img ", at + 1)) {
    ++images;
  }
  EXPECT_EQ(traces, 57);
  EXPECT_EQ(images, 2);
  // Issue 18: at most 2 MB for 57 traces (was ~8 MB: SVG paths and glyphs simplified, shared).
  EXPECT_LE(page.size(), 2u * 1024 * 1024);
  ExpectEveryHrefResolves(page);
  // pitch_20/trial_2 has an amplitude-trend warning: listed, and flagged in the traces table.
  const size_t warnings = page.find("<h2 id=\"warnings\">Warnings</h2>");
  ASSERT_NE(warnings, std::string::npos);
  const std::string section = page.substr(warnings, page.find("<h2>", warnings + 1) - warnings);
  EXPECT_NE(section.find("pitch_20/trial_2.csv.gz"), std::string::npos) << section;
  EXPECT_NE(page.find(">ok (warned)</a>"), std::string::npos);
  EXPECT_EQ(page.find("None: every trace passed"), std::string::npos);
  // units: imperial throughout (figure titles included): no kg m^2 before the config text.
  const std::string shown = page.substr(0, page.find("<h2>Config used</h2>"));
  EXPECT_EQ(shown.find("kg m"), std::string::npos);
  char tmpl[] = "/tmp/bifilar_sample_shot_XXXXXX";
  const std::string work = mkdtemp(tmpl);
  EXPECT_GT(ScreenshotInChromium(html, work), 50000u);
  fs::remove_all(work);
}

// issue 33 item 2: a results.json from someone else names figures outside its folder (`../`, an
// absolute path, a link leading out): `report` refuses it naming the key and the value, and no
// file outside is read, embedded or rewritten; the folder's own figures still work.
TEST(Report, FigureNamesOutsideTheFolderAreRefusedAndNothingIsTouched) {
  const std::string out = MakeCampaign();
  const std::string base = fs::path(out).parent_path().string();
  const std::string outside_svg =
      "<?xml version=\"1.0\"?>\n<!-- the user's own -->\n<svg xmlns=\"http://www.w3.org/2000/svg\" "
      "width=\"10\" height=\"10\"><text>outside</text></svg>\n";
  WriteFile(base + "/outside.svg", outside_svg);
  WriteFile(base + "/secret.txt", "the reader's secret");
  const std::string report_before = ReadFile(out + "/report.html");
  nlohmann::json results;
  {
    std::ifstream in(out + "/results.json");
    results = nlohmann::json::parse(in);
  }
  fs::create_symlink(base + "/outside.svg", out + "/figures/leaving.svg");
  struct Case {
    std::string key, value;
  };
  const std::vector<Case> cases = {{"figures.moments", "../../outside.svg"},
                                   {"figures.polar", base + "/secret.txt"},
                                   {"traces[0].figure", "leaving.svg"},
                                   {"traces[1].sweep_figure", "../report.html"}};
  for (const Case& c : cases) {
    nlohmann::json hostile = results;
    if (c.key == "figures.moments") hostile["figures"]["moments"] = c.value;
    if (c.key == "figures.polar") hostile["figures"]["polar"] = c.value;
    if (c.key == "traces[0].figure") hostile["traces"][0]["figure"] = c.value;
    if (c.key == "traces[1].sweep_figure") hostile["traces"][1]["sweep_figure"] = c.value;
    WriteFile(out + "/results.json", hostile.dump(1));
    try {
      RunReport(out);
      ADD_FAILURE() << c.key << " = " << c.value << " was accepted";
    } catch (const UserError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(c.key + " = \"" + c.value + "\""), std::string::npos) << message;
      EXPECT_NE(message.find("refused"), std::string::npos) << message;
    }
    EXPECT_EQ(ReadFile(base + "/outside.svg"), outside_svg) << c.key;
    EXPECT_EQ(ReadFile(base + "/secret.txt"), "the reader's secret") << c.key;
    EXPECT_EQ(ReadFile(out + "/report.html"), report_before) << c.key;
    EXPECT_TRUE(fs::is_symlink(out + "/figures/leaving.svg"));
    // The page built in `process` refuses the same names (no read through BuildReportHtml).
    EXPECT_THROW(BuildReportHtml(hostile, out), UserError) << c.key;
  }
  // The folder's own names: the report is built as before.
  WriteFile(out + "/results.json", results.dump(1));
  EXPECT_NO_THROW(RunReport(out));
  EXPECT_NE(ReadFile(out + "/report.html").find("<svg class=\"trace\""), std::string::npos);
  fs::remove_all(base);
}

}  // namespace
}  // namespace bifilar
