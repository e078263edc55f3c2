#pragma once
// Helpers for file-format errors that name the file, the line and the reason.
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace spinradar::sim::detail {

/// One step of a JSON path: an object key, or an array index when key is empty.
struct JsonStep {
  std::string key;
  int index = -1;
};

/// 1-based line of the value at `path` inside the JSON text, or 0 when it cannot be found.
/// A small scanner (strings, nesting, keys, array positions): nlohmann keeps no positions.
int jsonLineOf(const std::string& text, const std::vector<JsonStep>& path);

/// A semantic error at a JSON path; load() functions turn it into file + line + reason.
struct JsonPathError : std::runtime_error {
  JsonPathError(std::vector<JsonStep> p, const std::string& reason);
  std::vector<JsonStep> path;
  std::string reason;
};
std::string pathString(const std::vector<JsonStep>& path);

/// Reads a whole file; throws std::runtime_error "<path>: cannot open".
std::string readFile(const std::string& path);

/// Parses JSON text; parse errors become "<name>:<line>: <reason>".
nlohmann::json parseJson(const std::string& text, const std::string& name);

/// Error with location: "<name>:<line>: <reason>" (or "<name>: <reason>" when line is 0).
[[noreturn]] void fail(const std::string& name, int line, const std::string& reason);

/// T::fromJson over a JSON file; a JsonPathError becomes "<path>:<line>: <where>: <reason>".
template <class T>
T loadJsonFile(const std::string& path) {
  const std::string text = readFile(path);
  const nlohmann::json j = parseJson(text, path);
  try {
    return T::fromJson(j);
  } catch (const JsonPathError& e) {
    const std::string where = pathString(e.path);
    fail(path, jsonLineOf(text, e.path), where.empty() ? e.reason : where + ": " + e.reason);
  }
}

/// Writes v.toJson() to path, one space indented.
template <class T>
void saveJsonFile(const T& v, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write");
  out << v.toJson().dump(1) << "\n";
  if (!out) throw std::runtime_error(path + ": write failed");
}

}  // namespace spinradar::sim::detail
