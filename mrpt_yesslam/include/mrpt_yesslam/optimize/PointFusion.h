#pragma once
// Fusing map points into a keyframe (ORB-SLAM2's ORBmatcher::Fuse): one search shared by local
// mapping (duplicates with the neighbouring keyframes) and loop closing (the place's points into the
// corrected keyframes), so that neither stage depends on the other.
#include <mrpt/poses/CPose3D.h>

#include <vector>

#include "mrpt_yesslam/data/CSparseMap.h"
#include "mrpt_yesslam/geometry/DepthNoise.h"

namespace mrpt_yesslam
{
/** ORB-SLAM2's Fuse search: `points` projected with `Twc` into keyframe `into`, each matched to the
 * closest keypoint within `radius` pixels (x scale^octave) and `maxHamming`, no ratio test; a
 * keypoint with depth must agree with the point's depth (3 sigma of the sensor's depth noise at
 * level 0, plus 2 cm), as ORB-SLAM2 checks the right-image coordinate. Shared by local
 * mapping's fusion with the neighbours and loop fusion. */
std::vector<TFuseCandidate> fuseCandidates(const CKeyFrame& into, const mrpt::poses::CPose3D& Twc,
										   const TLocalMapPoints& points, double radius, int maxHamming,
										   double scaleFactor, const TDepthNoise& depthNoise);
}  // namespace mrpt_yesslam
