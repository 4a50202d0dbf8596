// core::first_invalid_utf8 against hand-written byte sequences (RFC 3629's well-formed ranges),
// and ConfigNode::as_string, which refuses text that is not UTF-8 at its file:line:key.
#include <gtest/gtest.h>

#include <string>

#include "config_error_of.hpp"
#include "spidar/core/config.hpp"
#include "spidar/core/utf8.hpp"

namespace spidar::core {
namespace {

using testing::error_of;

TEST(Utf8, WellFormedTextHasNoInvalidByte) {
  EXPECT_FALSE(first_invalid_utf8("").has_value());
  EXPECT_FALSE(first_invalid_utf8("SPIDAR-8, left hand").has_value());
  EXPECT_FALSE(first_invalid_utf8("\xC3\xA9t\xC3\xA9").has_value());                   // été (2 bytes)
  EXPECT_FALSE(first_invalid_utf8("\xE2\x82\xAC \xE2\x89\xA4 \xC2\xB5").has_value());  // € ≤ µ (3, 2)
  EXPECT_FALSE(first_invalid_utf8("\xF0\x9F\x96\x90").has_value());                   // U+1F590 (4)
  EXPECT_FALSE(first_invalid_utf8("\xF4\x8F\xBF\xBF").has_value());                   // U+10FFFF, the last
  EXPECT_FALSE(first_invalid_utf8("\xED\x9F\xBF").has_value());                       // U+D7FF, before the surrogates
}

TEST(Utf8, FindsTheFirstByteThatIsNot) {
  EXPECT_EQ(first_invalid_utf8("\xFF\xFE\xC3\x28"), 0u);       // bytes UTF-8 never uses
  EXPECT_EQ(first_invalid_utf8("ab\x80"), 2u);                 // a continuation byte alone
  EXPECT_EQ(first_invalid_utf8("ab\xC3\x28"), 2u);             // a lead byte without its continuation
  EXPECT_EQ(first_invalid_utf8("ab\xE2\x82"), 2u);             // cut short at the end
  EXPECT_EQ(first_invalid_utf8("\xC0\xAF"), 0u);               // overlong '/'
  EXPECT_EQ(first_invalid_utf8("x\xE0\x80\xAF"), 1u);          // overlong, 3 bytes
  EXPECT_EQ(first_invalid_utf8("xy\xF0\x80\x80\xAF"), 2u);     // overlong, 4 bytes
  EXPECT_EQ(first_invalid_utf8("\xED\xA0\x80"), 0u);           // U+D800, a surrogate
  EXPECT_EQ(first_invalid_utf8("\xF4\x90\x80\x80"), 0u);       // U+110000, beyond Unicode
  EXPECT_EQ(first_invalid_utf8("\xF5\x80\x80\x80"), 0u);
  EXPECT_EQ(first_invalid_utf8(std::string("ok\0\xC3\xA9\xFF", 6)), 5u);  // NUL is ASCII
}

TEST(Utf8, ConfigTextThatIsNotUtf8IsRefusedAtItsKey) {
  auto root = ConfigNode::Parse("name: SPIDAR-8\nother: \xC3\xA9t\xC3\xA9\nbad: ab\xFF\n", "f.yaml");
  EXPECT_EQ(root["name"].as_string(), "SPIDAR-8");
  EXPECT_EQ(root["other"].as_string(), "\xC3\xA9t\xC3\xA9");
  EXPECT_EQ(error_of([&] { root["bad"].as_string(); }), "f.yaml:3: bad: expected UTF-8 text, got byte 0xFF at offset 2");
}

}  // namespace
}  // namespace spidar::core
