#include "glint/readers/yaml_reader.h"

#include <sys/stat.h>
#include <unistd.h>
#include <yaml.h>

#include <oneapi/tbb/global_control.h>

#include <algorithm>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <functional>
#include <mutex>
#include <set>
#include <string>
#include <system_error>
#include <thread>
#include <unordered_map>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "glint/core/cancel.h"
#include "glint/core/seeded_hash.h"
#include "glint/readers/diagnostics.h"

namespace glint::yaml {
namespace {

// Events between polls of the cancel flag: about a millisecond of parsing.
constexpr std::size_t kEventsPerPoll = 4096;
// Bytes libyaml asks for at a time from a file.
constexpr std::size_t kReadBlock = std::size_t{1} << 16;

std::uint64_t saturatingAdd(std::uint64_t a, std::uint64_t b) {
  return a > UINT64_MAX - b ? UINT64_MAX : a + b;
}

TextPosition positionOf(const yaml_mark_t& mark) {
  return {static_cast<std::uint32_t>(std::min<std::size_t>(mark.index, ValueTree::kMaxOffset)),
          static_cast<std::uint32_t>(mark.line + 1), static_cast<std::uint32_t>(mark.column + 1)};
}

// Where the text is read from: in memory, or a file descriptor in blocks. Counts the bytes read
// and can give back one line of the text for error messages.
class Source {
 public:
  explicit Source(std::string_view text) : text_(text) {}
  Source(int fd, std::uint64_t maxBytes) : fd_(fd), maxBytes_(maxBytes) {}

  bool inMemory() const { return fd_ < 0; }
  std::string_view text() const { return text_; }
  std::uint64_t bytesRead() const { return bytesRead_; }
  bool tooLarge() const { return tooLarge_; }
  int readErrno() const { return readErrno_; }
  const std::atomic<bool>* cancel = nullptr;
  bool cancelled = false;

  void countBytes(std::size_t size) { bytesRead_ += size; }

  // libyaml's read handler: fills buffer with up to `size` bytes; 0 = error.
  static int readHandler(void* data, unsigned char* buffer, std::size_t size,
                         std::size_t* sizeRead) {
    auto* self = static_cast<Source*>(data);
    *sizeRead = 0;
    if (isCancelled(self->cancel)) {
      self->cancelled = true;
      return 0;  // an exception must not cross libyaml's C frames
    }
    for (;;) {
      const ssize_t n = ::read(self->fd_, buffer, std::min(size, kReadBlock));
      if (n < 0 && errno == EINTR) {
        if (isCancelled(self->cancel)) {
          self->cancelled = true;
          return 0;
        }
        continue;
      }
      if (n < 0) {
        self->readErrno_ = errno;
        return 0;
      }
      self->countBytes(static_cast<std::size_t>(n));
      if (self->bytesRead_ > self->maxBytes_) {
        self->tooLarge_ = true;
        return 0;
      }
      *sizeRead = static_cast<std::size_t>(n);
      return 1;
    }
  }

  // The 1-based line `line` of the text without its line break (empty when out of range); for a
  // file, read again from the start (only on an error).
  std::string line(std::uint32_t line) const {
    if (inMemory()) return std::string(lineOf(text_, line));
    std::string content;
    char buffer[1 << 14];
    off_t offset = 0;
    std::uint32_t current = 1;
    for (;;) {
      const ssize_t n = ::pread(fd_, buffer, sizeof buffer, offset);
      if (n <= 0) break;
      offset += n;
      for (ssize_t i = 0; i < n; ++i) {
        if (buffer[i] == '\n') {
          if (current == line) return content;
          ++current;
          continue;
        }
        if (current == line && content.size() < 4096) content.push_back(buffer[i]);
      }
      if (offset > static_cast<off_t>(maxBytes_)) break;
    }
    return current == line ? content : std::string();
  }

