// spinradar::bag for the CLI: forwards to the spinradar_bag library, loaded with dlopen on first
// use, so that the ROS libraries it needs are only loaded by the commands that read or write a
// bag (linking them cost every process ~50 ms of CPU and 13 MB at start-up; scan_bag.hpp).
#ifdef SPINRADAR_HAVE_BAG
#include <dlfcn.h>

#include <stdexcept>
#include <string>

#include "scan_bag.hpp"

namespace spinradar::bag {

namespace {

/// Loads the library: by name first (the program's run path, LD_LIBRARY_PATH), then where the
/// build put it. Throws std::runtime_error with dlerror()'s reason.
const BagApi& api() {
  static const BagApi* table = [] {
    void* lib = dlopen(SPINRADAR_BAG_SO_NAME, RTLD_NOW | RTLD_LOCAL);
    if (!lib) lib = dlopen(SPINRADAR_BAG_SO_PATH, RTLD_NOW | RTLD_LOCAL);
    if (!lib) throw std::runtime_error(std::string("cannot load the rosbag support library: ") + dlerror());
    using Entry = const BagApi* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(lib, "spinradar_bag_api"));
    if (!entry) throw std::runtime_error(std::string(SPINRADAR_BAG_SO_NAME ": ") + dlerror());
    return entry();
  }();
  return *table;
}

}  // namespace

size_t folderToBag(const ScanFolder& folder, const std::string& bag_path, const ScanBagOptions& options,
                   const BagProgress& progress) {
  return api().folder_to_bag(folder, bag_path, options, progress);
}

size_t bagToFolder(const std::string& bag_path, const std::string& out_dir, const std::string& topic,
                   const BagProgress& progress) {
  return api().bag_to_folder(bag_path, out_dir, topic, progress);
}

}  // namespace spinradar::bag
#endif
