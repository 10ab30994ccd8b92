#pragma once
// Map points copied out of the map for a search (tracking's local map, a loop's place): the
// matcher (feature/) reads them without depending on the map itself.
#include <mrpt/math/TPoint3D.h>

#include <opencv2/core.hpp>
#include <vector>

#include "mrpt_yesslam/data/TFrame.h"

namespace mrpt_yesslam
{
/** What tracking searches a frame against: points near the current view, copied out. */
struct TLocalMapPoints
{
	std::vector<TPointId> ids;
	std::vector<mrpt::math::TPoint3D> positions;
	cv::Mat descriptors;  //!< one row per point
	/** How each point has been seen, for projection search (ORB-SLAM2's MapPoint normal and
	 * scale-invariance distances); one per point when the map gave them, empty for points made from
	 * a frame. `normals`: the mean unit direction from its keyframes' centres to it (world frame);
	 * `refDistances` and `refOctaves`: its distance from its reference keyframe (the one that made
	 * it, while it observes it) and the pyramid level it was seen at there. */
	std::vector<mrpt::math::TPoint3D> normals;
	std::vector<float> refDistances;
	std::vector<int> refOctaves;

	/** Whether every point carries how it has been seen. */
	bool hasViews() const { return !ids.empty() && normals.size() == ids.size(); }
};
}  // namespace mrpt_yesslam
