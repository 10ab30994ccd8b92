#pragma once
// Building and checking the one frame type every stage consumes:
// mrpt::obs::CObservation3DRangeScan with a colour image and a registered depth image.
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <opencv2/core.hpp>
#include <string>

#include "mrpt_yesslam/io/RgbdCamera.h"

namespace mrpt_yesslam
{
/** Builds a frame from a BGR 8-bit image and a 16-bit depth image whose raw values are copied
 * unchanged (metres = raw / camera.depthScale, stored as rangeUnits). Depth is registered to
 * colour, so both camera models are the colour intrinsics. */
mrpt::obs::CObservation3DRangeScan::Ptr makeRgbdObservation(double timestamp, const cv::Mat& bgr,
															const cv::Mat& depth16, const TRgbdCamera& camera,
															const std::string& sensorLabel = "RGBD");

/** Checks that a frame can be used: a colour image, a non-empty depth image of the same size,
 * finite positive rangeUnits and sane intrinsics. Throws InputError("where: problem"). */
void validateRgbdObservation(const mrpt::obs::CObservation3DRangeScan& obs, const std::string& where);

/** The depth image in metres (CV_32FC1, 0 where there is no depth). */
cv::Mat depthInMetres(const mrpt::obs::CObservation3DRangeScan& obs);

/** The median of a frame's valid depth in metres, from every `step`-th pixel of every `step`-th
 * row (0 when none is valid): a cheap check that the depth scale is right. */
double medianDepth(const mrpt::obs::CObservation3DRangeScan& obs, int step = 8);

/** Whether a run's typical depth (the median of its frames' medianDepth) is one an RGB-D camera
 * measures; empty when it is, else why not, naming the likely cause (a wrong depth scale). */
std::string implausibleDepthReason(double typicalDepthMetres);

/** The timestamp of a frame in seconds (Unix epoch, as in TUM files). */
double observationTime(const mrpt::obs::CObservation& obs);
}  // namespace mrpt_yesslam