  // Up to `count` bytes of the text from byte `offset` (fewer at its end); for a file, read again.
  std::string bytesAt(std::uint64_t offset, std::size_t count) const {
    if (inMemory()) {
      return offset < text_.size() ? std::string(text_.substr(offset, count)) : std::string();
    }
    std::string bytes(count, '\0');
    const ssize_t n = ::pread(fd_, bytes.data(), count, static_cast<off_t>(offset));
    bytes.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
    return bytes;
  }

  // Line and column (1-based, in characters) of a byte offset of the text.
  TextPosition positionOfByte(std::uint64_t offset) const {
    TextPosition p{0, 1, 1};
    const auto advance = [&](unsigned char c) {
      if (c == '\n') {
        ++p.line;
        p.column = 1;
      } else if ((c & 0xC0) != 0x80) {
        ++p.column;
      }
      if ((c & 0xC0) != 0x80) ++p.offset;
    };
    if (inMemory()) {
      for (std::uint64_t i = 0; i < offset && i < text_.size(); ++i) {
        advance(static_cast<unsigned char>(text_[i]));
      }
      return p;
    }
    char buffer[1 << 14];
    std::uint64_t done = 0;
    while (done < offset) {
      const ssize_t n = ::pread(fd_, buffer, std::min<std::uint64_t>(sizeof buffer, offset - done),
                                static_cast<off_t>(done));
      if (n <= 0) break;
      for (ssize_t i = 0; i < n; ++i) advance(static_cast<unsigned char>(buffer[i]));
      done += static_cast<std::uint64_t>(n);
    }
    return p;
  }

  static std::string_view lineOf(std::string_view text, std::uint32_t line) {
    std::size_t begin = 0;
    for (std::uint32_t l = 1; l < line; ++l) {
      begin = text.find('\n', begin);
      if (begin == std::string_view::npos) return {};
      ++begin;
    }
    const std::size_t end = text.find('\n', begin);
    return text.substr(begin, end == std::string_view::npos ? std::string_view::npos : end - begin);
  }

