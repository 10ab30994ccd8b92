#include "mrpt_yesslam/types.h"

namespace mrpt_yesslam
{
double boxIoU(const cv::Rect2f& a, const cv::Rect2f& b)
{
	const double inter = (a & b).area();
	const double uni = static_cast<double>(a.area()) + b.area() - inter;
	return uni > 0 ? inter / uni : 0.0;
}
}  // namespace mrpt_yesslam
