#pragma once
// Keypoint depth at the colour image's moment when the depth image was taken at another one.
// RGB-D cameras run their colour and depth streams on separate clocks: the real Bonn and TUM frames pair images up to
// half a frame apart. A hand-held camera turning 20 deg/s moves the scene a few pixels in that time, so the depth under
// a keypoint belongs to a neighbouring surface point, and a translating camera reads every depth a millimetre off. With
// both stamps known (TUM lists) and the motion model's velocity, each keypoint's depth is read where its scene point
// was at the depth image's moment and carried back to the colour image's (as a rolling-shutter or time-offset
// correction in VIO carries measurements to one moment, e.g. VINS-Mono's td).
#include <mrpt/poses/CPose3D.h>

#include <opencv2/core.hpp>

#include "mrpt_yesslam/data/TFeatures.h"
#include "mrpt_yesslam/geometry/CPinholeCamera.h"

namespace mrpt_yesslam
{
/** Re-reads each keypoint's depth (keypoints undistorted, depth image raw as recorded, CV_32F
 * metres) for a depth image taken by the camera at pose `depthCamera` relative to the colour
 * image's camera (T_colour_depth). A keypoint whose depth cannot be read there loses it (0).
 * Returns how many keypoints had depth before and have none now. */
std::size_t moveDepthToColourMoment(TFeatures& features, const cv::Mat& depthMetres, const CPinholeCamera& camera,
									const mrpt::poses::CPose3D& depthCamera);
}  // namespace mrpt_yesslam