 private:
  std::string_view text_;
  int fd_ = -1;
  std::uint64_t maxBytes_ = 0;
  std::uint64_t bytesRead_ = 0;
  bool tooLarge_ = false;
  int readErrno_ = 0;
};

// libyaml's syntax problems in plain words; `at` is the character at the problem's place.
std::string plainProblem(std::string_view problem, std::string_view at) {
  const std::string quoted = at.empty() ? std::string("end of file") : "'" + std::string(at) + "'";
  if (problem == "did not find expected ',' or ']'") {
    return "a '[' is not closed with ']' (or a ',' is missing between its items)";
  }
  if (problem == "did not find expected ',' or '}'") {
    return "a '{' is not closed with '}' (or a ',' is missing between its entries)";
  }
  if (problem == "mapping values are not allowed in this context") {
    return "unexpected ':' here (check the indentation, or quote the text)";
  }
  if (problem == "block sequence entries are not allowed in this context") {
    return "unexpected '-' list item here (check the indentation)";
  }
  if (problem == "did not find expected '-' indicator") {
    return "unexpected " + quoted + " in a list (check the indentation)";
  }
  if (problem == "did not find expected key") {
    return "unexpected " + quoted + " in a mapping (check the indentation)";
  }
  if (problem == "could not find expected ':'") return "a key is not followed by ':'";
  if (problem == "found unexpected end of stream") {
    return "the file ends inside a quoted text (missing closing quote?)";
  }
  if (problem == "did not find expected hexdecimal number") {
    // libyaml's words (and spelling) for "\x", "\u" or "\U" without its hexadecimal digits.
    return "an escape sequence in quoted text lacks its hexadecimal digits (\\xHH, \\uHHHH "
           "or \\UHHHHHHHH)";
  }
  if (problem == "found unknown escape character") {
    return "unknown escape sequence in quoted text: " + std::string(at);  // "\\q"
  }
  if (problem.find("tab character") != std::string_view::npos) {
    return "tabs are not allowed in indentation; use spaces";
  }
  if (problem == "did not find expected node content" ||
      problem == "did not find expected <document start>" ||
      problem == "found character that cannot start any token" ||
      problem == "found unexpected ':'") {
    return "unexpected " + quoted + " here";
  }
  if (problem == "mapping keys are not allowed in this context") {
    return "unexpected '?' here (explicit '? key' entries are not used in scene files)";
  }
  if (problem == "found unexpected document indicator") {
    return "a line inside quoted text starts with '---' or '...' (missing closing quote?)";
  }
  if (problem == "found invalid Unicode character escape code") {
    return "an escape sequence in quoted text names no Unicode character";
  }
  // Anchors (&name) and aliases (*name).
  if (problem == "did not find expected alphabetic or numeric character") {
    return "an anchor ('&') or alias ('*') needs a name of letters, digits, '-' or '_'";
  }
  // Block scalars (| and >).
  if (problem == "found an indentation indicator equal to 0") {
    return "the indentation digit after '|' or '>' must be 1 to 9";
  }
  if (problem == "did not find expected comment or line break") {
    return "unexpected " + quoted + " here (only a comment may follow on this line)";
  }
  // Tags (!name, !<uri>, !handle!suffix).
  if (problem == "found undefined tag handle" || problem == "did not find the expected '>'" ||
      problem == "did not find expected '>'" || problem == "did not find expected tag URI" ||
      problem == "did not find expected '!'" || problem == "did not find URI escaped octet" ||
      problem == "found an incorrect leading UTF-8 octet" ||
      problem == "found an incorrect trailing UTF-8 octet" ||
      problem == "did not find expected whitespace or line break" ||
      problem == "found duplicate %TAG directive") {
    return "a malformed YAML tag ('!' and what follows it); scene files need no tags";
  }
  // Directives (%YAML, %TAG).
  if (problem == "found incompatible YAML document") {
    return "the %YAML line asks for a YAML version other than 1.x";
  }
  if (problem == "found duplicate %YAML directive") return "the %YAML line is given twice";
  if (problem.find("directive") != std::string_view::npos ||
      problem == "found unexpected non-alphabetical character" ||
      problem == "did not find expected digit or '.' character" ||
      problem == "found extremely long version number" ||
      problem == "did not find expected whitespace") {
    return "a malformed '%' line (a YAML directive such as %YAML 1.2)";
  }
  return std::string(problem);
}

// The UTF-8 character starting at column `column` (1-based, in characters) of `line`.
std::string characterAt(std::string_view line, std::uint32_t column) {
  std::uint32_t current = 1;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const auto c = static_cast<unsigned char>(line[i]);
    if ((c & 0xC0) == 0x80) continue;
    if (current == column) {
      std::size_t end = i + 1;
      while (end < line.size() && (static_cast<unsigned char>(line[end]) & 0xC0) == 0x80) ++end;
      return shortenForMessage(line.substr(i, end - i));
    }
    ++current;
  }
  return {};
}

// Texts from this size up are parsed on a second thread while the tree is built (when the job
// allows two threads): below it the thread costs more than it saves.
constexpr std::uint64_t kPipelinedBytes = std::uint64_t{1} << 20;
// Events handed over at a time, and batches that may wait: bounds the memory of the hand-over.
constexpr std::size_t kEventsPerBatch = 1024;
constexpr std::size_t kBatchesInFlight = 8;

// Threads this process may use now (the job's --threads, through oneTBB's global control).
std::size_t allowedThreads() {
  return tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
}

struct EventGuard {
  yaml_event_t* event;
  ~EventGuard() { yaml_event_delete(event); }
};

// What a failed yaml_parser_parse left in the parser, kept for the message (libyaml's problem
// texts are static strings).
struct ParseFailure {
  yaml_error_type_t error = YAML_NO_ERROR;
  const char* problem = nullptr;
  std::size_t problem_offset = 0;
  int problem_value = 0;
  yaml_mark_t problem_mark{};
  static ParseFailure of(const yaml_parser_t& parser) {
    return {parser.error, parser.problem, parser.problem_offset, parser.problem_value,
            parser.problem_mark};
  }
};

// Batches of events from the parsing thread to the building one (a bounded queue).
class EventPipe {
 public:
  // The parsing thread: parses until the end of the stream, a failure, or stop().
  void produce(yaml_parser_t& parser) {
    std::vector<yaml_event_t> batch;
    batch.reserve(kEventsPerBatch);
    bool end = false;
    while (!end) {
      yaml_event_t event;
      if (yaml_parser_parse(&parser, &event) == 0) {
        failure_ = ParseFailure::of(parser);
        end = true;
      } else {
        end = event.type == YAML_STREAM_END_EVENT;
        batch.push_back(event);
      }
      if (end || batch.size() == kEventsPerBatch) {
        if (!push(std::move(batch))) return;
        batch = {};
        batch.reserve(kEventsPerBatch);
      }
    }
    std::lock_guard lock(mutex_);
    finished_ = true;
    ready_.notify_all();
  }

