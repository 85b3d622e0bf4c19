// first_invalid_utf8: well-formed text of every length class passes; each way a byte sequence
// can fail to be UTF-8 is found at its first byte.
#include "kinograph/dynamics/utf8.h"

#include <gtest/gtest.h>

#include <string>

namespace kinograph::dynamics {
namespace {

TEST(Utf8, WellFormedTextOfEveryLength) {
  EXPECT_EQ(first_invalid_utf8(""), std::nullopt);
  EXPECT_EQ(first_invalid_utf8("plain ascii\n"), std::nullopt);
  EXPECT_EQ(first_invalid_utf8("ü é"), std::nullopt);     // two bytes
  EXPECT_EQ(first_invalid_utf8("机器人 €"), std::nullopt);  // three bytes
  EXPECT_EQ(first_invalid_utf8("🎱 \xf4\x8f\xbf\xbf"), std::nullopt);  // four, up to U+10FFFF
}

TEST(Utf8, EachMalformationIsFoundAtItsFirstByte) {
  EXPECT_EQ(first_invalid_utf8("ab\xda"), 2u);              // ends inside a character
  EXPECT_EQ(first_invalid_utf8("a\xe6\x9c"), 1u);           // truncated three-byte
  EXPECT_EQ(first_invalid_utf8("ab\x80"), 2u);              // stray continuation byte
  EXPECT_EQ(first_invalid_utf8("\xc3\x28"), 0u);            // lead without continuation
  EXPECT_EQ(first_invalid_utf8("x\xc0\xaf"), 1u);           // overlong '/'
  EXPECT_EQ(first_invalid_utf8("xy\xe0\x80\xaf"), 2u);      // overlong, three bytes
  EXPECT_EQ(first_invalid_utf8("\xed\xa0\x80"), 0u);        // surrogate U+D800
  EXPECT_EQ(first_invalid_utf8("é\xf4\x90\x80\x80"), 2u);   // past U+10FFFF
  EXPECT_EQ(first_invalid_utf8("\xff"), 0u);                // never a lead byte
}

TEST(Utf8, LineAtCountsNewlinesBefore) {
  const std::string text = "a\nb\n\nc";
  EXPECT_EQ(line_at(text, 0), 1);
  EXPECT_EQ(line_at(text, 2), 2);
  EXPECT_EQ(line_at(text, 5), 4);
  EXPECT_EQ(line_at(text, 100), 4);
}

}  // namespace
}  // namespace kinograph::dynamics
