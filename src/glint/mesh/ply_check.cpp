#include "glint/mesh/ply_check.h"

#include <fmt/format.h>

#include <charconv>
#include <cstdint>
#include <cstring>
#include <vector>

#include "glint/mesh/file_fault.h"
#include "glint/readers/diagnostics.h"

namespace glint {
namespace {

enum class Format { Ascii, BinaryLittle, BinaryBig };

struct PlyType {
  std::size_t bytes = 0;  // 0: not a PLY type
  bool isSigned = false;
  bool isFloat = false;
};

PlyType typeNamed(std::string_view name) {
  if (name == "char" || name == "int8") return {1, true, false};
  if (name == "uchar" || name == "uint8") return {1, false, false};
  if (name == "short" || name == "int16") return {2, true, false};
  if (name == "ushort" || name == "uint16") return {2, false, false};
  if (name == "int" || name == "int32") return {4, true, false};
  if (name == "uint" || name == "uint32") return {4, false, false};
  if (name == "float" || name == "float32") return {4, true, true};
  if (name == "double" || name == "float64") return {8, true, true};
  return {};
}

struct Property {
  std::string name;
  bool list = false;
  PlyType countType;  // of a list
  PlyType type;       // of the value, or of a list's items
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

// The header's elements, its format and where the body starts; nothing when the header is not
// one checkPlyHeader takes (it has refused such a file before the child runs).
struct Header {
  Format format = Format::Ascii;
  std::vector<Element> elements;
  std::size_t bodyStart = 0;
  std::size_t bodyLine = 0;  // the body's first line (1-based)
};

std::optional<Header> readHeader(std::string_view file) {
  Header header;
  std::size_t at = 0;
  std::size_t line = 0;
  while (at < file.size()) {
    const std::size_t end = file.find('\n', at);
    const std::size_t next = end == std::string_view::npos ? file.size() : end + 1;
    std::string_view text = file.substr(at, next - at);
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.remove_suffix(1);
    ++line;
    at = next;
    // Words at spaces and tabs, as assimp splits header lines.
    std::vector<std::string_view> words;
    for (std::size_t i = 0; i < text.size();) {
      while (i < text.size() && (text[i] == ' ' || text[i] == '\t')) ++i;
      const std::size_t start = i;
      while (i < text.size() && text[i] != ' ' && text[i] != '\t') ++i;
      if (i > start) words.push_back(text.substr(start, i - start));
    }
    if (words.empty()) continue;
    if (words[0] == "format" && words.size() >= 2) {
      if (words[1] == "binary_little_endian") header.format = Format::BinaryLittle;
      if (words[1] == "binary_big_endian") header.format = Format::BinaryBig;
    } else if (words[0] == "element" && words.size() >= 3) {
      Element element;
      element.name = std::string(words[1]);
      const auto [ptr, error] =
          std::from_chars(words[2].data(), words[2].data() + words[2].size(), element.count);
      if (error != std::errc{}) return std::nullopt;
      header.elements.push_back(std::move(element));
    } else if (words[0] == "property" && words.size() >= 3 && !header.elements.empty()) {
      Property property;
      if (words[1] == "list") {
        if (words.size() < 5) return std::nullopt;
        property.list = true;
        property.countType = typeNamed(words[2]);
        property.type = typeNamed(words[3]);
        property.name = std::string(words[4]);
        if (property.countType.bytes == 0 || property.countType.isFloat) return std::nullopt;
      } else {
        property.type = typeNamed(words[1]);
        property.name = std::string(words[2]);
      }
      if (property.type.bytes == 0) return std::nullopt;
      header.elements.back().properties.push_back(std::move(property));
    } else if (words[0] == "end_header") {
      header.bodyStart = at;
      header.bodyLine = line + 1;
      return header;
    }
  }
  return std::nullopt;
}

std::string propertyNames(const Element& element) {
  std::string names;
  for (const Property& p : element.properties) {
    if (!names.empty()) names += ' ';
    names += p.list ? "(list " + p.name + ")" : p.name;
  }
  return names;
}

// "'face' 2 of 3": which instance of which element.
std::string instanceName(const Element& element, std::uint64_t i) {
  return fmt::format("'{}' {} of {}", element.name, i + 1, element.count);
}

// A list's count: a whole number within its type (no sign for an unsigned type).
std::optional<std::uint64_t> listCount(std::string_view token, const PlyType& type) {
  if (!token.empty() && token[0] == '+') token.remove_prefix(1);
  std::uint64_t value = 0;
  const auto [ptr, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (error != std::errc{} || ptr != token.data() + token.size()) return std::nullopt;
  const int bits = static_cast<int>(type.bytes * 8) - (type.isSigned ? 1 : 0);
  if (bits < 64 && value >= (std::uint64_t{1} << bits)) return std::nullopt;
  return value;
}

std::optional<PlyFault> asciiFault(std::string_view file, const Header& header) {
  const auto isBlank = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  std::size_t at = header.bodyStart;       // where the next line starts
  std::size_t line = header.bodyLine - 1;  // the current line's number
  std::size_t lineStart = at;
  std::size_t lineEnd = at;
  std::size_t cursor = at;
  const auto readLine = [&]() {
    if (at >= file.size()) return false;
    const std::size_t end = file.find('\n', at);
    lineStart = at;
    lineEnd = end == std::string_view::npos ? file.size() : end;
    at = end == std::string_view::npos ? file.size() : end + 1;
    cursor = lineStart;
    ++line;
    return true;
  };
  const auto nextToken = [&]() -> std::string_view {
    while (cursor < lineEnd && isBlank(file[cursor])) ++cursor;
    const std::size_t start = cursor;
    while (cursor < lineEnd && !isBlank(file[cursor])) ++cursor;
    return file.substr(start, cursor - start);
  };
  const auto columnOf = [&](std::string_view token) {
    return static_cast<std::size_t>(token.data() - file.data()) - lineStart + 1;
  };
  for (const Element& element : header.elements) {
    for (std::uint64_t i = 0; i < element.count; ++i) {
      // The instance's line. A blank one is a fault: assimp reads some blank lines as an
      // instance of zeros and skips others, shifting every later line.
      if (!readLine()) {
        return PlyFault{line + 1, 1,
                        fmt::format("the file ends before {} (the header declares {} '{}' "
                                    "elements): it is cut short, or the count is too large",
                                    instanceName(element, i), element.count, element.name)};
      }
      while (cursor < lineEnd && isBlank(file[cursor])) ++cursor;
      if (cursor == lineEnd) {
        return PlyFault{line, 1,
                        fmt::format("a blank line where {} should be: the mesh library would "
                                    "read it as one, or skip it, and shift the lines after it",
                                    instanceName(element, i))};
      }
      cursor = lineStart;
      const auto shortLine = [&](const std::string& needs) {
        std::size_t end = lineEnd;
        if (end > lineStart && file[end - 1] == '\r') --end;
        return PlyFault{line, end - lineStart + 1,
                        fmt::format("the line of {} ends early: {} (the header's properties: {})",
                                    instanceName(element, i), needs, propertyNames(element))};
      };
      const auto notANumber = [&](std::string_view token, const Property& property) {
        return PlyFault{line, columnOf(token),
                        fmt::format("{} is not a number ('{}' of {})", quoteForMessage(token),
                                    property.name, instanceName(element, i))};
      };
      for (const Property& property : element.properties) {
        std::string_view token = nextToken();
        if (token.empty()) return shortLine(fmt::format("no value for '{}'", property.name));
        if (!property.list) {
          if (!isNumberWord(token)) return notANumber(token, property);
          continue;
        }
        const std::optional<std::uint64_t> count = listCount(token, property.countType);
        if (!count) {
          return PlyFault{
              line, columnOf(token),
              fmt::format("{} is not a count of '{}' values for {} (a whole number "
                          "of the count's type)",
                          quoteForMessage(token), property.name, instanceName(element, i))};
        }
        for (std::uint64_t k = 0; k < *count; ++k) {
          token = nextToken();
          if (token.empty()) {
            return shortLine(
                fmt::format("'{}' holds {} of its {} values", property.name, k, *count));
          }
          if (!isNumberWord(token)) return notANumber(token, property);
        }
      }
      const std::string_view extra = nextToken();
      if (!extra.empty()) {
        return PlyFault{line, columnOf(extra),
                        fmt::format("more values than {} holds (the header's properties: {}): "
                                    "the header does not describe this line",
                                    instanceName(element, i), propertyNames(element))};
      }
    }
  }
  // After the last instance: blank lines (and NUL padding) only.
  while (readLine()) {
    const std::string_view extra = nextToken();
    if (!extra.empty() && extra.find_first_not_of('\0') != std::string_view::npos) {
      return PlyFault{line, columnOf(extra),
                      "more data after the last element the header declares: the file holds "
                      "more than the header's counts say"};
    }
  }
  return std::nullopt;
}

std::uint64_t readUnsigned(const unsigned char* p, std::size_t bytes, bool bigEndian) {
  std::uint64_t value = 0;
  for (std::size_t k = 0; k < bytes; ++k) {
    value |= std::uint64_t{p[bigEndian ? bytes - 1 - k : k]} << (8 * k);
  }
  return value;
}

std::optional<PlyFault> binaryFault(std::string_view file, const Header& header) {
  const bool bigEndian = header.format == Format::BinaryBig;
  const auto* bytes = reinterpret_cast<const unsigned char*>(file.data());
  std::uint64_t at = header.bodyStart;
  const std::uint64_t size = file.size();
  const auto cutShort = [&](const Element& element, std::uint64_t i) {
    return PlyFault{0, 0,
                    fmt::format("the file ends at byte {} within {} (the header declares {} '{}' "
                                "elements): it is cut short, or the count is too large",
                                size, instanceName(element, i), element.count, element.name)};
  };
  for (const Element& element : header.elements) {
    bool fixed = true;
    std::uint64_t fixedBytes = 0;
    for (const Property& p : element.properties) {
      fixed = fixed && !p.list;
      fixedBytes += p.type.bytes;
    }
    if (fixed) {
      if (fixedBytes != 0 && (size - at) / fixedBytes < element.count) {
        return cutShort(element, (size - at) / fixedBytes);
      }
      at += fixedBytes * element.count;
      continue;
    }
    for (std::uint64_t i = 0; i < element.count; ++i) {
      for (const Property& p : element.properties) {
        if (!p.list) {
          if (size - at < p.type.bytes) return cutShort(element, i);
          at += p.type.bytes;
          continue;
        }
        if (size - at < p.countType.bytes) return cutShort(element, i);
        std::uint64_t count = readUnsigned(bytes + at, p.countType.bytes, bigEndian);
        if (p.countType.isSigned && (count >> (8 * p.countType.bytes - 1)) != 0) {
          return PlyFault{0, 0,
                          fmt::format("a negative count of '{}' values at byte {}, in {}", p.name,
                                      at, instanceName(element, i))};
        }
        at += p.countType.bytes;
        if ((size - at) / p.type.bytes < count) return cutShort(element, i);
        at += count * p.type.bytes;
      }
    }
  }
  // Whitespace and NUL padding after the last instance are allowed (a final newline).
  const std::string_view rest = file.substr(static_cast<std::size_t>(at));
  if (rest.find_first_not_of(std::string_view(" \t\r\n\0", 5)) != std::string_view::npos) {
    return PlyFault{0, 0,
                    fmt::format("{} bytes after the last element the header declares (from byte "
                                "{}): the file holds more than the header's counts say",
                                size - at, at)};
  }
  return std::nullopt;
}

}  // namespace

std::optional<PlyFault> findPlyFault(std::string_view file) {
  const std::optional<Header> header = readHeader(file);
  if (!header) return std::nullopt;  // assimp's words for it
  for (const Element& element : header->elements) {
    // Instances of nothing: assimp counts through them one by one (4e9 of them kept the reader
    // busy for 24 s before it gave a wrong reason).
    if (element.properties.empty() && element.count > 0) {
      return PlyFault{0, 0,
                      fmt::format("its header declares {} '{}' elements without any property",
                                  element.count, element.name)};
    }
    if (element.name == "tristrips" && element.count > 0) {
      return PlyFault{0, 0,
                      "it holds triangle strips (element 'tristrips'), which glint does not read "
                      "from PLY files: convert them to faces"};
    }
  }
  return header->format == Format::Ascii ? asciiFault(file, *header) : binaryFault(file, *header);
}

}  // namespace glint