  // The building thread: the next batch, or false when there is none and will be none.
  bool next(std::vector<yaml_event_t>& batch) {
    std::unique_lock lock(mutex_);
    ready_.wait(lock, [&] { return !queue_.empty() || finished_ || stopped_; });
    if (queue_.empty()) return false;
    batch = std::move(queue_.front());
    queue_.pop_front();
    space_.notify_all();
    return true;
  }

  void stop() {
    std::lock_guard lock(mutex_);
    stopped_ = true;
    space_.notify_all();
    ready_.notify_all();
  }
  // After the parsing thread has ended: frees the events nobody took.
  void freeRemaining() {
    for (std::vector<yaml_event_t>& batch : queue_) {
      for (yaml_event_t& event : batch) yaml_event_delete(&event);
    }
    queue_.clear();
  }
  const ParseFailure& failure() const { return failure_; }

 private:
  bool push(std::vector<yaml_event_t> batch) {
    std::unique_lock lock(mutex_);
    space_.wait(lock, [&] { return queue_.size() < kBatchesInFlight || stopped_; });
    if (stopped_) {
      for (yaml_event_t& event : batch) yaml_event_delete(&event);
      return false;
    }
    queue_.push_back(std::move(batch));
    ready_.notify_all();
    return true;
  }

  std::mutex mutex_;
  std::condition_variable ready_, space_;
  std::deque<std::vector<yaml_event_t>> queue_;
  bool finished_ = false;
  bool stopped_ = false;
  ParseFailure failure_;
};

class Reader {
 public:
  Reader(Source& source, const Limits& limits, const std::atomic<bool>* cancel)
      : source_(source), limits_(limits), cancel_(cancel) {
    source_.cancel = cancel;
  }

  Document run(std::uint64_t expectedBytes) {
    doc_.values.reserveForText(expectedBytes);
    yaml_parser_t parser;
    if (yaml_parser_initialize(&parser) == 0) throw std::bad_alloc();
    struct Guard {
      yaml_parser_t* parser;
      ~Guard() { yaml_parser_delete(parser); }
    } guard{&parser};
    if (source_.inMemory()) {
      const std::string_view text = source_.text();
      yaml_parser_set_input_string(&parser, reinterpret_cast<const unsigned char*>(text.data()),
                                   text.size());
      source_.countBytes(text.size());
    } else {
      yaml_parser_set_input(&parser, &Source::readHandler, &source_);
    }
    if (expectedBytes >= kPipelinedBytes && allowedThreads() >= 2) {
      runPipelined(parser);
    } else {
      runSerial(parser);
    }
    doc_.root = doc_.values.root();
    doc_.bytesRead = source_.bytesRead();
    return std::move(doc_);
  }

 private:
  // One thread: parse an event, add it to the tree, free it.
  void runSerial(yaml_parser_t& parser) {
    std::size_t events = 0;
    bool done = false;
    while (!done) {
      if (++events % kEventsPerPoll == 0) throwIfCancelled(cancel_);
      yaml_event_t event;
      if (yaml_parser_parse(&parser, &event) == 0) fail(ParseFailure::of(parser));
      EventGuard eventGuard{&event};
      done = handle(event);
    }
  }

