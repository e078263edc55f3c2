#include "file_errors.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace spinradar::sim::detail {

namespace {

// Scanner over JSON text that tracks the path of the value being entered.
struct Scanner {
  const std::string& s;
  size_t i = 0;
  int line = 1;

  void skipWs() {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\n' || s[i] == '\r')) {
      if (s[i] == '\n') ++line;
      ++i;
    }
  }
  bool readString(std::string* out) {
    if (i >= s.size() || s[i] != '"') return false;
    ++i;
    while (i < s.size() && s[i] != '"') {
      if (s[i] == '\\') ++i;
      else if (out) out->push_back(s[i]);
      if (i < s.size() && s[i] == '\n') ++line;
      ++i;
    }
    ++i;
    return true;
  }
  // Skips one value; returns false on malformed text.
  bool skipValue() {
    skipWs();
    if (i >= s.size()) return false;
    char c = s[i];
    if (c == '"') return readString(nullptr);
    if (c == '{' || c == '[') {
      int depth = 0;
      while (i < s.size()) {
        char d = s[i];
        if (d == '"') {
          readString(nullptr);
          continue;
        }
        if (d == '\n') ++line;
        if (d == '{' || d == '[') ++depth;
        if (d == '}' || d == ']') {
          --depth;
          if (depth == 0) {
            ++i;
            return true;
          }
        }
        ++i;
      }
      return false;
    }
    while (i < s.size() && s[i] != ',' && s[i] != '}' && s[i] != ']' && s[i] != '\n') ++i;
    return true;
  }
  // Positions the scanner at the start of the value at path[k..].
  bool descend(const std::vector<JsonStep>& path, size_t k) {
    skipWs();
    if (k == path.size()) return true;
    if (i >= s.size()) return false;
    const JsonStep& step = path[k];
    if (!step.key.empty()) {
      if (s[i] != '{') return false;
      ++i;
      for (;;) {
        skipWs();
        if (i >= s.size() || s[i] == '}') return false;
        std::string key;
        if (!readString(&key)) return false;
        skipWs();
        if (i >= s.size() || s[i] != ':') return false;
        ++i;
        if (key == step.key) return descend(path, k + 1);
        if (!skipValue()) return false;
        skipWs();
        if (i < s.size() && s[i] == ',') ++i;
      }
    }
    if (s[i] != '[') return false;
    ++i;
    for (int n = 0;; ++n) {
      skipWs();
      if (i >= s.size() || s[i] == ']') return false;
      if (n == step.index) return descend(path, k + 1);
      if (!skipValue()) return false;
      skipWs();
      if (i < s.size() && s[i] == ',') ++i;
    }
  }
};

}  // namespace

int jsonLineOf(const std::string& text, const std::vector<JsonStep>& path) {
  Scanner sc{text};
  return sc.descend(path, 0) ? sc.line : 0;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

nlohmann::json parseJson(const std::string& text, const std::string& name) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    // Byte position -> line.
    size_t pos = std::min<size_t>(e.byte, text.size());
    int line = 1;
    for (size_t k = 0; k + 1 < pos; ++k)
      if (text[k] == '\n') ++line;
    fail(name, line, std::string("invalid JSON: ") + e.what());
  }
}

std::string pathString(const std::vector<JsonStep>& path) {
  std::string out;
  for (const auto& st : path) {
    if (!st.key.empty()) out += (out.empty() ? "" : ".") + st.key;
    else out += "[" + std::to_string(st.index) + "]";
  }
  return out;
}

JsonPathError::JsonPathError(std::vector<JsonStep> p, const std::string& r)
    : std::runtime_error(pathString(p) + ": " + r), path(std::move(p)), reason(r) {}

void fail(const std::string& name, int line, const std::string& reason) {
  throw std::runtime_error(line > 0 ? name + ":" + std::to_string(line) + ": " + reason
                                    : name + ": " + reason);
}

}  // namespace spinradar::sim::detail
