#pragma once
// cv::GaussianBlur of 8-bit images, bit for bit, without its per-call allocations.
#include <cstdint>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace spinradar {

/// Gives exactly the bytes of cv::GaussianBlur(src, dst, Size(k, k), sigma, sigma,
/// BORDER_REFLECT_101) on CV_8UC1 images, in either of OpenCV 4's two 8-bit paths (tested
/// against OpenCV on noise, simulated and real radar images, several kernels and sizes):
///  - WholeImage: a whole image (or BORDER_ISOLATED). The bit-exact fixed-point path: taps in
///    1/256 that sum to exactly 256 (rounded from the double kernel with the error carried to
///    the next tap; ORB's 7 x 7 sigma 2: 18 34 48 56 48 34 18), integer sums, one rounding.
///  - View: a view into a larger image without BORDER_ISOLATED, the pixels around it standing
///    in for the border; this is what cv::ORB does (it blurs inside a bordered copy). OpenCV
///    then takes its generic separable filter in float (the float kernel; row sums and column
///    sums in its order of operations, fused multiply-adds where its AVX2 build fuses them;
///    rounded half to even). Here the image's own reflected border stands in for the pixels
///    around the view (the same bytes when they are that border, as in ORB). On a CPU without
///    AVX2 + FMA OpenCV runs its SSE build (multiply, then add) and so does this; only the
///    AVX2 + FMA case is tested here (the machines this project runs on).
/// cv::GaussianBlur builds a filter engine and its buffers on every call (23 small allocations
/// per ORB image, plus a copy of the image when blurring in place); this keeps a ring of `k`
/// rows of row sums and a padded row, reused: no allocation once `dst` has the size.
class GaussianBlur8u {
 public:
  enum class Path { WholeImage, View };
  /// `ksize`: odd, >= 1; `sigma` > 0 (pixels).
  GaussianBlur8u(int ksize, double sigma, Path path = Path::WholeImage);

  /// `src` CV_8UC1, any size >= 1 x 1; `dst` is (re)created with src's size and must not share
  /// memory with `src`.
  void apply(const cv::Mat& src, cv::Mat& dst);

  /// View path: 2 = AVX-512 when the CPU has it, else AVX2 + FMA (default); 1 = AVX2 + FMA at
  /// most; 0 = portable (OpenCV's non-AVX2 build: multiply, then add). Levels 2 and 1 give the
  /// same bytes (tested); the switch exists so that tests cover each.
  void setSimdLevel(int level) { simd_ = level; }

  /// The fixed-point path's taps in 1/256 (the View path uses the float kernel).
  const std::vector<uint32_t>& taps() const { return taps_; }

 private:
  int ksize_, radius_;
  Path path_;
  int simd_ = 2;
  std::vector<uint32_t> taps_;
  std::vector<float> float_taps_;
  std::vector<uint8_t> padded_;  ///< one source row with reflected ends
  std::vector<float> padded_float_;  ///< the same as floats (View)
  std::vector<uint32_t> ring_;   ///< row sums of ksize rows, slot = row % ksize (WholeImage)
  std::vector<float> float_ring_;  ///< the same in float (View)
};

}  // namespace spinradar
