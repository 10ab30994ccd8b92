#pragma once
// yesslam-sim's depth sensor models: the Kinect model (white noise growing with depth squared, quantised disparity,
// range limits, dropouts at depth edges and in small holes) and the real sensor fitted to the real Xtion/Kinect frames
// (--real-sensor). The reasons are in SimSensorModel.cpp, the measurements in docs/benchmarks.md.
#include <opencv2/core.hpp>

#include <random>

#include "mrpt_yesslam/io/RgbdCamera.h"

namespace mrpt_yesslam
{
/** The real sensor's depth error and dropouts on depth `z` (CV_32F, metres): a smooth error field,
 * blobs lost on dark surfaces (`grey`, the image the depth camera saw) and in the registration
 * border; `drop` holds the dropout draws (coherentUniform). */
void addRealSensorDepthError(cv::Mat& z, const cv::Mat& grey, const cv::Mat& drop, std::mt19937& rng);

/** Random numbers uniform on [0, 1] at every pixel but alike over about `cell` pixels. */
cv::Mat coherentUniform(cv::Size size, int cell, std::mt19937& rng);

/** Per-pixel depth noise (sigma = whiteK z^2), disparity quantisation, range limits, dropouts within
 * `edgeRadius` px of depth edges (draws from `drop`, per pixel when empty) and small holes. */
void addDepthNoise(cv::Mat& z, std::mt19937& rng, const TRgbdCamera& cam, float whiteK, const cv::Mat& drop,
				   int edgeRadius);
}  // namespace mrpt_yesslam
