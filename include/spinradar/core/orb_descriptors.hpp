#pragma once
// ORB descriptors of radar keypoints on the Cartesian image.
#include <vector>

#include <opencv2/core/mat.hpp>
#include <opencv2/features2d.hpp>

#include "spinradar/core/cartesian.hpp"
#include "spinradar/core/feature_frame.hpp"

namespace spinradar {

class OrbDescriber {
 public:
  /// `patch_size`: ORB patch in pixels (odd). Keypoints closer than the patch size to the image
  /// border (ORB's edge threshold) get no descriptor.
  explicit OrbDescriber(int patch_size = 21);
  void setPatchSize(int patch_size);

  /// Computes one 32-byte ORB descriptor per keypoint at its pixel on `image` (as placed by
  /// `projector`). Keypoints without a descriptor (patch off the image) are removed from
  /// `keypoints`, keeping order, so that row i of `descriptors` belongs to keypoints[i].
  void describe(const cv::Mat& image, const CartesianProjector& projector, std::vector<Keypoint>& keypoints,
                cv::Mat& descriptors);

 private:
  int patch_size_ = 21;
  cv::Ptr<cv::ORB> orb_;
  std::vector<cv::KeyPoint> cv_kps_;
  std::vector<Keypoint> kept_;
  cv::Mat raw_;
};

/// Keeps the `max_keypoints` keypoints of highest power (all when max_keypoints <= 0 or there
/// are fewer), preserving their order. `scratch` is reused between calls.
void keepStrongest(std::vector<Keypoint>& keypoints, int max_keypoints, std::vector<float>& scratch);

}  // namespace spinradar