  // Two threads: libyaml's scanner and parser (about four fifths of the reading) run on a thread
  // of their own and hand over batches of events; this thread adds them to the tree (and frees
  // them) while the next ones are parsed. The tree is built from the same events in the same
  // order as runSerial builds it.
  void runPipelined(yaml_parser_t& parser) {
    EventPipe pipe;
    std::thread producer([&] { pipe.produce(parser); });
    struct Join {
      EventPipe& pipe;
      std::thread& thread;
      ~Join() {
        pipe.stop();
        if (thread.joinable()) thread.join();
        pipe.freeRemaining();
      }
    } join{pipe, producer};
    std::size_t events = 0;
    bool done = false;
    std::vector<yaml_event_t> batch;
    while (!done && pipe.next(batch)) {
      for (std::size_t i = 0; i < batch.size(); ++i) {
        EventGuard eventGuard{&batch[i]};
        if (done) continue;  // events after the end: only freed
        if (++events % kEventsPerPoll == 0) throwIfCancelled(cancel_);
        try {
          done = handle(batch[i]);
        } catch (...) {
          for (std::size_t j = i + 1; j < batch.size(); ++j) yaml_event_delete(&batch[j]);
          throw;
        }
      }
      batch.clear();
    }
    if (!done) {
      // The producer stopped without the end of the stream: the parse failed.
      pipe.stop();
      producer.join();  // the failure is the parsing thread's; the source's flags too
      fail(pipe.failure());
    }
  }

  // Returns true when reading can stop: the end of the stream, or the start of a second document.
  bool handle(const yaml_event_t& e) {
    switch (e.type) {
      case YAML_STREAM_END_EVENT:
        return true;
      case YAML_DOCUMENT_START_EVENT:
        if (++documents_ == 2) {
          doc_.secondDocument = positionOf(e.start_mark);
          return true;
        }
        return false;
      case YAML_SCALAR_EVENT: {
        const auto* text = reinterpret_cast<const char*>(e.data.scalar.value);
        const std::string_view value(text, e.data.scalar.length);
        // The core schema's nulls, as plain (unquoted) scalars only: "~", "null", empty.
        const bool isNull = e.data.scalar.style == YAML_PLAIN_SCALAR_STYLE &&
                            (value.empty() || value == "~" || value == "null" || value == "Null" ||
                             value == "NULL");
        countValue(e.start_mark);
        // A plain `<<` as a key is YAML's merge key: resolved when its mapping closes.
        if (e.data.scalar.style == YAML_PLAIN_SCALAR_STYLE && value == "<<" && atKey()) {
          mergeIn_.back() = true;
        }
        const ValueId id = isNull ? doc_.values.addNull(positionOf(e.start_mark))
                                  : doc_.values.addScalar(value, positionOf(e.start_mark));
        added(id, e.data.scalar.anchor);
        return false;
      }
      case YAML_SEQUENCE_START_EVENT:
        open(ValueKind::List, e.start_mark, e.data.sequence_start.anchor);
        return false;
      case YAML_MAPPING_START_EVENT:
        open(ValueKind::Map, e.start_mark, e.data.mapping_start.anchor);
        return false;
      case YAML_SEQUENCE_END_EVENT:
      case YAML_MAPPING_END_EVENT:
        close();
        return false;
      case YAML_ALIAS_EVENT:
        alias(e);
        return false;
      default:
        return false;
    }
  }

  void countValue(const yaml_mark_t& mark) {
    if (doc_.values.valueCount() >= limits_.maxValues) {
      throw SyntaxError(positionOf(mark),
                        fmt::format("the document holds more than {} values (scalars, lists and "
                                    "mappings); a scene file describes a scene, and large "
                                    "geometry belongs in mesh files",
                                    limits_.maxValues),
                        SyntaxError::Kind::Refused);
    }
  }

  void added(ValueId id, const yaml_char_t* anchor) {
    weight_.push_back(1);
    open_.push_back(false);
    if (anchor != nullptr) anchors_[reinterpret_cast<const char*>(anchor)] = id;
  }

