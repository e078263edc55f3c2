#pragma once
// Brute-force Hamming matching of binary descriptors with the nearest-neighbour ratio test.
#include <vector>

#include <opencv2/core/mat.hpp>

namespace spinradar {

struct Match {
  int i1 = 0;  ///< row in the first frame's descriptors / keypoints
  int i2 = 0;  ///< row in the second frame's
  float distance = 0.f;
};

/// For each row of d1, finds its two nearest rows of d2; keeps it when best < nndr * second.
/// `out` is cleared and filled; buffers are reused across calls.
void matchDescriptors(const cv::Mat& d1, const cv::Mat& d2, double nndr, std::vector<Match>& out);

/// The kernels behind matchDescriptors (all give the same matches; `bench` times each).
enum class MatchKernel { Avx512, Avx2, Scalar };
const char* matchKernelName(MatchKernel kernel);
/// The kernel matchDescriptors uses for 32-byte (ORB) descriptors on this CPU.
MatchKernel matchKernelUsed();
/// matchDescriptors with the given kernel; false (and `out` empty) when this CPU lacks it or the
/// descriptors are not 32 bytes wide (the SIMD kernels' only width).
bool matchDescriptorsWith(MatchKernel kernel, const cv::Mat& d1, const cv::Mat& d2, double nndr,
                          std::vector<Match>& out);

}  // namespace spinradar
