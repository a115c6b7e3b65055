#include "core/yaml_duplicate_keys.hpp"

#include <fmt/format.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/exceptions.h>
#include <yaml-cpp/parser.h>

#include <map>
#include <sstream>
#include <vector>

#include "core/input_error.hpp"

namespace imscal {
namespace {

std::size_t line_of(const YAML::Mark& mark) {
  return mark.line >= 0 ? static_cast<std::size_t>(mark.line + 1) : 0;
}

// Follows the nesting of maps and sequences; in a map, nodes alternate key, value.
class DuplicateKeyFinder : public YAML::EventHandler {
 public:
  explicit DuplicateKeyFinder(std::string origin) : origin_(std::move(origin)) {}

  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t) override { node(mark, nullptr); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override { node(mark, nullptr); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string& value) override {
    node(mark, &value);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    push(mark, false);
  }
  void OnSequenceEnd() override { levels_.pop_back(); }
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    push(mark, true);
  }
  void OnMapEnd() override { levels_.pop_back(); }

 private:
  struct Level {
    bool is_map = false;
    bool expecting_key = true;
    std::size_t items = 0;  // sequence entries so far
    std::string path;       // key path of this map or sequence
    std::string last_key;   // in a map: the key whose value comes next
    std::map<std::string, std::size_t> key_lines;
  };

  // The key path of the node that starts now, in the current level.
  std::string child_path() const {
    if (levels_.empty()) return "";
    const Level& top = levels_.back();
    if (!top.is_map) return fmt::format("{}[{}]", top.path, top.items);
    return top.path.empty() ? top.last_key : top.path + "." + top.last_key;
  }

  // A node begins: in a map it is a key or a value, in a sequence an entry.
  void node(const YAML::Mark& mark, const std::string* scalar) {
    if (levels_.empty()) return;
    Level& top = levels_.back();
    if (!top.is_map) {
      ++top.items;
      return;
    }
    if (top.expecting_key) {
      top.last_key = scalar != nullptr ? *scalar : "?";
      if (scalar != nullptr) check_key(top, *scalar, line_of(mark));
    }
    top.expecting_key = !top.expecting_key;
  }

  void check_key(Level& level, const std::string& key, std::size_t line) {
    const auto [it, inserted] = level.key_lines.emplace(key, line);
    if (inserted) return;
    const std::string path = level.path.empty() ? key : level.path + "." + key;
    throw InputError(origin_, line, path,
                     fmt::format("key '{}' appears twice in one map (first at line {}); only one "
                                 "may be given",
                                 key, it->second));
  }

  void push(const YAML::Mark& mark, bool is_map) {
    std::string path = child_path();
    node(mark, nullptr);
    Level level;
    level.is_map = is_map;
    level.path = std::move(path);
    levels_.push_back(std::move(level));
  }

  std::string origin_;
  std::vector<Level> levels_;
};

}  // namespace

void refuse_duplicate_yaml_keys(const std::string& text, const std::string& origin) {
  std::istringstream stream(text);
  DuplicateKeyFinder finder(origin);
  try {
    YAML::Parser parser(stream);
    parser.HandleNextDocument(finder);
  } catch (const YAML::Exception&) {
    // A syntax error: the loader reports it with its line.
  }
}

}  // namespace imscal
