#include "mrpt_yesslam/data/TFrame.h"

#include "mrpt_yesslam/geometry/CPinholeCamera.h"

namespace mrpt_yesslam
{
cv::Point3d TFrame::backProject(std::size_t i) const
{
	const auto& p = features.keypoints[i].pt;
	return CPinholeCamera(camera).backProject(p.x, p.y, features.depth[i]);
}
}  // namespace mrpt_yesslam
