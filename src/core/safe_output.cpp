#include "spinradar/core/safe_output.hpp"

#include <unistd.h>

#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace fs = std::filesystem;

namespace spinradar {

namespace {

std::string partialName(const fs::path& p) {
  return "." + p.stem().string() + ".partial-" + std::to_string(::getpid()) +
         p.extension().string();
}

fs::path normalised(const std::string& p) {
  std::error_code ec;
  fs::path c = fs::weakly_canonical(fs::absolute(p, ec), ec);
  if (ec) c = fs::absolute(p).lexically_normal();
  return c;
}

/// True when `inner` lies strictly inside folder `outer` (both normalised).
bool isInside(const fs::path& inner, const fs::path& outer) {
  auto o = outer.begin(), i = inner.begin();
  for (; o != outer.end(); ++o, ++i) {
    if (o->empty()) continue;  // trailing separator
    if (i == inner.end() || *i != *o) return false;
  }
  return i != inner.end();
}

}  // namespace

AtomicOutputFile::AtomicOutputFile(std::string path) : path_(std::move(path)) {
  if (path_.empty()) throw std::invalid_argument("empty output path");
  const fs::path p(path_);
  std::error_code ec;
  if (fs::is_directory(p, ec))
    throw std::runtime_error(path_ + ": is a folder, a file name is expected for this output");
  temp_ = (p.parent_path() / partialName(p)).string();
}

AtomicOutputFile::~AtomicOutputFile() {
  if (committed_) return;
  if (out_.is_open()) out_.close();
  std::error_code ec;
  fs::remove(temp_, ec);
}

std::ofstream& AtomicOutputFile::stream() {
  if (!out_.is_open()) {
    out_.open(temp_);
    if (!out_) throw std::runtime_error(path_ + ": cannot open for writing");
  }
  return out_;
}

void AtomicOutputFile::commit() {
  if (committed_) return;
  if (out_.is_open()) {
    out_.flush();
    out_.close();
    if (out_.fail()) throw std::runtime_error(path_ + ": write failed (disk full?)");
  }
  std::error_code ec;
  fs::rename(temp_, path_, ec);
  if (ec) throw std::runtime_error(path_ + ": cannot move the finished output into place (" +
                                   ec.message() + ")");
  committed_ = true;
}

AtomicOutputFolder::AtomicOutputFolder(std::string dir, bool force, const std::string& option,
                                       bool remove_old_scans)
    : dir_(std::move(dir)), force_(force), remove_old_scans_(remove_old_scans) {
  if (dir_.empty()) throw std::invalid_argument("empty output folder");
  fs::path d = fs::path(dir_).lexically_normal();
  if (d.filename().empty()) d = d.parent_path();  // trailing slash
  std::error_code ec;
  if (fs::exists(d, ec)) {
    if (!fs::is_directory(d, ec))
      throw std::runtime_error(dir_ + ": exists and is not a folder (" + option +
                               " names a recording folder)");
    auto it = fs::directory_iterator(d, ec);
    if (ec) throw std::runtime_error(dir_ + ": cannot list folder (" + ec.message() + ")");
    if (it != fs::directory_iterator() && !force_)
      throw std::runtime_error(dir_ + ": folder is not empty (it holds " +
                               it->path().filename().string() +
                               "...); a recording is never mixed with old files: choose a new " +
                               option + " folder, or give --force to replace its scans");
  }
  const fs::path parent = d.has_parent_path() ? d.parent_path() : fs::path(".");
  fs::create_directories(parent, ec);
  if (ec) throw std::runtime_error(parent.string() + ": cannot create folder (" + ec.message() + ")");
  const fs::path temp = parent / partialName(d);
  fs::remove_all(temp, ec);
  fs::create_directory(temp, ec);
  if (ec) throw std::runtime_error(temp.string() + ": cannot create folder (" + ec.message() + ")");
  temp_ = temp.string();
  dir_ = d.string();
}

AtomicOutputFolder::~AtomicOutputFolder() {
  if (committed_) return;
  std::error_code ec;
  fs::remove_all(temp_, ec);
}

void AtomicOutputFolder::commit() {
  if (committed_) return;
  std::error_code ec;
  auto fail = [&](const std::string& what) {
    throw std::runtime_error(dir_ + ": " + what + " (" + ec.message() + "); the new recording is in " +
                             temp_);
  };
  if (!fs::exists(dir_, ec)) {
    fs::rename(temp_, dir_, ec);
    if (ec) fail("cannot move the finished recording into place");
    committed_ = true;
    return;
  }
  if (force_ && remove_old_scans_) {
    fs::remove_all(fs::path(dir_) / "radar", ec);
    if (!ec) fs::remove(fs::path(dir_) / "radar.timestamps", ec);
    if (ec) fail("cannot remove the old scans");
  }
  for (const auto& e : fs::directory_iterator(temp_, ec)) {
    const fs::path target = fs::path(dir_) / e.path().filename();
    if (fs::is_directory(target) && !fs::is_symlink(target)) fs::remove_all(target, ec);
    if (!ec) fs::rename(e.path(), target, ec);
    if (ec) fail("cannot move " + e.path().filename().string() + " into place");
  }
  if (ec) fail("cannot list the finished recording");
  fs::remove(temp_, ec);
  committed_ = true;
}

void refuseOutputOverInput(const NamedPath& output, const std::vector<NamedPath>& inputs,
                           bool output_is_folder) {
  if (output.path.empty() || output.path == "-") return;
  const fs::path out = normalised(output.path);
  std::error_code ec;
  const bool out_exists = fs::exists(out, ec);
  for (const NamedPath& in : inputs) {
    if (in.path.empty() || in.path == "-") continue;
    const fs::path inp = normalised(in.path);
    const bool same = inp == out || (out_exists && fs::exists(inp, ec) && fs::equivalent(inp, out, ec));
    if (same)
      throw std::invalid_argument(output.path + ": the output (" + output.option +
                                  ") is the same file as " + in.option + " " + in.path +
                                  ": refusing to overwrite it; choose another path");
    if (output_is_folder && isInside(inp, out))
      throw std::invalid_argument(output.path + ": the output folder (" + output.option +
                                  ") holds an input (" + in.option + " " + in.path +
                                  "): refusing to write over inputs; choose another folder");
  }
}

}  // namespace spinradar