  void open(ValueKind kind, const yaml_mark_t& mark, const yaml_char_t* anchor) {
    if (doc_.values.openCollections() >= limits_.maxDepth) {
      throw SyntaxError(positionOf(mark),
                        fmt::format("syntax error: lists or mappings are nested too deeply (more "
                                    "than {} levels)",
                                    limits_.maxDepth),
                        SyntaxError::Kind::TooDeep);
    }
    countValue(mark);
    const ValueId id = doc_.values.open(kind, positionOf(mark));
    added(id, anchor);
    open_[id] = true;
    stack_.push_back(id);
    mergeIn_.push_back(false);
  }

  // Whether the next value is a key of the innermost open mapping.
  bool atKey() const {
    return !stack_.empty() && doc_.values.kind(stack_.back()) == ValueKind::Map &&
           doc_.values.openChildren().size() % 2 == 0;
  }

  // YAML's merge keys (`<<: *base`, `<<: [*a, *b]`) in the innermost mapping: the entries of the
  // mappings named join it, unless it has the key itself or an earlier merged mapping had it;
  // they keep the places where they were written.
  void resolveMergeKeys() {
    const ValueTree& t = doc_.values;
    const std::vector<ValueId> children = t.openChildren();
    std::vector<ValueId> own, merged;
    // The keys the mapping has so far: a sorted set (a list searched once per merged key was
    // quadratic: 160,000 merged keys took 20 s; a hash set could be flooded by chosen keys).
    std::set<std::string_view> present;
    const auto isMergeKey = [&](ValueId key) { return t.isScalar(key) && t.scalar(key) == "<<"; };
    for (std::size_t i = 0; i + 1 < children.size(); i += 2) {
      if (isMergeKey(children[i])) continue;
      own.push_back(children[i]);
      own.push_back(children[i + 1]);
      if (t.isScalar(children[i])) present.insert(t.scalar(children[i]));
    }
    const auto mergeFrom = [&](ValueId map, ValueId where) {
      if (!t.isMap(map)) {
        throw SyntaxError(t.position(where),
                          "a merge key '<<' takes a mapping or a list of mappings (an alias "
                          "*name of one)",
                          SyntaxError::Kind::Syntax);
      }
      for (std::size_t i = 0; i < t.size(map); ++i) {
        const ValueId key = t.key(map, i);
        if (isMergeKey(key)) continue;  // already resolved when that mapping closed
        if (t.isScalar(key) && !present.insert(t.scalar(key)).second) continue;
        merged.push_back(key);
        merged.push_back(t.value(map, i));
      }
    };
    for (std::size_t i = 0; i + 1 < children.size(); i += 2) {
      if (!isMergeKey(children[i])) continue;
      const ValueId value = children[i + 1];
      if (t.isList(value)) {
        for (std::size_t j = 0; j < t.size(value); ++j) mergeFrom(t.item(value, j), value);
      } else {
        mergeFrom(value, t.isNull(value) ? children[i] : value);
      }
    }
    own.insert(own.end(), merged.begin(), merged.end());
    doc_.values.replaceOpenChildren(own);
  }

  // A closed collection's weight: itself plus its children's (aliased subtrees included).
  void close() {
    if (mergeIn_.back()) resolveMergeKeys();
    mergeIn_.pop_back();
    const ValueId id = stack_.back();
    stack_.pop_back();
    doc_.values.close();
    open_[id] = false;
    std::uint64_t weight = 1;
    const ValueTree& t = doc_.values;
    const std::size_t n = t.kind(id) == ValueKind::Map ? 2 * t.size(id) : t.size(id);
    for (std::size_t i = 0; i < n; ++i) {
      const ValueId child = t.kind(id) == ValueKind::Map
                                ? (i % 2 == 0 ? t.key(id, i / 2) : t.value(id, i / 2))
                                : t.item(id, i);
      weight = saturatingAdd(weight, weight_[child]);
    }
    weight_[id] = weight;
  }

