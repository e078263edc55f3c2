#include "spinradar/evaluation/plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "spinradar/io/png_io.hpp"
#include "plot_range.hpp"

namespace spinradar::plot {

namespace {

const cv::Scalar kWhite(255, 255, 255);
using detail::ensureSpan;
using detail::Range;

}  // namespace

cv::Scalar paletteColor(int index) {
  // Okabe-Ito, BGR.
  static const cv::Scalar colors[] = {
      {178, 114, 0},   // blue
      {0, 94, 213},    // vermillion
      {115, 158, 0},   // bluish green
      {0, 159, 230},   // orange
      {167, 121, 204}, // reddish purple
      {233, 180, 86},  // sky blue
      {66, 228, 240},  // yellow
      {60, 60, 60},    // dark grey
  };
  return colors[((index % 8) + 8) % 8];
}

Histogram histogram(const std::vector<double>& values, int bins, double lo, double hi) {
  Histogram h;
  if (bins < 1) throw std::invalid_argument("histogram: bins must be >= 1");
  if (lo == hi) {
    Range r;
    for (double v : values) r.add(v);
    ensureSpan(r);
    lo = r.lo;
    hi = r.hi;
  }
  h.width = (hi - lo) / bins;
  h.centres.resize(bins);
  h.counts.assign(bins, 0.0);
  for (int i = 0; i < bins; ++i) h.centres[i] = lo + (i + 0.5) * h.width;
  for (double v : values) {
    if (!std::isfinite(v) || v < lo || v > hi) continue;
    const int i = std::min(bins - 1, static_cast<int>((v - lo) / h.width));
    h.counts[i] += 1.0;
  }
  return h;
}

std::vector<double> niceTicks(double lo, double hi, int target) {
  std::vector<double> ticks;
  if (!(hi > lo) || target < 1) return ticks;
  const double raw = (hi - lo) / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * mag >= raw) {
      step = m * mag;
      break;
    }
  const double first = std::ceil(lo / step - 1e-9) * step;
  for (double v = first; v <= hi + step * 1e-9; v += step) ticks.push_back(v);
  return ticks;
}

Plot& Plot::title(std::string t) { title_ = std::move(t); return *this; }
Plot& Plot::xlabel(std::string l) { xlabel_ = std::move(l); return *this; }
Plot& Plot::ylabel(std::string l) { ylabel_ = std::move(l); return *this; }
Plot& Plot::labels(std::string t, std::string x, std::string y) {
  return title(std::move(t)).xlabel(std::move(x)).ylabel(std::move(y));
}
Plot& Plot::xlim(double lo, double hi) { xlim_ = std::make_pair(lo, hi); return *this; }
Plot& Plot::ylim(double lo, double hi) { ylim_ = std::make_pair(lo, hi); return *this; }
Plot& Plot::equalAspect(bool on) { equal_aspect_ = on; return *this; }
Plot& Plot::grid(bool on) { grid_ = on; return *this; }
Plot& Plot::legend(bool on) { legend_ = on; return *this; }

Plot& Plot::add(Series s) {
  if (s.x.size() != s.y.size())
    throw std::invalid_argument("plot series '" + s.label + "': x has " +
                                std::to_string(s.x.size()) + " values, y has " +
                                std::to_string(s.y.size()));
  series_.push_back(std::move(s));
  return *this;
}

Plot& Plot::line(const std::vector<double>& x, const std::vector<double>& y, std::string label,
                 std::optional<cv::Scalar> color, int thickness) {
  Series s;
  s.x = x;
  s.y = y;
  s.label = std::move(label);
  s.color = color;
  s.thickness = thickness;
  return add(std::move(s));
}

Plot& Plot::scatter(const std::vector<double>& x, const std::vector<double>& y,
                    std::string label, std::optional<cv::Scalar> color, int radius) {
  Series s;
  s.x = x;
  s.y = y;
  s.label = std::move(label);
  s.color = color;
  s.style = SeriesStyle::Points;
  s.marker_radius = radius;
  return add(std::move(s));
}

Plot& Plot::bars(const Histogram& h, std::string label, std::optional<cv::Scalar> color) {
  Series s;
  s.x = h.centres;
  s.y = h.counts;
  s.label = std::move(label);
  s.color = color;
  s.style = SeriesStyle::Bars;
  s.bar_width = h.width;
  return add(std::move(s));
}

void Plot::save(const std::string& path, int width, int height) const {
  saveImage(render(width, height), path);
}

cv::Mat tile(const std::vector<cv::Mat>& panels, int cols) {
  if (panels.empty()) return {};
  cols = std::max(1, std::min(cols, static_cast<int>(panels.size())));
  const int rows = (static_cast<int>(panels.size()) + cols - 1) / cols;
  const cv::Size sz = panels.front().size();
  cv::Mat out(rows * sz.height, cols * sz.width, CV_8UC3, kWhite);
  for (size_t i = 0; i < panels.size(); ++i) {
    cv::Mat p = panels[i];
    if (p.channels() == 1) cv::cvtColor(p, p, cv::COLOR_GRAY2BGR);
    if (p.size() != sz) cv::resize(p, p, sz, 0, 0, cv::INTER_AREA);
    const int r = static_cast<int>(i) / cols, c = static_cast<int>(i) % cols;
    p.copyTo(out(cv::Rect(c * sz.width, r * sz.height, sz.width, sz.height)));
  }
  return out;
}

void checkImagePath(const std::string& path) {
  const auto dot = path.rfind('.');
  std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  if (ext != ".png")
    throw std::runtime_error(path + ": not an image file name (plots are written as .png)");
}

void saveImage(const cv::Mat& image, const std::string& path) {
  // PNG only, through io's libspng writer: OpenCV's imgcodecs would cost every process 0.3 s
  // of start-up (see io/png_io.hpp).
  checkImagePath(path);
  writePng(image, path, 3);  // temp file renamed when complete; errors name the file
}

}  // namespace spinradar::plot
