// One YAML document from text through yaml-cpp 0.7, with the guards every reader of the project's
// YAML files needs, in one place: the map_server reader (maps/src/map_io.cpp) uses it, and so can
// the node's config. Header only and not installed (target vnsba_yaml, maps/CMakeLists.txt), so
// that no installed header exposes yaml-cpp. Each caller words the problem in its own style.
//
// Guards:
// - nesting: yaml-cpp's parser recurses once a level and stops at a fixed depth (its DepthGuard,
//   500 in 0.7) rather than overflow the stack; its message ("bad file") does not say so;
// - documents: YAML::LoadAll of yaml-cpp 0.7 never returns on a document that starts with ','
//   (it appends empty documents at the same place until memory runs out: jbeder/yaml-cpp#1040,
//   fixed after 0.7); the documents are counted with the event parser, and a document that starts
//   where the previous one did is that case, a syntax error;
// - aliases: yaml-cpp does not expand them (an alias is the anchored node itself), so an alias
//   bomb ("billion laughs") costs memory linear in the text. A reader must not walk aliased
//   collections recursively; reading known keys, as the project's readers do, is safe;
// - bytes: yaml-cpp 0.7 stops reading at a NUL byte, and drops DEL and a carriage return that
//   ends no line ("x\ry" reads "xy"), so it would silently read another document than the file
//   holds; YAML text holds no such bytes (nor other control characters but tab, line feed and
//   carriage return), so they are refused, with their place;
// - nothing yaml-cpp throws escapes.
#pragma once

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <exception>
#include <optional>
#include <sstream>
#include <string>

namespace vnsba::yaml {

// 1-based line of a mark or a node, 0 when yaml-cpp has none (yaml-cpp's marks are 0-based).
inline int line_of(const YAML::Mark& mark) {
  return mark.is_null() ? 0 : mark.line + 1;
}
inline int line_of(const YAML::Node& node) {
  return node.IsDefined() ? line_of(node.Mark()) : 0;
}

// What kind of value a node holds, for messages: "a map", "a list", "a text", "no value".
inline const char* kind_of(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Map:
      return "a map";
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Scalar:
      return "a text";
    default:
      return "no value";
  }
}

struct Problem {
  enum class Kind {
    kSyntax,     // message: yaml-cpp's ("end of map not found")
    kNesting,    // nested deeper than yaml-cpp reads
    kDocuments,  // more than one document
    kOther,      // anything else yaml-cpp (or the allocator) threw
  };
  Kind kind = Kind::kOther;
  int line = 0;    // 1-based; 0 when unknown
  int column = 0;  // 1-based; 0 when unknown
  std::string message;
};

struct Document {
  YAML::Node root;  // a null node for an empty text
  std::optional<Problem> problem;
};

namespace detail {

// Where each document of a stream starts; the content is not built.
class DocumentStarts : public YAML::EventHandler {
 public:
  void OnDocumentStart(const YAML::Mark& mark) override { start = mark; }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t,
                const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
  YAML::Mark start = YAML::Mark::null_mark();
};

// The number of documents in `text`, and where the second one starts (null mark when none).
inline size_t count_documents(const std::string& text, YAML::Mark* second) {
  std::istringstream in(text);
  YAML::Parser parser(in);
  DocumentStarts starts;
  size_t count = 0;
  YAML::Mark previous = YAML::Mark::null_mark();
  *second = YAML::Mark::null_mark();
  while (parser.HandleNextDocument(starts)) {
    if (count > 0 && starts.start.pos == previous.pos)
      throw YAML::ParserException(starts.start, "unexpected ',' where a document starts");
    if (count == 1) *second = starts.start;
    previous = starts.start;
    ++count;
  }
  return count;
}

// 1-based line and column of the place yaml-cpp's depth guard stopped: the mark is where its
// scanner was, at most the end of the nested collection; having read through a newline, that is
// the end of the line before.
inline void nesting_place(const YAML::Mark& mark, const std::string& text, Problem* p) {
  if (mark.is_null()) return;
  int line = mark.line, column = mark.column;
  const auto pos = static_cast<size_t>(std::max(mark.pos, 0));
  if (column == 0 && line > 0 && pos > 0 && pos <= text.size() && text[pos - 1] == '\n') {
    const size_t previous = pos >= 2 ? text.rfind('\n', pos - 2) : std::string::npos;
    const size_t begin = previous == std::string::npos ? 0 : previous + 1;
    --line;
    column = static_cast<int>(pos - 1 - begin);
  }
  p->line = line + 1;
  p->column = column + 1;
}

// The first byte YAML text may not hold (c-printable of YAML 1.2, for bytes: control characters
// other than tab, line feed and carriage return, DEL, and a carriage return followed by anything
// but a line feed),
// as a syntax problem at its place; nullopt when there is none.
inline std::optional<Problem> forbidden_byte(const std::string& text) {
  int line = 1;
  size_t line_start = 0;
  for (size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c == '\n') {
      ++line;
      line_start = i + 1;
      continue;
    }
    const bool lone_cr = c == '\r' && i + 1 < text.size() && text[i + 1] != '\n';
    if ((c < 0x20 && c != '\t' && c != '\r') || c == 0x7f || lone_cr) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02x", c);
      const std::string what = c == 0    ? "a NUL byte (not UTF-8 text?)"
                               : lone_cr ? "a carriage return that ends no line (only \"\\n\" and "
                                           "\"\\r\\n\" line ends are read)"
                                         : "the control character " + std::string(hex);
      return Problem{Problem::Kind::kSyntax, line, static_cast<int>(i - line_start) + 1,
                     what + ": YAML text holds none"};
    }
  }
  return std::nullopt;
}

}  // namespace detail

// `text` as one YAML document (none: a null root). Never throws.
inline Document load_document(const std::string& text) {
  Document doc;
  if ((doc.problem = detail::forbidden_byte(text))) return doc;
  try {
    YAML::Mark second = YAML::Mark::null_mark();
    const size_t documents = detail::count_documents(text, &second);
    if (documents > 1) {
      doc.problem = Problem{Problem::Kind::kDocuments, line_of(second), 0,
                            "found " + std::to_string(documents) + " YAML documents, expected one"};
      return doc;
    }
    if (documents == 1) doc.root = YAML::Load(text);
  } catch (const YAML::DeepRecursion& e) {
    Problem p{Problem::Kind::kNesting, 0, 0,
              "the YAML is nested deeper than " + std::to_string(e.depth() - 1) +
                  " levels (the most yaml-cpp reads)"};
    detail::nesting_place(e.mark, text, &p);
    doc = {YAML::Node(), p};
  } catch (const YAML::ParserException& e) {
    const bool place = !e.mark.is_null();
    doc = {YAML::Node(), Problem{Problem::Kind::kSyntax, place ? e.mark.line + 1 : 0,
                                 place ? e.mark.column + 1 : 0, e.msg}};
  } catch (const std::exception& e) {
    doc = {YAML::Node(), Problem{Problem::Kind::kOther, 0, 0, e.what()}};
  } catch (...) {
    doc = {YAML::Node(), Problem{Problem::Kind::kOther, 0, 0, "unknown error"}};
  }
  return doc;
}

}  // namespace vnsba::yaml