  void alias(const yaml_event_t& e) {
    const TextPosition where = positionOf(e.start_mark);
    const auto* name = reinterpret_cast<const char*>(e.data.alias.anchor);
    const auto it = anchors_.find(name);
    if (it == anchors_.end()) {
      throw SyntaxError(where,
                        fmt::format("syntax error: an alias (*{}) refers to an undefined anchor",
                                    shortenForMessage(name)),
                        SyntaxError::Kind::Syntax);
    }
    const ValueId target = it->second;
    if (open_[target]) {
      // `&a [*a]`: the anchor's value would contain itself, and every walk of it never ends.
      throw SyntaxError(where, "an alias (*name) refers to a list or mapping that contains it",
                        SyntaxError::Kind::Refused);
    }
    aliasValues_ = saturatingAdd(aliasValues_, weight_[target]);
    const std::uint64_t allowed =
        std::max<std::uint64_t>(limits_.maxAliasValues, doc_.values.valueCount());
    if (aliasValues_ > allowed) {
      throw SyntaxError(
          where,
          fmt::format("the aliases (*name) up to here repeat {} nodes, more than the limit of {} "
                      "(a YAML alias bomb?)",
                      aliasValues_ == UINT64_MAX ? std::string("more than 10^19")
                                                 : std::to_string(aliasValues_),
                      allowed),
          SyntaxError::Kind::Refused);
    }
    doc_.values.attach(target);
  }

  // libyaml's UTF-8 errors placed at the character's first byte and said with its bytes. libyaml
  // gives the offset of the byte it stopped at — for a bad continuation byte that one (and its
  // value), for a sequence cut by the end of the file the first byte (and -1) — so the message
  // named the byte after a Latin-1 'é'.
  SyntaxError notUtf8(std::uint64_t offset, const std::string& problem) const {
    if (problem == "invalid trailing UTF-8 octet") {
      // Back to the sequence's first byte (at most 3 before: a sequence is at most 4 bytes).
      const std::uint64_t from = offset >= 3 ? offset - 3 : 0;
      const std::string before = source_.bytesAt(from, static_cast<std::size_t>(offset - from));
      for (std::size_t i = before.size(); i-- > 0;) {
        if ((static_cast<unsigned char>(before[i]) & 0xC0) == 0xC0) {
          offset = from + i;
          break;
        }
      }
    }
    const std::string bytes = source_.bytesAt(offset, 4);
    const auto byte = [&](std::size_t i) {
      return fmt::format("0x{:02X}", static_cast<unsigned char>(bytes[i]));
    };
    std::string message;
    if (bytes.empty()) {
      message = "the file is not UTF-8 text here (" + problem + ")";
    } else if (problem == "invalid leading UTF-8 octet") {
      message =
          fmt::format("the file is not UTF-8 text here: byte {} cannot start a character", byte(0));
    } else if (problem == "invalid trailing UTF-8 octet" ||
               problem == "incomplete UTF-8 octet sequence") {
      message = fmt::format(
          "the file is not UTF-8 text here: byte {} starts a character the bytes after it do not "
          "complete",
          byte(0));
    } else {
      // An overlong form or no Unicode character (a surrogate, past U+10FFFF): the whole sequence.
      const auto lead = static_cast<unsigned char>(bytes[0]);
      const std::size_t width = lead >= 0xF0 ? 4 : lead >= 0xE0 ? 3 : 2;
      std::string shown;
      for (std::size_t i = 0; i < width && i < bytes.size(); ++i) {
        shown += (i > 0 ? " " : "") + byte(i);
      }
      message = fmt::format("the file is not UTF-8 text here: bytes {} are {}", shown,
                            problem == "invalid Unicode character"
                                ? "no Unicode character (a surrogate or past U+10FFFF)"
                                : "a character in more bytes than UTF-8 allows");
    }
    if (!bytes.empty() && problem != "invalid Unicode character" &&
        problem != "invalid length of a UTF-8 sequence") {
      message += " (a Latin-1 or Windows-1252 file? save it as UTF-8)";
    }
    return SyntaxError(source_.positionOfByte(offset), message, SyntaxError::Kind::Encoding);
  }

