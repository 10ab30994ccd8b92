#include "mrpt_yesslam/types.h"

#include <cmath>

namespace mrpt_yesslam
{
cv::Rect coveringRect(const cv::Rect2f& box, double margin, int scale, const cv::Rect& image)
{
	const double mx = box.width * margin, my = box.height * margin, s = scale;
	return cv::Rect(cv::Point(static_cast<int>(std::floor((box.x - mx) / s)),
							  static_cast<int>(std::floor((box.y - my) / s))),
					cv::Point(static_cast<int>(std::ceil((box.br().x + mx) / s)),
							  static_cast<int>(std::ceil((box.br().y + my) / s)))) &
		   image;
}

double boxIoU(const cv::Rect2f& a, const cv::Rect2f& b)
{
	const double inter = (a & b).area();
	const double uni = static_cast<double>(a.area()) + b.area() - inter;
	return uni > 0 ? inter / uni : 0.0;
}
}  // namespace mrpt_yesslam
