// The allowed directions between the parts (docs/DEVELOPING.md, block "layers") hold for every
// source: a file of part P includes headers of P and of the parts P may use, nothing else.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace fs = std::filesystem;
namespace {

using Layers = std::map<std::string, std::set<std::string>>;

/// Reads the fenced ```layers block of docs/DEVELOPING.md: "part: used parts...".
Layers readLayers(const fs::path& developing_md) {
  std::ifstream in(developing_md);
  if (!in) throw std::runtime_error(developing_md.string() + ": cannot open");
  Layers layers;
  std::string line;
  bool inside = false;
  while (std::getline(in, line)) {
    if (line == "```layers") { inside = true; continue; }
    if (inside && line.rfind("```", 0) == 0) break;
    if (!inside || line.empty()) continue;
    const auto colon = line.find(':');
    if (colon == std::string::npos) throw std::runtime_error(developing_md.string() + ": bad line " + line);
    std::istringstream uses(line.substr(colon + 1));
    auto& set = layers[line.substr(0, colon)];
    for (std::string u; uses >> u;) set.insert(u);
  }
  return layers;
}

/// Which part a source folder (relative to the repository root) belongs to; "" for none.
std::string partOfFolder(const std::string& rel) {
  static const std::vector<std::pair<std::string, std::string>> special = {
      {"include/spinradar_ros", "ros"}, {"nodelets", "ros"}, {"src/ros", "ros"},
      {"src/bag", "tools"}, {"src/tools", "tools"}};
  for (const auto& [prefix, part] : special)
    if (rel.rfind(prefix + "/", 0) == 0) return part;
  static const std::regex part_folder(R"(^(?:include/spinradar|src)/(\w+)/)");
  std::smatch m;
  if (std::regex_search(rel, m, part_folder)) return m[1];
  return "";
}

struct Violation {
  std::string file;
  int line;
  std::string text;
};

/// Every include of a part's header that the layers do not allow, and every part folder that
/// the layers do not list (so a new folder cannot slip past the check).
std::vector<Violation> checkTree(const fs::path& root, const Layers& layers) {
  std::vector<Violation> out;
  static const std::regex inc(R"(^\s*#\s*include\s*"(spinradar_ros|spinradar/(\w+))/)");
  for (const char* top : {"include", "src", "nodelets"}) {
    if (!fs::exists(root / top)) continue;
    for (const auto& e : fs::recursive_directory_iterator(root / top)) {
      if (!e.is_regular_file()) continue;
      const auto ext = e.path().extension();
      if (ext != ".hpp" && ext != ".cpp" && ext != ".h") continue;
      const std::string rel = fs::relative(e.path(), root).generic_string();
      const std::string part = partOfFolder(rel);
      if (part.empty()) continue;
      const auto allowed = layers.find(part);
      if (allowed == layers.end()) {
        out.push_back({rel, 0, "part '" + part + "' is not in the layers list"});
        continue;
      }
      std::ifstream in(e.path());
      std::string line;
      for (int n = 1; std::getline(in, line); ++n) {
        std::smatch m;
        if (!std::regex_search(line, m, inc)) continue;
        const std::string used = m[2].matched ? std::string(m[2]) : "ros";
        if (used != part && !allowed->second.count(used)) out.push_back({rel, n, line});
      }
    }
  }
  return out;
}

std::string describe(const std::vector<Violation>& v) {
  std::string s;
  for (const auto& x : v) s += x.file + ":" + std::to_string(x.line) + ": " + x.text + "\n";
  return s;
}

const fs::path kRoot = SPINRADAR_SOURCE_DIR;

TEST(Layering, EveryPartIsListedAndUsesOnlyLowerParts) {
  const Layers layers = readLayers(kRoot / "docs/DEVELOPING.md");
  ASSERT_GE(layers.size(), 10u) << "the layers block of docs/DEVELOPING.md looks truncated";
  EXPECT_TRUE(layers.at("core").empty()) << "core must use no other part";
  const auto v = checkTree(kRoot, layers);
  EXPECT_TRUE(v.empty()) << "includes that break docs/DEVELOPING.md's layers:\n" << describe(v);
}

TEST(Layering, NoPartUsesAPartThatUsesIt) {
  // The list itself must be a hierarchy: no cycles (a uses b and b uses a, directly or not).
  const Layers layers = readLayers(kRoot / "docs/DEVELOPING.md");
  for (const auto& [part, uses] : layers) {
    std::set<std::string> seen, todo(uses.begin(), uses.end());
    while (!todo.empty()) {
      const std::string u = *todo.begin();
      todo.erase(todo.begin());
      ASSERT_NE(u, part) << part << " reaches itself through the parts it uses";
      if (!seen.insert(u).second) continue;
      ASSERT_TRUE(layers.count(u)) << part << " uses '" << u << "', which is not a part";
      for (const auto& w : layers.at(u)) todo.insert(w);
    }
  }
}

TEST(Layering, APlantedBadIncludeIsCaught) {
  // A copy of the layers with a tree holding one allowed and one forbidden include: the check
  // must name exactly the forbidden one (estimation must never include the driver).
  const fs::path tmp = fs::temp_directory_path() / ("spinradar_layering_" + std::to_string(::getpid()));
  fs::remove_all(tmp);
  fs::create_directories(tmp / "src/estimation");
  {
    std::ofstream(tmp / "src/estimation/good.cpp") << "#include \"spinradar/features/matcher.hpp\"\n";
    std::ofstream(tmp / "src/estimation/bad.cpp")
        << "// estimation reading the socket\n#include \"spinradar/driver/navtech_driver.hpp\"\n";
  }
  const auto v = checkTree(tmp, readLayers(kRoot / "docs/DEVELOPING.md"));
  fs::remove_all(tmp);
  ASSERT_EQ(v.size(), 1u) << describe(v);
  EXPECT_EQ(v[0].file, "src/estimation/bad.cpp");
  EXPECT_EQ(v[0].line, 2);
}

TEST(Layering, AnUnlistedPartFolderIsCaught) {
  const fs::path tmp = fs::temp_directory_path() / ("spinradar_layering_new_" + std::to_string(::getpid()));
  fs::remove_all(tmp);
  fs::create_directories(tmp / "src/newpart");
  std::ofstream(tmp / "src/newpart/x.cpp") << "int x;\n";
  const auto v = checkTree(tmp, readLayers(kRoot / "docs/DEVELOPING.md"));
  fs::remove_all(tmp);
  ASSERT_EQ(v.size(), 1u) << describe(v);
  EXPECT_NE(v[0].text.find("newpart"), std::string::npos);
}

}  // namespace
