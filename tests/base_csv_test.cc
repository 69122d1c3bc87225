// base/csv.h: the one CSV splitter (RFC 4180, section 2) and the one whole-field number parser.
// The splitter is scored on the RFC's own cases (quoted fields, doubled quotes, delimiters and
// line breaks inside quotes, CRLF, empty fields) and on the lenient rules csv.h states for text
// the RFC calls malformed; the parser on each rule of its policy.
#include "base/csv.h"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace bifilar {
namespace {

using Fields = std::vector<std::string>;

TEST(SplitCsvRecord, PlainFieldsAndEmptyOnes) {
  EXPECT_EQ(SplitCsvRecord("aaa,bbb,ccc"), (Fields{"aaa", "bbb", "ccc"}));
  EXPECT_EQ(SplitCsvRecord(""), (Fields{""}));  // an empty record is one empty field
  EXPECT_EQ(SplitCsvRecord(","), (Fields{"", ""}));
  EXPECT_EQ(SplitCsvRecord("a,,b,"), (Fields{"a", "", "b", ""}));  // trailing delimiter
  EXPECT_EQ(SplitCsvRecord(",a"), (Fields{"", "a"}));
  EXPECT_EQ(SplitCsvRecord("\"\",x"), (Fields{"", "x"}));  // a quoted empty field
}

TEST(SplitCsvRecord, QuotedFieldsHoldDelimitersQuotesAndLineBreaks) {
  // RFC 4180 section 2, rules 5-7.
  EXPECT_EQ(SplitCsvRecord("\"aaa\",\"bbb\",\"ccc\""), (Fields{"aaa", "bbb", "ccc"}));
  EXPECT_EQ(SplitCsvRecord("\"a,b\",c"), (Fields{"a,b", "c"}));
  EXPECT_EQ(SplitCsvRecord("\"a\"\"b\",c"), (Fields{"a\"b", "c"}));  // "" is one quote
  EXPECT_EQ(SplitCsvRecord("\"\"\"\""), (Fields{"\""}));             // a field that is one quote
  EXPECT_EQ(SplitCsvRecord("\"b\r\nbb\",c"), (Fields{"b\r\nbb", "c"}));  // line break inside
  EXPECT_EQ(SplitCsvRecord("\"x;y\";z", ';'), (Fields{"x;y", "z"}));     // another delimiter
}

TEST(SplitCsvRecord, RecordEndAndSpaces) {
  // CRLF (RFC 4180 rule 1) or LF at the end is not part of the last field, nor a lone CR (a
  // CRLF file read with std::getline).
  EXPECT_EQ(SplitCsvRecord("a,b\r\n"), (Fields{"a", "b"}));
  EXPECT_EQ(SplitCsvRecord("a,b\n"), (Fields{"a", "b"}));
  EXPECT_EQ(SplitCsvRecord("a,b\r"), (Fields{"a", "b"}));
  EXPECT_EQ(SplitCsvRecord("a,\r\n"), (Fields{"a", ""}));
  EXPECT_EQ(SplitCsvRecord("a,\"b\"\r\n"), (Fields{"a", "b"}));
  // Spaces are part of a field (rule 4).
  EXPECT_EQ(SplitCsvRecord(" a , b "), (Fields{" a ", " b "}));
  EXPECT_EQ(SplitCsvRecord("a\tb,c", '\t'), (Fields{"a", "b,c"}));
}

TEST(SplitCsvRecord, MalformedTextIsReadLeniently) {
  // A quote inside an unquoted field is text; text after a closing quote is appended; an
  // unterminated quoted field runs to the end of the record.
  EXPECT_EQ(SplitCsvRecord("ab\"c,d"), (Fields{"ab\"c", "d"}));
  EXPECT_EQ(SplitCsvRecord("\"ab\"c,d"), (Fields{"abc", "d"}));
  EXPECT_EQ(SplitCsvRecord("\"ab,c"), (Fields{"ab,c"}));
}

TEST(ParseNumber, WholeFieldOnly) {
  double v = 0;
  EXPECT_TRUE(ParseNumber("1.5", &v));
  EXPECT_EQ(v, 1.5);
  EXPECT_TRUE(ParseNumber("-2e-3", &v));
  EXPECT_EQ(v, -2e-3);
  EXPECT_TRUE(ParseNumber("+7", &v));
  EXPECT_EQ(v, 7.0);
  EXPECT_TRUE(ParseNumber(".5", &v));
  EXPECT_EQ(v, 0.5);
  EXPECT_TRUE(ParseNumber("1.", &v));
  EXPECT_EQ(v, 1.0);
  EXPECT_TRUE(ParseNumber("-0", &v));
  EXPECT_TRUE(std::signbit(v));
  // The correctly rounded double, as strtod gives it.
  EXPECT_TRUE(ParseNumber("0.1", &v));
  EXPECT_EQ(v, 0.1);
  EXPECT_TRUE(ParseNumber("2.2250738585072014e-308", &v));
  EXPECT_EQ(v, std::numeric_limits<double>::min());
  for (const char* text :
       {"", "+", "-", "1.5x", "1,5", "1e", "1e+", "x1", "++1", "+-1", "--1", "1 2", ".", "e5"}) {
    EXPECT_FALSE(ParseNumber(text, &v)) << text;
  }
}

TEST(ParseNumber, WhiteSpaceIsTheCallersToTrim) {
  double v = 0;
  for (const char* text : {" 1", "1 ", "\t1", "1\r", "1\n", " "}) {
    EXPECT_FALSE(ParseNumber(text, &v)) << "'" << text << "'";
  }
}

TEST(ParseNumber, InfinityAndNanRefusedUnlessAsked) {
  double v = 0;
  for (const char* text :
       {"inf", "-inf", "+inf", "infinity", "INF", "nan", "NaN", "1e400", "-1e400"}) {
    EXPECT_FALSE(ParseNumber(text, &v)) << text;
    EXPECT_TRUE(ParseNumber(text, &v, NonFinite::kAccept)) << text;
    EXPECT_FALSE(std::isfinite(v)) << text;
  }
  EXPECT_TRUE(ParseNumber("1e308", &v));  // the largest decades are finite
  EXPECT_EQ(v, 1e308);
}

TEST(ParseNumber, SubnormalsAreReadAndUnderflowIsZero) {
  double v = 0;
  EXPECT_TRUE(ParseNumber("4.9406564584124654e-324", &v));
  EXPECT_EQ(v, std::numeric_limits<double>::denorm_min());
  EXPECT_TRUE(ParseNumber("1e-310", &v));
  EXPECT_EQ(v, 1e-310);
  EXPECT_GT(v, 0.0);
  EXPECT_LT(v, std::numeric_limits<double>::min());
  EXPECT_TRUE(ParseNumber("1e-400", &v));
  EXPECT_EQ(v, 0.0);
}

TEST(ParseNumber, HexadecimalIsRefused) {
  double v = 0;
  for (const char* text : {"0x10", "0X1p3", "0x1.8p1", "-0x2"}) {
    EXPECT_FALSE(ParseNumber(text, &v)) << text;
    EXPECT_FALSE(ParseNumber(text, &v, NonFinite::kAccept)) << text;
  }
}

}  // namespace
}  // namespace bifilar
