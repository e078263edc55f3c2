#pragma once
// Small chart renderer on OpenCV: one set of axes per Plot (ticks, grid, labels, title,
// legend) holding line, scatter, step/bar (histogram) series; figures are composed by tiling
// rendered panels. Enough for evaluation and diagnosis reports without a Python stack.
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace spinradar::plot {

enum class SeriesStyle { Line, Points, LinePoints, Bars };

struct Series {
  std::string label;             ///< legend entry (empty = not in the legend)
  std::vector<double> x, y;      ///< same length; non-finite points are skipped (break lines)
  SeriesStyle style = SeriesStyle::Line;
  std::optional<cv::Scalar> color;  ///< BGR; default: the palette, in order of addition
  int thickness = 2;             ///< line width, px
  int marker_radius = 3;         ///< px, for Points / LinePoints
  double bar_width = 0;          ///< data units, Bars only (0: spacing of consecutive x)
};

/// Default palette (BGR), colour-blind friendly (Okabe-Ito).
cv::Scalar paletteColor(int index);

struct Histogram {
  std::vector<double> centres;  ///< bin centres
  std::vector<double> counts;   ///< counts (or densities)
  double width = 0;             ///< bin width
};
/// `bins` equal bins over [lo, hi] (lo == hi: data range). Values outside are ignored.
Histogram histogram(const std::vector<double>& values, int bins, double lo = 0, double hi = 0);

class Plot {
 public:
  Plot& title(std::string t);
  Plot& xlabel(std::string l);
  Plot& ylabel(std::string l);
  /// title, xlabel and ylabel at once.
  Plot& labels(std::string t, std::string x, std::string y);
  Plot& xlim(double lo, double hi);
  Plot& ylim(double lo, double hi);
  Plot& equalAspect(bool on = true);  ///< same metres per pixel on both axes (trajectories)
  Plot& grid(bool on = true);
  Plot& legend(bool on = true);

  Plot& line(const std::vector<double>& x, const std::vector<double>& y, std::string label = {},
             std::optional<cv::Scalar> color = {}, int thickness = 2);
  Plot& scatter(const std::vector<double>& x, const std::vector<double>& y,
                std::string label = {}, std::optional<cv::Scalar> color = {}, int radius = 3);
  Plot& bars(const Histogram& h, std::string label = {}, std::optional<cv::Scalar> color = {});
  Plot& add(Series s);

  /// Renders the axes to a BGR image of the given size (white background).
  cv::Mat render(int width = 800, int height = 600) const;
  /// render() + saveImage; throws std::runtime_error naming the file on failure.
  void save(const std::string& path, int width = 800, int height = 600) const;

  const std::vector<Series>& series() const { return series_; }

 private:
  std::vector<Series> series_;
  std::string title_, xlabel_, ylabel_;
  std::optional<std::pair<double, double>> xlim_, ylim_;
  bool equal_aspect_ = false, grid_ = true, legend_ = true;
};

/// "Nice" tick positions (1, 2, 5 x 10^k steps) covering [lo, hi], about `target` of them.
std::vector<double> niceTicks(double lo, double hi, int target = 6);

/// Tiles panels (all resized to the first panel's size) into `cols` columns.
cv::Mat tile(const std::vector<cv::Mat>& panels, int cols);
/// Writes a .png (8-bit, 1/3/4 channels) with an error naming the file.
void saveImage(const cv::Mat& image, const std::string& path);
/// Throws std::runtime_error naming `path` when it is not a .png file name (so a command can
/// refuse `--plot x.txt` before doing any work).
void checkImagePath(const std::string& path);

}  // namespace spinradar::plot
