// The one rule that cuts a log line into cells (pipeline/logs/log_line.h), shared by the reader,
// the format guess and a watched stream: quotes trimmed, not interpreted; runs of spaces and tabs
// one separator when the delimiter is ' '; carriage returns are padding.
#include "pipeline/logs/log_line.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace bifilar {
namespace {

TEST(LogLine, CommaCellsAreUnquotedAndTrimmed) {
  const std::vector<std::string> cells = LogLineCells(" \"t\" , 'gx',gy ,\"g z\"\r", ',');
  ASSERT_EQ(cells.size(), 4u);
  EXPECT_EQ(cells[0], "t");
  EXPECT_EQ(cells[1], "gx");
  EXPECT_EQ(cells[2], "gy");
  EXPECT_EQ(cells[3], "g z");  // a logger's quotes hold a name, kept whole
}

TEST(LogLine, SpacesAndTabsAreOneSeparator) {
  const std::vector<std::string> cells = LogLineCells("  0.01\t 0.5   -0.25\t\r", ' ');
  ASSERT_EQ(cells.size(), 3u);
  EXPECT_EQ(cells[0], "0.01");
  EXPECT_EQ(cells[1], "0.5");
  EXPECT_EQ(cells[2], "-0.25");
}

TEST(LogLine, EmptyCellsAndUnmatchedQuotesStay) {
  const std::vector<std::string> cells = LogLineCells("1,,\"x,'y'", ',');
  ASSERT_EQ(cells.size(), 4u);
  EXPECT_EQ(cells[1], "");
  EXPECT_EQ(cells[2], "\"x");  // unmatched: not a quoted name, left as it is
  EXPECT_EQ(cells[3], "y");
  std::vector<std::string_view> fields;
  SplitLogLine("a;b", ';', &fields);
  ASSERT_EQ(fields.size(), 2u);
  EXPECT_EQ(fields[1], "b");
  EXPECT_EQ(UnquoteLogCell("  ' gx '  "), "gx");
}

}  // namespace
}  // namespace bifilar
