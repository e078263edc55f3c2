#pragma once
// The matcher's kernels, exposed to the tests so that every path is checked on machines that
// have it. Use matchDescriptors() (matcher.hpp), which picks the fastest.
#include <cstdint>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "spinradar/features/matcher.hpp"

namespace spinradar::detail {

/// Portable kernel (64-bit POPCNT), any descriptor width. Appends to `out`.
void matchScalar(const cv::Mat& d1, const cv::Mat& d2, double nndr, std::vector<Match>& out);

/// AVX-512 VPOPCNTDQ kernel for 32-byte descriptors, eight train rows per instruction.
/// Returns false (and does nothing) when the CPU lacks the instructions. Appends to `out`.
bool matchAvx512(const cv::Mat& d1, const cv::Mat& d2, double nndr, std::vector<Match>& out);

/// AVX2 kernel for 32-byte descriptors (nibble-table popcount, four train rows per register).
/// Returns false (and does nothing) when the CPU lacks AVX2. Appends to `out`.
bool matchAvx2(const cv::Mat& d1, const cv::Mat& d2, double nndr, std::vector<Match>& out);

}  // namespace spinradar::detail
