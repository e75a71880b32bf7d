// How diagnostics quote what a file or the user wrote: file names and words with control bytes,
// escape sequences and invalid UTF-8 written as escapes, never raw on the terminal.
#include "glint/readers/diagnostics.h"
#include "glint/readers/spelling.h"

#include <gtest/gtest.h>

#include <map>
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

const std::string kLongName(100000, 'x');

// The did-you-mean search reads every defined name: only the first kMaxNameHints undefined names
// of a kind get one (thousands of undefined names among thousands of definitions took minutes);
// the rest get the list of defined names, and "no ... defined" is always said. A word longer than
// a name may be says so.
TEST(Spelling, UndefinedNamesGetHintsWithinABudget) {
  const std::map<std::string, int> names = {{"glass", 0}, {"steel", 1}, {kLongName, 2}};
  int hintsLeft = kMaxNameHints;
  for (int i = 0; i < kMaxNameHints; ++i) {
    EXPECT_EQ(undefinedNameHint("glas", names, "; none", hintsLeft), " (did you mean 'glass'?)");
  }
  EXPECT_EQ(hintsLeft, 0);
  EXPECT_EQ(undefinedNameHint("glas", names, "; none", hintsLeft),
            "; defined: glass, steel, " + std::string(40, 'x') + "...");
  EXPECT_EQ(undefinedNameHint("glas", std::map<std::string, int>(), "; none", hintsLeft), "; none");
  EXPECT_EQ(undefinedNameHint(std::string(257, 'g'), names, "; none", hintsLeft),
            "; names are at most 256 bytes");
  EXPECT_EQ(closestName(std::string(kLongName).substr(1), names), "");
}

}  // namespace
}  // namespace glint
