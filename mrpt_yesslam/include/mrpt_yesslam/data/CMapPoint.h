#pragma once
// A 3D landmark of the sparse map (ORB-SLAM2's MapPoint): its position, a descriptor, and the
// keyframes that observe it. Only CSparseMap changes it, under the map's lock; everyone else gets
// copies.
#include <mrpt/math/TPoint3D.h>

#include <cstdint>
#include <iosfwd>
#include <map>
#include <opencv2/core.hpp>

#include "mrpt_yesslam/data/TFrame.h"

namespace mrpt_yesslam
{
/** Stable id of a keyframe: given in insertion order, never reused, independent of storage. */
using TKeyFrameId = std::size_t;

/** A 3D landmark. */
struct CMapPoint
{
	TPointId id = -1;
	mrpt::math::TPoint3D position;                    //!< world frame, metres
	cv::Mat descriptor;                               //!< 1x32 CV_8U, from the keyframe that created it
	cv::Vec3b color;                                  //!< BGR
	std::map<TKeyFrameId, std::size_t> observations;  //!< keyframe id -> keypoint index
	TKeyFrameId firstKeyFrame = 0;                    //!< the keyframe that created it
	int visible = 1;                                  //!< times it was inside a tracked frame's view
	int found = 1;                                    //!< times tracking matched it
	/** Consecutive tracked frames that saw through it: farther surfaces measured where it should be
	 * in front (it has moved away). Not saved: a tracking statistic. */
	int seenThrough = 0;
	bool bad = false;          //!< culled, fused or left without observations; kept only so that old ids resolve
	TPointId replacedBy = -1;  //!< after a fusion: the point that took its observations

	/** Format version written by serialize(); read() refuses newer ones. */
	static constexpr std::uint32_t kSerialVersion = 1;
	/** Writes the point in a compact binary form (little-endian, versioned) for map saving. */
	void serialize(std::ostream& out) const;
	/** Reads what serialize() wrote; throws std::runtime_error for a truncated stream or an unknown version. */
	static CMapPoint deserialize(std::istream& in);
};
}  // namespace mrpt_yesslam
