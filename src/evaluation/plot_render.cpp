// Plot::render: axes, ticks, series and legend drawn with OpenCV (plot.cpp builds the Plot).
#include "spinradar/evaluation/plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "plot_range.hpp"

namespace spinradar::plot {

namespace {

using detail::ensureSpan;
using detail::Range;

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kTickFontScale = 0.42;
constexpr double kLabelFontScale = 0.5;
constexpr double kTitleFontScale = 0.6;
constexpr int kShift = 4;  // fixed-point bits for sub-pixel drawing
const cv::Scalar kBlack(0, 0, 0), kGrid(225, 225, 225), kWhite(255, 255, 255);

std::string tickLabel(double v, double step) {
  char buf[64];
  if (std::fabs(v) < step * 1e-9) v = 0;
  const int decimals = std::max(0, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
  if (std::fabs(v) >= 1e6 || (std::fabs(v) < 1e-4 && v != 0))
    std::snprintf(buf, sizeof buf, "%.3g", v);
  else
    std::snprintf(buf, sizeof buf, "%.*f", std::min(decimals, 6), v);
  return buf;
}

cv::Point toFixed(double px, double py) {
  return cv::Point(static_cast<int>(std::lround(px * (1 << kShift))),
                   static_cast<int>(std::lround(py * (1 << kShift))));
}

void putTextCentered(cv::Mat& img, const std::string& s, cv::Point centre, double scale,
                     const cv::Scalar& color, int thickness = 1) {
  int base = 0;
  const cv::Size sz = cv::getTextSize(s, kFont, scale, thickness, &base);
  cv::putText(img, s, cv::Point(centre.x - sz.width / 2, centre.y + sz.height / 2), kFont, scale,
              color, thickness, cv::LINE_AA);
}

}  // namespace

namespace {

double barWidth(const Series& s) {
  if (s.bar_width > 0) return s.bar_width;
  double w = std::numeric_limits<double>::infinity();
  for (size_t i = 1; i < s.x.size(); ++i)
    if (s.x[i] != s.x[i - 1]) w = std::min(w, std::fabs(s.x[i] - s.x[i - 1]));
  return std::isfinite(w) ? 0.8 * w : 1.0;
}

}  // namespace

cv::Mat Plot::render(int width, int height) const {
  if (width < 120 || height < 100)
    throw std::invalid_argument("plot: image must be at least 120 x 100 px");
  cv::Mat img(height, width, CV_8UC3, kWhite);

  // Data ranges.
  Range rx, ry;
  bool any_bars = false;
  for (const auto& s : series_) {
    const double bw = s.style == SeriesStyle::Bars ? barWidth(s) : 0.0;
    for (size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      rx.add(s.x[i] - bw / 2);
      rx.add(s.x[i] + bw / 2);
      ry.add(s.y[i]);
    }
    if (s.style == SeriesStyle::Bars) any_bars = true;
  }
  if (any_bars) ry.add(0.0);
  ensureSpan(rx);
  ensureSpan(ry);
  if (!xlim_) {
    const double pad = 0.04 * (rx.hi - rx.lo);
    rx.lo -= any_bars ? 0 : pad;
    rx.hi += any_bars ? 0 : pad;
  } else {
    rx.lo = xlim_->first;
    rx.hi = xlim_->second;
  }
  if (!ylim_) {
    const double pad = 0.06 * (ry.hi - ry.lo);
    if (!(any_bars && ry.lo >= 0)) ry.lo -= pad;
    ry.hi += pad;
  } else {
    ry.lo = ylim_->first;
    ry.hi = ylim_->second;
  }
  ensureSpan(rx);
  ensureSpan(ry);

  // Plot area.
  const int left = ylabel_.empty() ? 62 : 80, right = 16;
  const int top = title_.empty() ? 14 : 36, bottom = xlabel_.empty() ? 34 : 54;
  const cv::Rect area(left, top, width - left - right, height - top - bottom);
  if (equal_aspect_) {
    const double sx = (rx.hi - rx.lo) / area.width, sy = (ry.hi - ry.lo) / area.height;
    if (sx > sy) {
      const double c = 0.5 * (ry.lo + ry.hi), half = 0.5 * sx * area.height;
      ry.lo = c - half;
      ry.hi = c + half;
    } else {
      const double c = 0.5 * (rx.lo + rx.hi), half = 0.5 * sy * area.width;
      rx.lo = c - half;
      rx.hi = c + half;
    }
  }
  auto px = [&](double x) { return area.x + (x - rx.lo) / (rx.hi - rx.lo) * area.width; };
  auto py = [&](double y) { return area.y + area.height - (y - ry.lo) / (ry.hi - ry.lo) * area.height; };

  // Grid and ticks.
  const auto xt = niceTicks(rx.lo, rx.hi, std::max(2, area.width / 90));
  const auto yt = niceTicks(ry.lo, ry.hi, std::max(2, area.height / 60));
  const double xstep = xt.size() > 1 ? xt[1] - xt[0] : rx.hi - rx.lo;
  const double ystep = yt.size() > 1 ? yt[1] - yt[0] : ry.hi - ry.lo;
  for (double v : xt) {
    const int x = static_cast<int>(std::lround(px(v)));
    if (grid_) cv::line(img, {x, area.y}, {x, area.y + area.height}, kGrid, 1);
    cv::line(img, {x, area.y + area.height}, {x, area.y + area.height + 4}, kBlack, 1);
    putTextCentered(img, tickLabel(v, xstep), {x, area.y + area.height + 14}, kTickFontScale,
                    kBlack);
  }
  for (double v : yt) {
    const int y = static_cast<int>(std::lround(py(v)));
    if (grid_) cv::line(img, {area.x, y}, {area.x + area.width, y}, kGrid, 1);
    cv::line(img, {area.x - 4, y}, {area.x, y}, kBlack, 1);
    const std::string s = tickLabel(v, ystep);
    int base = 0;
    const cv::Size sz = cv::getTextSize(s, kFont, kTickFontScale, 1, &base);
    cv::putText(img, s, {area.x - 7 - sz.width, y + sz.height / 2}, kFont, kTickFontScale, kBlack,
                1, cv::LINE_AA);
  }

  // Series, clipped to the plot area.
  cv::Mat canvas = img(area);
  const cv::Point2d off(area.x, area.y);
  for (size_t k = 0; k < series_.size(); ++k) {
    const Series& s = series_[k];
    const cv::Scalar color = s.color ? *s.color : paletteColor(static_cast<int>(k));
    if (s.style == SeriesStyle::Bars) {
      const double bw = barWidth(s);
      for (size_t i = 0; i < s.x.size(); ++i) {
        if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
        cv::Point p1 = toFixed(px(s.x[i] - bw / 2) - off.x, py(0.0) - off.y);
        cv::Point p2 = toFixed(px(s.x[i] + bw / 2) - off.x, py(s.y[i]) - off.y);
        cv::rectangle(canvas, p1, p2, color, cv::FILLED, cv::LINE_AA, kShift);
        cv::rectangle(canvas, p1, p2, kBlack, 1, cv::LINE_AA, kShift);
      }
      continue;
    }
    const bool lines = s.style == SeriesStyle::Line || s.style == SeriesStyle::LinePoints;
    const bool points = s.style == SeriesStyle::Points || s.style == SeriesStyle::LinePoints;
    const cv::Size clip(canvas.cols << kShift, canvas.rows << kShift);
    for (size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      const cv::Point p = toFixed(px(s.x[i]) - off.x, py(s.y[i]) - off.y);
      if (lines && i > 0 && std::isfinite(s.x[i - 1]) && std::isfinite(s.y[i - 1])) {
        cv::Point a = toFixed(px(s.x[i - 1]) - off.x, py(s.y[i - 1]) - off.y), b = p;
        if (cv::clipLine(clip, a, b)) cv::line(canvas, a, b, color, s.thickness, cv::LINE_AA, kShift);
      }
      if (points && p.x >= 0 && p.y >= 0 && p.x < clip.width && p.y < clip.height)
        cv::circle(canvas, p, s.marker_radius << kShift, color, cv::FILLED, cv::LINE_AA, kShift);
    }
  }
  cv::rectangle(img, area, kBlack, 1);

  // Labels and title.
  if (!title_.empty())
    putTextCentered(img, title_, {area.x + area.width / 2, 18}, kTitleFontScale, kBlack, 1);
  if (!xlabel_.empty())
    putTextCentered(img, xlabel_, {area.x + area.width / 2, height - 14}, kLabelFontScale, kBlack);
  if (!ylabel_.empty()) {
    int base = 0;
    const cv::Size sz = cv::getTextSize(ylabel_, kFont, kLabelFontScale, 1, &base);
    cv::Mat t(sz.height + base + 4, sz.width + 4, CV_8UC3, kWhite);
    cv::putText(t, ylabel_, {2, sz.height + 1}, kFont, kLabelFontScale, kBlack, 1, cv::LINE_AA);
    cv::rotate(t, t, cv::ROTATE_90_COUNTERCLOCKWISE);
    const int x0 = 4;
    const int y0 = std::max(0, area.y + area.height / 2 - t.rows / 2);
    const cv::Rect dst(x0, y0, std::min(t.cols, width - x0), std::min(t.rows, height - y0));
    t(cv::Rect(0, 0, dst.width, dst.height)).copyTo(img(dst));
  }

  // Legend (top right inside the axes).
  if (legend_) {
    std::vector<size_t> entries;
    int text_w = 0;
    for (size_t k = 0; k < series_.size(); ++k) {
      if (series_[k].label.empty()) continue;
      entries.push_back(k);
      int base = 0;
      text_w = std::max(text_w, cv::getTextSize(series_[k].label, kFont, kTickFontScale, 1, &base).width);
    }
    if (!entries.empty()) {
      const int row_h = 18, sample_w = 26;
      const int bw = text_w + sample_w + 14, bh = row_h * static_cast<int>(entries.size()) + 8;
      // The corner covering the fewest data points (top right on ties).
      const cv::Rect corners[4] = {
          {area.x + area.width - bw - 8, area.y + 8, bw, bh},
          {area.x + 8, area.y + 8, bw, bh},
          {area.x + area.width - bw - 8, area.y + area.height - bh - 8, bw, bh},
          {area.x + 8, area.y + area.height - bh - 8, bw, bh}};
      int hits[4] = {0, 0, 0, 0};
      for (const auto& s : series_)
        for (size_t i = 0; i < s.x.size(); ++i) {
          if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
          const cv::Point p(static_cast<int>(px(s.x[i])), static_cast<int>(py(s.y[i])));
          for (int c = 0; c < 4; ++c) hits[c] += corners[c].contains(p);
        }
      const cv::Rect box = corners[std::min_element(hits, hits + 4) - hits];
      cv::rectangle(img, box, kWhite, cv::FILLED);
      cv::rectangle(img, box, cv::Scalar(160, 160, 160), 1);
      for (size_t e = 0; e < entries.size(); ++e) {
        const Series& s = series_[entries[e]];
        const cv::Scalar color = s.color ? *s.color : paletteColor(static_cast<int>(entries[e]));
        const int y = box.y + 4 + row_h * static_cast<int>(e) + row_h / 2;
        const int x = box.x + 6;
        if (s.style == SeriesStyle::Bars)
          cv::rectangle(img, cv::Rect(x + 4, y - 5, sample_w - 8, 10), color, cv::FILLED);
        if (s.style == SeriesStyle::Line || s.style == SeriesStyle::LinePoints)
          cv::line(img, {x, y}, {x + sample_w - 4, y}, color, std::max(1, s.thickness), cv::LINE_AA);
        if (s.style == SeriesStyle::Points || s.style == SeriesStyle::LinePoints)
          cv::circle(img, {x + (sample_w - 4) / 2, y}, std::max(2, s.marker_radius), color,
                     cv::FILLED, cv::LINE_AA);
        cv::putText(img, s.label, {x + sample_w, y + 5}, kFont, kTickFontScale, kBlack, 1,
                    cv::LINE_AA);
      }
    }
  }
  return img;
}

}  // namespace spinradar::plot
