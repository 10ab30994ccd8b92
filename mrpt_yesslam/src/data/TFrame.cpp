#include "mrpt_yesslam/data/TFrame.h"

namespace mrpt_yesslam
{
cv::Point3d TFrame::backProject(std::size_t i) const
{
	const double z = features.depth[i];
	const auto& p = features.keypoints[i].pt;
	return {(p.x - camera.cx()) * z / camera.fx(), (p.y - camera.cy()) * z / camera.fy(), z};
}
}  // namespace mrpt_yesslam
