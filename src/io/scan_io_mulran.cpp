// MulRan ray CSV: one line per azimuth (stamp ns, azimuth deg, encoder, packet counter, bins).
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "scan_io_detail.hpp"
#include "spinradar/io/scan_io.hpp"

namespace spinradar {

namespace {

[[noreturn]] void fail(const std::string& path, int line, const std::string& why) {
  std::ostringstream s;
  s << path << ": line " << line << ": " << why;
  throw std::runtime_error(s.str());
}

/// Splits one line into fields in place (no allocation beyond `fields` growth).
void splitCsv(std::string& line, std::vector<const char*>& fields) {
  fields.clear();
  if (!line.empty() && line.back() == '\r') line.pop_back();
  char* p = line.data();
  fields.push_back(p);
  for (; *p; ++p)
    if (*p == ',') {
      *p = '\0';
      fields.push_back(p + 1);
    }
  if (fields.size() > 1 && *fields.back() == '\0') fields.pop_back();  // trailing comma
}

long long parseInt(const char* s, const std::string& path, int line, const char* what) {
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(s, &end, 10);
  if (end == s || *end != '\0' || errno) fail(path, line, std::string("bad ") + what + " '" + s + "'");
  return v;
}

}  // namespace

PolarScan loadMulranCsv(const std::string& path, double range_resolution, double range_offset) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot open file");
  PolarScan scan;
  scan.range_resolution = range_resolution;
  scan.range_offset = range_offset;
  scan.encoder_size = 5600;
  std::string line;
  std::vector<const char*> fields;
  int lineno = 0, bins = -1;
  while (std::getline(f, line)) {
    ++lineno;
    if (line.empty() || line == "\r") continue;
    splitCsv(line, fields);
    const int nb = static_cast<int>(fields.size()) - 4;
    if (nb < 1) fail(path, lineno, std::to_string(fields.size()) + " fields but 4 + bins expected");
    if (bins < 0) bins = nb;
    if (nb != bins)
      fail(path, lineno, std::to_string(nb) + " bins but " + std::to_string(bins) + " expected");
    const int64_t stamp = parseInt(fields[0], path, lineno, "stamp");
    const long long enc = parseInt(fields[2], path, lineno, "encoder");
    if (enc < 0 || enc >= scan.encoder_size)
      fail(path, lineno, "encoder " + std::to_string(enc) + " >= " + std::to_string(scan.encoder_size));
    scan.stamp_ns.push_back(stamp);
    scan.encoder.push_back(static_cast<uint16_t>(enc));
    scan.azimuth.push_back(2.0 * M_PI * double(enc) / scan.encoder_size);
    scan.valid.push_back(1);
    for (int b = 0; b < nb; ++b) {
      const long long v = parseInt(fields[4 + b], path, lineno, "bin value");
      if (v < 0 || v > 255) fail(path, lineno, "bin " + std::to_string(b) + " value " + std::to_string(v) + " outside 0..255");
      scan.power.push_back(static_cast<uint8_t>(v));
    }
  }
  if (bins < 0) throw std::runtime_error(path + ": no data lines");
  scan.azimuths = static_cast<int>(scan.stamp_ns.size());
  scan.bins = bins;
  detail::checkScanShape(scan.azimuths, scan.bins, path, "MulRan", "lines", "values after the 4 "
                         "leading fields of a line");
  detail::markMissingAndDuplicates(scan, path);
  return scan;
}

}  // namespace spinradar
