#include "glint/mesh/file_fault.h"

#include <charconv>
#include <system_error>

namespace glint {

bool isNumberWord(std::string_view word) {
  if (!word.empty() && (word[0] == '-' || word[0] == '+')) word.remove_prefix(1);
  if (word.empty() || word[0] == '-' || word[0] == '+') return false;
  double value = 0;
  const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
  return end == word.data() + word.size() &&
         (error == std::errc{} || error == std::errc::result_out_of_range);
}

}  // namespace glint
