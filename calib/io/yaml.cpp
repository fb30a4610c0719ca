#include "rigcal/io/yaml.h"

#include <fmt/format.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/parser.h>

#include <algorithm>
#include <set>
#include <sstream>
#include <string>

#include "rigcal/core/error.h"
#include "rigcal/core/text.h"

namespace rigcal::io {

namespace {

// Counts nodes as a reader walking the tree would meet them (an alias once per use).
void count_nodes(const YAML::Node& node, size_t& count, std::string_view file, int depth = 0) {
  if (depth > kMaxYamlDepth) {
    fail_at(file, yaml_line(node), "",
            fmt::format("YAML nested deeper than {} levels (or an alias inside itself)",
                        kMaxYamlDepth));
  }
  if (++count > kMaxYamlNodes) {
    fail_at(file, yaml_line(node), "",
            fmt::format("more than {} YAML nodes once anchors and aliases are expanded",
                        kMaxYamlNodes));
  }
  // Standard tags only: a !!binary or an application tag would be read as its text.
  if (const std::string& tag = node.Tag();
      !tag.empty() && tag != "?" && tag != "!" &&
      !(tag.starts_with("tag:yaml.org,2002:") &&
        (tag.ends_with(":str") || tag.ends_with(":int") || tag.ends_with(":float") ||
         tag.ends_with(":bool") || tag.ends_with(":null") || tag.ends_with(":map") ||
         tag.ends_with(":seq")))) {
    fail_at(file, yaml_line(node), "", fmt::format("YAML tag '{}' is not one rigcal reads", tag));
  }
  if (node.IsSequence()) {
    for (const YAML::Node& child : node) count_nodes(child, count, file, depth + 1);
  } else if (node.IsMap()) {
    for (auto it = node.begin(); it != node.end(); ++it) {
      count_nodes(it->first, count, file, depth + 1);
      count_nodes(it->second, count, file, depth + 1);
    }
  }
}

// Records the first event of a YAML document that is more than an empty (null) node.
class DocumentContent : public YAML::EventHandler {
 public:
  bool empty() const { return !has_content_; }
  int line() const { return line_; }
  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override { seen(mark); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string&) override {
    seen(mark);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    seen(mark);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    seen(mark);
  }
  void OnMapEnd() override {}

 private:
  void seen(const YAML::Mark& mark) {
    if (has_content_) return;
    has_content_ = true;
    line_ = mark.is_null() ? 0 : mark.line + 1;
  }
  bool has_content_ = false;
  int line_ = 0;
};

// Lines that begin with a document marker ('---' or '...'): a stream holds at most one document
// more than it has markers.
size_t document_markers(std::string_view text) {
  size_t count = 0;
  for (size_t start = 0; start < text.size();) {
    const std::string_view line = text.substr(start, text.find('\n', start) - start);
    if ((line.starts_with("---") || line.starts_with("...")) &&
        (line.size() == 3 || line[3] == ' ' || line[3] == '\t' || line[3] == '\r'))
      ++count;
    start += line.size() + 1;
  }
  return count;
}

// Refuses a second document that holds anything. Not YAML::LoadAll: yaml-cpp 0.7's parser returns
// an empty document again and again on some malformed text (a lone ','), and LoadAll collects
// them until memory runs out; here the documents are bounded by the markers in the text, and a
// text without markers (one document) is not parsed a second time.
void refuse_second_document(const std::string& text, std::string_view file) {
  const size_t markers = document_markers(text);
  if (markers == 0) return;
  std::istringstream stream(text);
  YAML::Parser parser(stream);
  DocumentContent first;
  if (!parser.HandleNextDocument(first)) return;
  for (size_t more = markers; more > 0; --more) {
    DocumentContent next;
    if (!parser.HandleNextDocument(next)) return;
    if (!next.empty())
      fail_at(file, next.line(), "", "a second YAML document ('---'); a rigcal YAML input is one");
  }
}
}  // namespace

YAML::Node load_yaml(std::string_view text, std::string_view file) {
  if (text.size() > kMaxYamlBytes) {
    fail_at(file, 0, "",
            fmt::format("{} bytes, more than a YAML input of rigcal may be ({} bytes)", text.size(),
                        kMaxYamlBytes));
  }
  if (const size_t bad = first_invalid_utf8(text); bad != std::string_view::npos) {
    const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + bad, '\n'));
    fail_at(file, line, "", "bytes that are not UTF-8: YAML is UTF-8 text");
  }
  if (const size_t nul = text.find('\0'); nul != std::string_view::npos) {
    const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + nul, '\n'));
    fail_at(file, line, "", "a NUL byte: not YAML text");
  }
  try {
    const std::string text_copy(text);
    refuse_second_document(text_copy, file);
    YAML::Node root = YAML::Load(text_copy);
    size_t count = 0;
    count_nodes(root, count, file);
    return root;
  } catch (const YAML::Exception& e) {
    fail_at(file, e.mark.is_null() ? 0 : e.mark.line + 1, "",
            fmt::format("YAML syntax error: {}", e.msg));
  }
}

void refuse_duplicate_keys(const YAML::Node& node, std::string_view file) {
  if (node.IsSequence()) {
    for (const YAML::Node& child : node) refuse_duplicate_keys(child, file);
  } else if (node.IsMap()) {
    std::set<std::string> keys;
    for (auto it = node.begin(); it != node.end(); ++it) {
      if (it->first.IsScalar() && !keys.insert(it->first.Scalar()).second)
        fail_at(file, yaml_line(it->first), it->first.Scalar(), "given twice");
      refuse_duplicate_keys(it->second, file);
    }
  }
}

int yaml_line(const YAML::Node& node) { return node.Mark().is_null() ? 0 : node.Mark().line + 1; }

}  // namespace rigcal::io
