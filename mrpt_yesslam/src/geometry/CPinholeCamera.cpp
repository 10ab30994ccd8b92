#include "mrpt_yesslam/geometry/CPinholeCamera.h"

#include <opencv2/calib3d.hpp>

namespace mrpt_yesslam
{
void CPinholeCamera::undistort(std::vector<cv::Point2f>& pixels) const
{
	if (!distorted() || pixels.empty()) return;
	const cv::Matx33d K(fx_, 0, cx_, 0, fy_, cy_, 0, 0, 1);
	const cv::Matx<double, 1, 5> D(dist_[0], dist_[1], dist_[2], dist_[3], dist_[4]);
	std::vector<cv::Point2f> out;
	// P = K: the result stays in pixels of the same intrinsics, without distortion.
	cv::undistortPoints(pixels, out, K, D, cv::noArray(), K);
	pixels.swap(out);
}
}  // namespace mrpt_yesslam
