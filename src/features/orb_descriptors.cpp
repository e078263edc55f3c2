#include "spinradar/features/orb_descriptors.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace spinradar {

namespace {
/// Makes `m` a rows x cols CV_8UC1 matrix, reusing its allocation (as a row range of it) when
/// large enough, so that steady-state calls do not allocate.
void resizeRows(cv::Mat& m, int rows, int cols) {
  if (!m.empty() || m.datastart) {
    cv::Size whole;
    cv::Point ofs;
    if (m.type() == CV_8UC1 && m.cols == cols && m.datastart) {
      m.locateROI(whole, ofs);
      if (ofs.x == 0 && ofs.y == 0 && whole.width == cols && whole.height >= rows) {
        m.adjustROI(0, rows - m.rows, 0, 0);
        return;
      }
    }
  }
  cv::Mat buf(std::max(rows, 1) * 3 / 2 + 16, cols, CV_8UC1);
  m = buf.rowRange(0, rows);
}
}  // namespace

OrbDescriber::OrbDescriber(int patch_size, bool oriented) : oriented_(oriented) { setPatchSize(patch_size); }

void OrbDescriber::setPatchSize(int patch_size) {
  if (patch_size < 5) throw std::invalid_argument("OrbDescriber: patch size must be >= 5");
  patch_size_ = patch_size;
  // One pyramid level: radar keypoints come with their own positions and a fixed scale.
  orb_ = cv::ORB::create(500, 1.2f, 1, patch_size, 0, 2, cv::ORB::HARRIS_SCORE, patch_size);
  // Circular patch of radius patch/2: umax[v] = half width of row v (symmetric, as ORB builds it).
  const int half = patch_size / 2;
  umax_.assign(half + 2, 0);
  const int vmax = static_cast<int>(std::floor(half * std::sqrt(2.0) / 2 + 1));
  const int vmin = static_cast<int>(std::ceil(half * std::sqrt(2.0) / 2));
  for (int v = 0; v <= vmax; ++v) umax_[v] = static_cast<int>(std::lround(std::sqrt(double(half) * half - v * v)));
  for (int v = half, v0 = 0; v >= vmin; --v) {
    while (umax_[v0] == umax_[v0 + 1]) ++v0;
    umax_[v] = v0;
    ++v0;
  }
}

namespace {
/// Intensity-centroid orientation (degrees) of the circular patch around integer pixel (u, v).
float icAngle(const cv::Mat& img, int u, int v, int half, const std::vector<int>& umax) {
  int m01 = 0, m10 = 0;
  const uint8_t* c = img.ptr<uint8_t>(v) + u;
  const int step = static_cast<int>(img.step1());
  for (int x = -half; x <= half; ++x) m10 += x * c[x];
  for (int y = 1; y <= half; ++y) {
    int vsum = 0;
    const int d = umax[y];
    for (int x = -d; x <= d; ++x) {
      const int top = c[x - y * step], bottom = c[x + y * step];
      vsum += bottom - top;
      m10 += x * (bottom + top);
    }
    m01 += y * vsum;
  }
  return cv::fastAtan2(float(m01), float(m10));
}
}  // namespace

void OrbDescriber::describe(const cv::Mat& image, const CartesianProjector& projector,
                            std::vector<Keypoint>& keypoints, cv::Mat& descriptors) {
  cv_kps_.clear();
  cv_kps_.reserve(keypoints.size());
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const cv::Point2f px = projector.toPixel(keypoints[i].x, keypoints[i].y);
    // class_id carries the index through ORB, which drops keypoints near the border.
    cv_kps_.emplace_back(px, static_cast<float>(patch_size_), -1.f, keypoints[i].power, 0, static_cast<int>(i));
  }
  if (cv_kps_.empty()) {
    keypoints.clear();
    resizeRows(descriptors, 0, 32);
    return;
  }
  if (oriented_) {
    const int half = patch_size_ / 2;
    for (auto& k : cv_kps_) {
      const int u = cvRound(k.pt.x), v = cvRound(k.pt.y);
      if (u >= half && v >= half && u + half < image.cols && v + half < image.rows)
        k.angle = icAngle(image, u, v, half, umax_);
      else
        k.angle = 0.f;  // ORB drops it anyway (closer than the edge threshold)
    }
  } else {
    for (auto& k : cv_kps_) k.angle = 0.f;
  }
  orb_->compute(image, cv_kps_, raw_);
  kept_.clear();
  kept_.reserve(cv_kps_.size());
  const int cols = raw_.empty() ? 32 : raw_.cols;
  resizeRows(descriptors, static_cast<int>(cv_kps_.size()), cols);
  for (size_t k = 0; k < cv_kps_.size(); ++k) {
    const int i = cv_kps_[k].class_id;
    if (i < 0 || i >= static_cast<int>(keypoints.size()))
      throw std::logic_error("OrbDescriber: ORB returned a keypoint it was not given");
    kept_.push_back(keypoints[i]);
    std::memcpy(descriptors.ptr(static_cast<int>(k)), raw_.ptr(static_cast<int>(k)), cols);
  }
  keypoints.swap(kept_);
}

void keepStrongest(std::vector<Keypoint>& keypoints, int max_keypoints, std::vector<float>& scratch) {
  if (max_keypoints <= 0 || keypoints.size() <= static_cast<size_t>(max_keypoints)) return;
  scratch.clear();
  for (const auto& k : keypoints) scratch.push_back(k.power);
  std::nth_element(scratch.begin(), scratch.begin() + (max_keypoints - 1), scratch.end(), std::greater<float>());
  const float cut = scratch[max_keypoints - 1];
  // Everything above the cut, then ties at the cut in order until the budget is used.
  size_t above = 0;
  for (const auto& k : keypoints) above += k.power > cut;
  size_t ties = static_cast<size_t>(max_keypoints) - above, out = 0;
  for (const auto& k : keypoints) {
    if (k.power > cut || (k.power == cut && ties > 0)) {
      if (k.power == cut && !(k.power > cut)) --ties;
      keypoints[out++] = k;
    }
  }
  keypoints.resize(out);
}

}  // namespace spinradar