  [[noreturn]] void fail(const ParseFailure& parser) {
    if (source_.cancelled) throw Cancelled();
    if (source_.tooLarge()) {
      throw SyntaxError({}, "", SyntaxError::Kind::Refused);  // the caller words it
    }
    if (source_.readErrno() != 0) {
      throw std::system_error(source_.readErrno(), std::generic_category());
    }
    if (parser.error == YAML_READER_ERROR) {
      // Bytes that are not UTF-8 text: libyaml gives the byte offset, not the place.
      const std::string problem = parser.problem != nullptr ? parser.problem : "";
      const int value = parser.problem_value;
      if (problem.find("UTF-8") != std::string::npos || problem == "invalid Unicode character") {
        throw notUtf8(parser.problem_offset, problem);
      }
      const TextPosition where = source_.positionOfByte(parser.problem_offset);
      std::string message;
      if (problem == "control characters are not allowed") {
        message =
            fmt::format("the file holds a control character ({}) here; a scene file is UTF-8 text",
                        value == 0 ? std::string("a NUL byte") : fmt::format("U+{:04X}", value));
      } else if (problem.find("UTF-16") != std::string::npos ||
                 problem.find("surrogate") != std::string::npos) {
        message = "the file is not valid UTF-16 text here (" + problem + ")";
      } else {
        message = "the file is not UTF-8 text here (" + problem + ")";
      }
      throw SyntaxError(where, message, SyntaxError::Kind::Encoding);
    }
    TextPosition where = positionOf(parser.problem_mark);
    const std::string problem = parser.problem != nullptr ? parser.problem : "syntax error";
    const std::string line = source_.line(where.line);
    std::string at = characterAt(line, where.column);
    // An escape sequence is shown whole: the backslash at the mark and the character after it.
    if (problem == "found unknown escape character") at += characterAt(line, where.column + 1);
    std::string message = "syntax error: " + plainProblem(problem, at);
    // A tab in the indentation of this line or the previous one is the usual cause of a baffling
    // syntax error; YAML forbids tabs there.
    for (std::uint32_t l = where.line; l >= 1 && l + 1 >= where.line; --l) {
      const std::string text = l == where.line ? line : source_.line(l);
      const std::size_t indent = text.find_first_not_of(" \t");
      if (text.substr(0, indent).find('\t') != std::string::npos) {
        where = {0, l, 1};
        message = "syntax error: tabs are not allowed in indentation; use spaces";
        break;
      }
    }
    throw SyntaxError(where, message, SyntaxError::Kind::Syntax);
  }

  Source& source_;
  const Limits limits_;
  const std::atomic<bool>* cancel_;
  Document doc_;
  int documents_ = 0;
  std::vector<ValueId> stack_;
  std::vector<bool> mergeIn_;  // per open collection: it has a merge key `<<`
  std::unordered_map<std::string, ValueId, SeededHash, std::equal_to<>> anchors_;
  // Per value: values of its subtree with aliases expanded (saturating), and whether it is open.
  std::vector<std::uint64_t> weight_;
  std::vector<bool> open_;
  std::uint64_t aliasValues_ = 0;
};

}  // namespace

Document read(std::string_view text, const Limits& limits, const std::atomic<bool>* cancel) {
  Source source(text);
  return Reader(source, limits, cancel).run(text.size());
}

Document readFile(int fd, std::uint64_t maxBytes, const Limits& limits,
                  const std::atomic<bool>* cancel) {
  Source source(fd, maxBytes);
  struct stat info {};
  const std::uint64_t size = ::fstat(fd, &info) == 0 && S_ISREG(info.st_mode)
                                 ? static_cast<std::uint64_t>(info.st_size)
                                 : 0;
  return Reader(source, limits, cancel).run(std::min(size, maxBytes));
}

}  // namespace glint::yaml
