// Writing the command line's messages to stdout or stderr.
#pragma once

#include <cstdio>
#include <string_view>

namespace glint::cli {

// Writes without throwing (unlike fmt::print to a FILE*): a closed or full stderr must not turn a
// finished render into a failure, so a failed write of a message is ignored.
inline void emit(std::FILE* stream, std::string_view text) {
  std::fwrite(text.data(), 1, text.size(), stream);
  std::fflush(stream);
}

}  // namespace glint::cli
