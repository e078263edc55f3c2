#pragma once
// Helpers for file-format errors that name the file, the line and the reason.
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

}  // namespace spinradar::sim::detail
