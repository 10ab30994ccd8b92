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
mrpt::obs::CObservation3DRangeScan::Ptr makeRgbdObservation(
	double timestamp, const cv::Mat& bgr, const cv::Mat& depth16, const TRgbdCamera& camera,
	const std::string& sensorLabel = "RGBD");

/** Checks that a frame can be used: a colour image, a non-empty depth image of the same size,
 * finite positive rangeUnits and sane intrinsics. Throws InputError("where: problem"). */
void validateRgbdObservation(const mrpt::obs::CObservation3DRangeScan& obs, const std::string& where);

/** The depth image in metres (CV_32FC1, 0 where there is no depth). */
cv::Mat depthInMetres(const mrpt::obs::CObservation3DRangeScan& obs);

/** The timestamp of a frame in seconds (Unix epoch, as in TUM files). */
double observationTime(const mrpt::obs::CObservation& obs);
}  // namespace mrpt_yesslam
