#include "softsight/io/csv_reader.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/test_util.h"
#include "softsight/core/error.h"

namespace softsight {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using testing::TempDir;
using testing::WriteTextFile;

CsvTable ReadText(const TempDir& dir, const std::string& text) {
  WriteTextFile(dir.file("in.csv"), text);
  return ReadCsvTable(dir.file("in.csv"));
}

std::string ErrorOf(const TempDir& dir, const std::string& text) {
  try {
    ReadText(dir, text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(CsvReader, ReadsSoftsightsOwnPlainFields) {
  TempDir dir;
  const CsvTable table = ReadText(dir, "frame,time_s,red_x,red_status\n0,0.000000,12.5,found\n"
                                       "1,0.033333,,lost\n");
  EXPECT_THAT(table.columns, ElementsAre("frame", "time_s", "red_x", "red_status"));
  ASSERT_EQ(table.row_count(), 2u);
  EXPECT_EQ(table.values[0][1], 1.0);
  EXPECT_EQ(table.values[2][0], 12.5);
  EXPECT_FALSE(table.values[2][1].has_value()) << "an empty field is absent";
  EXPECT_FALSE(table.values[3][0].has_value()) << "a status is a word, not a number";
}

// RFC 4180, as a spreadsheet or Python's csv.writer(quoting=QUOTE_ALL) writes it: the issue's
// "column \"frame\": '\"0\"' is not a number".
TEST(CsvReader, QuotedFieldsAreTheirContents) {
  TempDir dir;
  const CsvTable table =
      ReadText(dir, "\"frame\",\"time_s\",\"note_status\"\r\n\"0\",\"0.5\",\"a, b\"\r\n"
                    "\"1\",\"\",\"say \"\"hi\"\"\"\r\n");
  EXPECT_THAT(table.columns, ElementsAre("frame", "time_s", "note_status"));
  ASSERT_EQ(table.row_count(), 2u);
  EXPECT_EQ(table.values[0][0], 0.0);
  EXPECT_EQ(table.values[0][1], 1.0);
  EXPECT_EQ(table.values[1][0], 0.5);
  EXPECT_FALSE(table.values[1][1].has_value()) << "a quoted empty field is empty";
}

TEST(CsvReader, CommasQuotesAndNewlinesInsideQuotesStayInTheField) {
  TempDir dir;
  // A header name with a comma, a doubled quote and a newline, then a number after it.
  const CsvTable table =
      ReadText(dir, "\"a,b\",\"say \"\"x\"\"\",\"two\nlines\",y\n1,2,3,4\n5,6,7,8\n");
  EXPECT_THAT(table.columns, ElementsAre("a,b", "say \"x\"", "two\nlines", "y"));
  ASSERT_EQ(table.row_count(), 2u);
  EXPECT_EQ(table.values[3][0], 4.0);
  EXPECT_EQ(table.values[0][1], 5.0);
}

TEST(CsvReader, LinesInMessagesCountTheNewlinesInsideQuotes) {
  TempDir dir;
  // The header spans lines 1-2, so the bad row is line 4.
  EXPECT_THAT(ErrorOf(dir, "\"fra\nme\",x\n1,2\n3,oops\n"),
              HasSubstr("in.csv:4: column x: 'oops' is not a number"));
}

TEST(CsvReader, SpacesAroundFieldsAndTheUtf8MarkAreNotPartOfThem) {
  TempDir dir;
  const CsvTable table = ReadText(dir, "\xEF\xBB\xBF" "frame, x\n 0 , \"2.5\" \n\n1,3\n");
  EXPECT_THAT(table.columns, ElementsAre("frame", "x"));
  ASSERT_EQ(table.row_count(), 2u) << "a blank line is no row";
  EXPECT_EQ(table.values[1][0], 2.5);
  EXPECT_EQ(table.values[1][1], 3.0);
}

TEST(CsvReader, BrokenQuotingIsOneLineNamingWhere) {
  TempDir dir;
  EXPECT_THAT(ErrorOf(dir, "a,b\n1,\"2\n"),
              HasSubstr("in.csv:2: field 2: a quoted field is not closed"));
  EXPECT_THAT(ErrorOf(dir, "a,b\n1,\"2\"3\n"),
              HasSubstr("in.csv:2: field 2: text after a quoted field's closing '\"'"));
  // A comma inside quotes does not split the field: two fields, the second not a number.
  EXPECT_THAT(ErrorOf(dir, "a,b\n1,\"2,3\"\n"),
              HasSubstr("in.csv:2: column b: '2,3' is not a number"));
  EXPECT_THAT(ErrorOf(dir, "a,b\n1,2,3\n"), HasSubstr("in.csv:2: expected 2 fields, found 3"));
}

}  // namespace
}  // namespace softsight
