#pragma once
// Keypoints of a rolling-shutter colour camera moved to where a global shutter would have seen them.
// The colour sensors of the Kinect and the Xtion read their rows one after another over most of a
// frame time, so a camera turning 10-20 deg/s (the real Bonn slice: median 11, p90 22) sees its
// bottom rows 0.3-0.7 deg later than its top rows: a 3-7 px shear that a single pose per image
// cannot explain. As ORB-SLAM3 and VINS-Mono's rolling-shutter models do to first order, each
// keypoint is carried along the motion model's velocity from its row's moment to the image
// stamp's moment (taken as the middle row's), so tracking, BA and the map see one moment per frame.
#include <mrpt/poses/CPose3D.h>

#include "mrpt_yesslam/data/TFeatures.h"
#include "mrpt_yesslam/geometry/CPinholeCamera.h"

namespace mrpt_yesslam
{
/** The readout assumed for a camera that does not state it (seconds): Kinect v1 and Xtion read
 * both images with rolling-shutter CMOS sensors; Kerl et al. (ICCV 2015) simulate them with 28 ms.
 * Measured here, not fitted: the real Bonn and fr1 frames gain most between 20 and 40 ms, and
 * reading the rows the other way (-28 ms) makes both worse (docs/benchmarks.md, "Rolling shutter"). */
constexpr double kConsumerRgbdReadout = 0.028;

/** Moves each keypoint (undistorted pixels, with its depth, 0 = none) of an image whose rows were
 * read top to bottom over one readout to the middle row's moment. `motionOverReadout` is the
 * camera's motion over the readout (the camera's pose at its end in the camera's frame at its
 * start). A keypoint without depth moves as a far point (by the rotation alone). Keypoints that
 * leave the image stay where they were. */
void unrollShutter(TFeatures& features, const CPinholeCamera& camera, const mrpt::poses::CPose3D& motionOverReadout);
}  // namespace mrpt_yesslam
