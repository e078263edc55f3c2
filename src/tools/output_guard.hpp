#pragma once
// Before a subcommand opens anything for writing: no output may be one of its inputs (the
// scan files of an input folder included) or another of its outputs.
#include <string>
#include <vector>

#include "spinradar/core/safe_output.hpp"
#include "spinradar/io/scan_folder.hpp"

namespace spinradar::cli {

/// The folder and every scan file of `folder`, as inputs given by `option`.
inline std::vector<NamedPath> scanFolderInputs(const ScanFolder& folder, const std::string& option) {
  std::vector<NamedPath> in{{folder.folder(), option}};
  for (size_t i = 0; i < folder.size(); ++i) in.push_back({folder.path(i), option});
  return in;
}

/// Refuses any output equal to an input or to another output; empty paths are ignored.
inline void refuseOutputsOverInputs(const std::vector<NamedPath>& outputs,
                                    const std::vector<NamedPath>& inputs) {
  std::vector<NamedPath> seen = inputs;
  for (const NamedPath& o : outputs) {
    if (o.path.empty()) continue;
    refuseOutputOverInput(o, seen);
    seen.push_back(o);
  }
}

}  // namespace spinradar::cli
