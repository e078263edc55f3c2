#pragma once
// Outputs that never lose data: every output file or recording folder is written under a
// temporary name next to its final place and renamed there only when complete, so a failed run
// leaves no partial output and never damages an older file; an output that is one of the inputs
// is refused before anything is opened for writing.
#include <fstream>
#include <string>
#include <vector>

namespace spinradar {

/// One file written as "<dir>/.<stem>.partial-<pid><ext>" (same folder, so the rename is atomic;
/// same extension, so writers that choose an encoder by extension still work) and renamed onto
/// its path by commit(). Destroyed without commit(): the temporary is removed, the path is
/// left as it was.
class AtomicOutputFile {
 public:
  explicit AtomicOutputFile(std::string path);
  ~AtomicOutputFile();
  AtomicOutputFile(const AtomicOutputFile&) = delete;
  AtomicOutputFile& operator=(const AtomicOutputFile&) = delete;

  const std::string& path() const { return path_; }
  /// Where writers write (e.g. cv::imwrite, rosbag).
  const std::string& tempPath() const { return temp_; }
  /// Opens tempPath() as a text stream (created once); throws naming path() when it cannot.
  std::ofstream& stream();
  /// Flushes and closes the stream (if any), checks it, renames onto path(). Throws
  /// std::runtime_error naming path() when the write or the rename failed.
  void commit();

 private:
  std::string path_, temp_;
  std::ofstream out_;
  bool committed_ = false;
};

/// A recording folder (radar/*.png, radar.timestamps, ...) written in a temporary sibling folder
/// and moved into place by commit(). The folder must not exist or be empty; with `force` an
/// existing folder is accepted and its old scans (radar/, radar.timestamps) are removed at
/// commit, just before the new ones move in, so a failed run still leaves the old recording
/// whole. Other files in it are kept unless the recording writes a file of the same name.
class AtomicOutputFolder {
 public:
  /// Throws std::runtime_error naming the folder when it is a file, or is not empty and
  /// `force` is false (`option` names the flag in the message, e.g. "--out").
  /// `remove_old_scans` false (a report folder): existing files are kept unless replaced.
  AtomicOutputFolder(std::string dir, bool force, const std::string& option = "--out",
                     bool remove_old_scans = true);
  ~AtomicOutputFolder();
  AtomicOutputFolder(const AtomicOutputFolder&) = delete;
  AtomicOutputFolder& operator=(const AtomicOutputFolder&) = delete;

  const std::string& path() const { return dir_; }
  /// The folder to write into until commit().
  const std::string& tempPath() const { return temp_; }
  void commit();

 private:
  std::string dir_, temp_;
  bool force_ = false, remove_old_scans_ = true, committed_ = false;
};

/// A path given to a command and the option that gave it (for messages).
struct NamedPath {
  std::string path;
  std::string option;
};

/// Throws std::invalid_argument when `output` is the same file or folder as one of `inputs`
/// (symbolic and hard links included) or, for a folder output, holds one of them. Call it
/// before opening anything for writing.
void refuseOutputOverInput(const NamedPath& output, const std::vector<NamedPath>& inputs,
                           bool output_is_folder = false);

}  // namespace spinradar
