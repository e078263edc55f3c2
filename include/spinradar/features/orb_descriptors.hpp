#pragma once
// ORB descriptors of radar keypoints on the Cartesian image.
#include <vector>

#include <opencv2/core/mat.hpp>
#include <opencv2/features2d.hpp>

#include "spinradar/features/cartesian.hpp"
#include "spinradar/features/gaussian_blur.hpp"
#include "spinradar/core/feature_frame.hpp"

namespace spinradar {

/// Gives exactly cv::ORB::compute's descriptors (one level, WTA_K 2, edge threshold = patch
/// size; tested byte for byte) without its per-call image pyramid, keypoint copies and
/// allocations: the image is blurred as ORB blurs it (7 x 7, sigma 2 on a view into a bordered
/// copy: the same bytes, by GaussianBlur8u's View path into a reused image), then each
/// descriptor is 256 comparisons at precomputed offsets. Patch size 31 uses ORB's built-in test
/// pattern, which is not rebuilt here: that size goes to cv::ORB.
class OrbDescriber {
 public:
  /// `patch_size`: ORB patch in pixels (odd). Keypoints closer than the patch size to the image
  /// border (ORB's edge threshold) get no descriptor. `oriented`: steer each descriptor by the
  /// intensity-centroid angle of its patch, as ORB's detector would (cv::ORB::compute does not
  /// compute angles for given keypoints); false (default) = upright pattern, as the authors' code
  /// effectively does. Upright matches better for the few degrees radar scans turn between
  /// frames: the centroid angle of a blob-like radar return is dominated by noise (measured on a
  /// synthetic blob image: 637 vs 288 correct matches at 0 deg, 562 vs 324 at 5 deg; oriented
  /// wins beyond about 10 deg: 318 vs 228 at 12 deg).
  explicit OrbDescriber(int patch_size = 21, bool oriented = false);
  void setPatchSize(int patch_size);
  void setOriented(bool oriented) { oriented_ = oriented; }
  /// Computes through cv::ORB::compute instead (always so for patch size 31). Both give the same
  /// descriptors; the switch exists so that tests compare the two.
  void setUseOpenCv(bool use) { use_opencv_ = use; }

  /// Computes one 32-byte ORB descriptor per keypoint at its pixel on `image` (as placed by
  /// `projector`). Keypoints without a descriptor (patch off the image) are removed from
  /// `keypoints`, keeping order, so that row i of `descriptors` belongs to keypoints[i].
  void describe(const cv::Mat& image, const CartesianProjector& projector, std::vector<Keypoint>& keypoints,
                cv::Mat& descriptors);

 private:
  void describeWithOpenCv(const cv::Mat& image, const CartesianProjector& projector,
                          std::vector<Keypoint>& keypoints, cv::Mat& descriptors);

  int patch_size_ = 21;
  bool oriented_ = false;
  std::vector<int> umax_;  ///< half widths of the circular patch per row (ORB's IC angle)
  std::vector<cv::Point> pattern_;  ///< ORB's 512 test points for this patch size (256 pairs)
  std::vector<int> offsets_;        ///< pattern_ as byte offsets for `offsets_step_`
  size_t offsets_step_ = 0;
  GaussianBlur8u blur_{7, 2.0, GaussianBlur8u::Path::View};  ///< ORB's blur (of a bordered copy)
  cv::Mat blurred_;
  std::vector<Keypoint> kept_;
  bool use_opencv_ = false;
  cv::Ptr<cv::ORB> orb_;  ///< created on first use of the OpenCV path
  std::vector<cv::KeyPoint> cv_kps_;
  cv::Mat raw_;
};

/// Keeps the `max_keypoints` keypoints of highest power (all when max_keypoints <= 0 or there
/// are fewer), preserving their order. `scratch` is reused between calls.
void keepStrongest(std::vector<Keypoint>& keypoints, int max_keypoints, std::vector<float>& scratch);

}  // namespace spinradar
