// yamlQuoted (the monitor's result file): any text, written as a YAML double-quoted scalar, reads
// back as itself through an independent YAML parser (yaml-cpp), whatever it holds.
#include <gtest/gtest.h>

#include <string>

#include <yaml-cpp/yaml.h>

#include "variational_formation_core/common/yaml_text.hpp"

namespace vf {
namespace {

/// `text` written as a result file line "key: <quoted>" and loaded again.
std::string readBack(const std::string& text) {
  const YAML::Node file = YAML::Load("result: failed\nreason: " + yamlQuoted(text) + "\ndropped: 0\n");
  EXPECT_EQ(file["result"].as<std::string>(), "failed");  // the lines around it are intact
  EXPECT_EQ(file["dropped"].as<int>(), 0);
  return file["reason"].as<std::string>();
}

TEST(YamlQuoted, PlainTextIsOnlyQuoted) {
  EXPECT_EQ(yamlQuoted("converged to the desired shape at step 472"),
            "\"converged to the desired shape at step 472\"");
  EXPECT_EQ(yamlQuoted(""), "\"\"");
}

TEST(YamlQuoted, EveryAsciiCharacterReadsBack) {
  std::string all;
  for (int c = 1; c < 128; ++c) all += static_cast<char>(c);
  EXPECT_EQ(readBack(all), all);
}

TEST(YamlQuoted, QuotesBackslashesAndLineBreaksReadBack) {
  for (const std::string& text :
       {std::string("a \"quoted\" word"), std::string("C:\\runs\\new\\tab"), std::string("ends with a backslash\\"),
        std::string("\\\""), std::string("two\nlines\r\n\tand a tab"), std::string("key: value # not a comment"),
        std::string("- [not, a, list]"), std::string("{not: a map}"), std::string("'single'"),
        std::string("&anchor *alias !tag %directive @ `"), std::string("   spaces around   "),
        std::string("null"), std::string("~"), std::string("1e3"), std::string("true")}) {
    EXPECT_EQ(readBack(text), text) << yamlQuoted(text);
  }
}

TEST(YamlQuoted, ControlCharactersAreEscaped) {
  const std::string text = std::string("bell\a nul") + '\0' + "del\x7f" + "esc\x1b";
  const std::string quoted = yamlQuoted(text);
  for (char c : quoted) {
    EXPECT_FALSE((static_cast<unsigned char>(c) < 0x20) || c == 0x7f) << "raw control character in " << quoted;
  }
  EXPECT_EQ(readBack(text), text);
}

TEST(YamlQuoted, Utf8KeptAndInvalidBytesReplaced) {
  const std::string text = "agent \xC3\xA9t\xC3\xA9 \xE2\x86\x92 \xF0\x9F\x9A\x80";  // été → 🚀
  EXPECT_EQ(yamlQuoted(text), "\"" + text + "\"");
  EXPECT_EQ(readBack(text), text);
  const std::string replacement = "\xEF\xBF\xBD";  // U+FFFD in UTF-8
  // A lone continuation byte, a truncated sequence, an overlong '/', a surrogate, a lead byte
  // past U+10FFFF: each invalid byte becomes one replacement character.
  EXPECT_EQ(readBack("a\x80z"), "a" + replacement + "z");
  EXPECT_EQ(readBack("cut \xE2\x86"), "cut " + replacement + replacement);
  EXPECT_EQ(readBack("\xC0\xAF"), replacement + replacement);
  EXPECT_EQ(readBack("\xED\xA0\x80"), replacement + replacement + replacement);
  EXPECT_EQ(readBack("\xF5\x80\x80\x80"), replacement + replacement + replacement + replacement);
}

}  // namespace
}  // namespace vf
