// How diagnostics quote what a file or the user wrote: file names and words with control bytes,
// escape sequences and invalid UTF-8 written as escapes, never raw on the terminal.
#include "glint/readers/diagnostics.h"

#include <gtest/gtest.h>

#include <string>

namespace glint {
namespace {

TEST(Diagnostics, AFileNameIsShownWithItsControlBytesEscaped) {
  const Diagnostic error{Diagnostic::Severity::Error, {"e\x1b[31mred\xe9.ply", 6, 1}, "bad"};
  EXPECT_EQ(error.format(), "e\\x1b[31mred\\xe9.ply:6:1: bad");
  const Diagnostic warning{Diagnostic::Severity::Warning, {"scène.yaml", 0, 0}, "note"};
  EXPECT_EQ(warning.format(), "scène.yaml: warning: note");  // valid UTF-8 stays as written
}

TEST(Diagnostics, QuotedWordsAreEscapedAndShortenedWithoutCuttingACharacter) {
  EXPECT_EQ(quoteForMessage("1x"), "'1x'");
  EXPECT_EQ(quoteForMessage("a\tb\nc\x7f"), "'a\\tb\\nc\\x7f'");
  const std::string long_word = std::string(39, 'a') + "é" + "zzz";
  EXPECT_EQ(quoteForMessage(long_word), "'" + std::string(39, 'a') + "é...'");
}

}  // namespace
}  // namespace glint
