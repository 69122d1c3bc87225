// One line per warning (issue 24, "two summaries of a warning"): the console of `bifilar process`
// and report.html show the same line for the same warning, LineOfWarning
// (pipeline/records/trace_record.h): the warning's first sentence and, when that does not hold
// the clause saying what to do, the clause after it. Checked on the real warnings the sample
// campaign's fits raise, through the binary, and on warning texts the fit has written.
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "pipeline/records/trace_record.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::Bifilar;
using test_support::ReadFile;
using test_support::TempDir;

// Page text back to the console's: tags out, "&rarr;" as "->", entities decoded.
std::string PlainText(std::string html) {
  for (size_t at = html.find(" &rarr; "); at != std::string::npos; at = html.find(" &rarr; ", at)) {
    html.replace(at, 8, " -> ");
  }
  std::string out;
  bool in_tag = false;
  for (char c : html) {
    if (c == '<') in_tag = true;
    if (!in_tag) out += c;
    if (c == '>') in_tag = false;
  }
  for (const auto& [entity, text] : std::vector<std::pair<std::string, std::string>>{
           {"&lt;", "<"}, {"&gt;", ">"}, {"&quot;", "\""}, {"&amp;", "&"}}) {
    for (size_t at = out.find(entity); at != std::string::npos; at = out.find(entity, at + 1)) {
      out.replace(at, entity.size(), text);
    }
  }
  return out;
}

// The report's Warnings table: file -> the line of each warning (the <summary> of a folded one,
// else its paragraph).
std::map<std::string, std::vector<std::string>> ReportLines(const std::string& html) {
  std::map<std::string, std::vector<std::string>> out;
  const size_t start = html.find("<table class=\"warnings\">");
  const size_t end = html.find("</table>", start);
  for (size_t row = html.find("<tr class=\"warned\">", start); row < end;
       row = html.find("<tr class=\"warned\">", row + 1)) {
    const size_t file_at = html.find("<td class=\"l\">", row) + 14;
    const std::string file = html.substr(file_at, html.find("</td>", file_at) - file_at);
    const size_t cell = html.find("<td class=\"l w\">", row),
                 cell_end = html.find("</td></tr>", cell);
    for (size_t at = cell; at < cell_end;) {
      const size_t details = html.find("<details><summary>", at), paragraph = html.find("<p>", at);
      if (details < cell_end && details <= paragraph) {
        const size_t from = details + 18, to = html.find("</summary>", from);
        out[file].push_back(PlainText(html.substr(from, to - from)));
        at = html.find("</details>", to);
      } else if (paragraph < cell_end) {
        const size_t from = paragraph + 3, to = html.find("</p>", from);
        out[file].push_back(PlainText(html.substr(from, to - from)));
        at = to;
      } else {
        break;
      }
    }
  }
  return out;
}

// The console's block "Warnings of N traces": file -> its "    warning: LINE" lines.
std::map<std::string, std::vector<std::string>> ConsoleLines(const std::string& console) {
  std::map<std::string, std::vector<std::string>> out;
  std::string file;
  size_t at = console.find("\nWarnings of ");
  for (at = console.find('\n', at + 1); at != std::string::npos && at + 1 < console.size();) {
    const size_t next = console.find('\n', at + 1);
    const std::string line = console.substr(at + 1, next - at - 1);
    at = next;
    if (line.rfind("    warning: ", 0) == 0) {
      out[file].push_back(line.substr(13));
    } else if (line.rfind("  ", 0) == 0 && line.size() > 2 && line[2] != ' ') {
      file = line.substr(2, line.rfind(" (") - 2);
    } else {
      break;
    }
  }
  return out;
}

TEST(ReportWarnings, TheSampleShowsTheSameLineOnTheConsoleAndInTheReport) {
  TempDir dir("bifilar_report_warnings");
  const std::string config = std::string(BIFILAR_SOURCE_DIR) + "/configs/prandtl_d.yaml";
  const test_support::CliRun run =
      Bifilar(dir, "process " + config + " --out " + dir.path + "/out");
  ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
  const auto console = ConsoleLines(run.out);
  const auto report = ReportLines(ReadFile(dir.path + "/out/report.html"));
  // The sample's fits warn on 5 traces: a damping term at its bound, an amplitude trend.
  ASSERT_EQ(report.size(), 5u) << run.out;
  EXPECT_EQ(report, console) << run.out;
  bool damping = false, trend = false;
  for (const auto& [file, lines] : report) {
    for (const std::string& line : lines) {
      damping = damping || line.find("at its bound): the damping is all in") != std::string::npos;
      trend = trend || line.find("I changes with amplitude") != std::string::npos;
      // The line says what to do (its first sentence holds the clause).
      // The sample's config sets fit.max_amplitude_deg: the advice lowers it, never "set" it.
      EXPECT_TRUE(line.find("; fit a longer window") != std::string::npos ||
                  line.find("; log a longer swing") != std::string::npos ||
                  line.find("swing lower, or lower fit.max_amplitude_deg") != std::string::npos)
          << line;
      EXPECT_EQ(line.find("set fit.max_amplitude_deg"), std::string::npos) << line;
    }
  }
  EXPECT_TRUE(damping && trend);
}

// Warning texts the fit has written (this version's and 0.2.0's): the line keeps what to do.
TEST(ReportWarnings, TheLineHoldsWhatToDo) {
  // The first sentence holds the action: the line is that sentence.
  const std::string damping =
      "C = 0 (linear damping at its bound): the damping is all in K_D here; fit a longer window "
      "(fit.windows or --window) to separate them. The fit holds C at 0, where the data asked "
      "for a negative linear damping; I depends little on how the damping is split.";
  EXPECT_EQ(LineOfWarning(damping).Text(),
            "C = 0 (linear damping at its bound): the damping is all in K_D here; fit a longer "
            "window (fit.windows or --window) to separate them");
  EXPECT_TRUE(LineOfWarning(damping).folded);
  // 0.2.0's amplitude warning: a first sentence of 325 characters, the action after it.
  const std::string trend =
      "I depends on the amplitude beyond its statistical error (+0.127 % per 10 deg between 24.5 "
      "and 28.8 deg, z = 4.1, I_0 (1 + c A^2) fits best): the rig departs from the ideal model; I "
      "is taken from the lowest-amplitude band (24.5 deg) with a model-inadequacy std of 0.0058 "
      "kg m^2 (the trend's change from that amplitude to zero). Swing at smaller amplitude, or "
      "set fit.max_amplitude_deg";
  const WarningLine line = LineOfWarning(trend);
  EXPECT_EQ(line.action, "Swing at smaller amplitude, or set fit.max_amplitude_deg");
  EXPECT_EQ(line.Text(),
            "I depends on the amplitude beyond its statistical error (+0.127 % per 10 deg ... -> "
            "Swing at smaller amplitude, or set fit.max_amplitude_deg");
  EXPECT_LE(line.Text().size(), kWarningLineChars);
  // A short warning with nothing more to it: the whole text, not folded.
  const std::string footer =
      "the time series ends at line 243 (a blank line, then a "
      "non-numeric row); 3 row(s) after it (a footer?) are ignored";
  EXPECT_EQ(LineOfWarning(footer).Text(), footer);
  EXPECT_FALSE(LineOfWarning(footer).folded);
  EXPECT_EQ(WarningAction("not observable from these swing axes: Ixy; swing about axes that mix "
                          "them to measure them"),
            "swing about axes that mix them to measure them");
}

}  // namespace
}  // namespace bifilar
