#include "spinradar/features/orb_descriptors.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <opencv2/core.hpp>

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
  // cv::ORB's test pattern for patch sizes other than 31: 512 points drawn by its fixed-seed RNG.
  pattern_.resize(512);
  cv::RNG rng(0x34985739);
  for (auto& p : pattern_) {
    p.x = rng.uniform(-patch_size / 2, patch_size / 2 + 1);
    p.y = rng.uniform(-patch_size / 2, patch_size / 2 + 1);
  }
  offsets_step_ = 0;
  orb_.reset();
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
  const int W = image.cols, H = image.rows, half = patch_size_ / 2;
  if (keypoints.empty() || W <= 2 * patch_size_ || H <= 2 * patch_size_) {
    keypoints.clear();
    resizeRows(descriptors, 0, 32);
    return;
  }
  if (use_opencv_ || patch_size_ == 31) {  // 31: ORB's built-in pattern, not rebuilt here
    describeWithOpenCv(image, projector, keypoints, descriptors);
    return;
  }
  // Blur as cv::ORB does: it blurs inside a copy with a reflected border, which gives the same
  // bytes as blurring the image with reflected borders (and the descriptors only read pixels a
  // patch away from the edges anyway).
  blur_.apply(image, blurred_);
  const cv::Mat& blurred = blurred_;

  const int step = static_cast<int>(blurred.step);
  if (offsets_step_ != blurred.step) {
    offsets_.resize(pattern_.size());
    for (size_t i = 0; i < pattern_.size(); ++i) offsets_[i] = pattern_[i].y * step + pattern_[i].x;
    offsets_step_ = blurred.step;
  }
  kept_.clear();
  kept_.reserve(keypoints.size());
  resizeRows(descriptors, static_cast<int>(keypoints.size()), 32);
  int rows = 0;
  for (const Keypoint& kp : keypoints) {
    const cv::Point2f px = projector.toPixel(kp.x, kp.y);
    // ORB's edge filter: the rounded pixel at least patch_size from every border.
    const int u = cvRound(px.x), v = cvRound(px.y);
    if (u < patch_size_ || u >= W - patch_size_ || v < patch_size_ || v >= H - patch_size_) continue;
    const uint8_t* c = blurred.ptr<uint8_t>(v) + u;
    uint8_t* d = descriptors.ptr<uint8_t>(rows++);
    if (!oriented_) {
      const int* o = offsets_.data();
      for (int i = 0; i < 32; ++i, o += 16) {
        int val = 0;
        for (int j = 0; j < 8; ++j) val |= (c[o[2 * j]] < c[o[2 * j + 1]]) << j;
        d[i] = static_cast<uint8_t>(val);
      }
    } else {
      // As ORB's rotated tests, in the same float operations.
      float angle = icAngle(image, u, v, half, umax_);
      angle *= static_cast<float>(CV_PI / 180.f);
      const float a = static_cast<float>(std::cos(angle)), b = static_cast<float>(std::sin(angle));
      auto value = [&](const cv::Point& p) {
        const float x = p.x * a - p.y * b, y = p.x * b + p.y * a;
        return c[cvRound(y) * step + cvRound(x)];
      };
      const cv::Point* p = pattern_.data();
      for (int i = 0; i < 32; ++i, p += 16) {
        int val = 0;
        for (int j = 0; j < 8; ++j) val |= (value(p[2 * j]) < value(p[2 * j + 1])) << j;
        d[i] = static_cast<uint8_t>(val);
      }
    }
    kept_.push_back(kp);
  }
  resizeRows(descriptors, rows, 32);
  keypoints.swap(kept_);
}

void OrbDescriber::describeWithOpenCv(const cv::Mat& image, const CartesianProjector& projector,
                                      std::vector<Keypoint>& keypoints, cv::Mat& descriptors) {
  cv_kps_.clear();
  cv_kps_.reserve(keypoints.size());
  const int half = patch_size_ / 2;
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const cv::Point2f px = projector.toPixel(keypoints[i].x, keypoints[i].y);
    // class_id carries the index through ORB, which drops keypoints near the border.
    cv::KeyPoint k(px, static_cast<float>(patch_size_), 0.f, keypoints[i].power, 0, static_cast<int>(i));
    const int u = cvRound(px.x), v = cvRound(px.y);
    if (oriented_ && u >= half && v >= half && u + half < image.cols && v + half < image.rows)
      k.angle = icAngle(image, u, v, half, umax_);
    cv_kps_.push_back(k);
  }
  // One pyramid level: radar keypoints come with their own positions and a fixed scale.
  if (!orb_) orb_ = cv::ORB::create(500, 1.2f, 1, patch_size_, 0, 2, cv::ORB::HARRIS_SCORE, patch_size_);
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
