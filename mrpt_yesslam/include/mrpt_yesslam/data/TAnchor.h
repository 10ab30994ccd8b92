#pragma once
// Where a frame hangs in the map: from its reference keyframe, so that a pose used later follows
// the keyframe when a loop correction or a global BA moves it. Map data shared by tracking (which
// makes anchors), the keyframe decision (recent frames) and the trajectory records.
#include <mrpt/poses/CPose3D.h>

#include <optional>

#include "mrpt_yesslam/data/CSparseMap.h"

namespace mrpt_yesslam
{
/** A frame's pose as its reference keyframe's pose times T_ref_frame. Anything that needs a frame's
 * pose later (a delayed keyframe, the next prediction, the trajectory) is re-derived from the
 * keyframe's pose at that time, so that a loop correction or a global BA landing in between
 * carries over instead of leaving the pose in the frame from before it (issue 28). */
struct TAnchor
{
	std::optional<TKeyFrameId> refKf;  //!< none: `relative` is T_w_frame
	mrpt::poses::CPose3D relative;
	/** The pose in the map as it is now. */
	mrpt::poses::CPose3D poseIn(const CSparseMap& map) const
	{
		return refKf ? map.keyFramePose(*refKf) + relative : relative;
	}
};
}  // namespace mrpt_yesslam
