#include "mrpt_yesslam/detection/CHogPeopleDetector.h"

#include <cmath>

namespace mrpt_yesslam
{
CHogPeopleDetector::CHogPeopleDetector(const TOptions& o) : CObjectDetector(o)
{
	hog_.setSVMDetector(cv::HOGDescriptor::getDefaultPeopleDetector());
	setClassNames({"person"}, "hog");
}

std::vector<TDetection> CHogPeopleDetector::detectImpl(const cv::Mat& bgr, double)
{
	std::vector<cv::Rect> found;
	std::vector<double> weights;
	hog_.detectMultiScale(bgr, found, weights, 0, cv::Size(8, 8), cv::Size(), 1.05, 2.0);
	std::vector<TDetection> out;
	for (std::size_t i = 0; i < found.size(); i++)
	{
		TDetection d;
		d.classId = 0;
		d.score = static_cast<float>(1.0 / (1.0 + std::exp(-(i < weights.size() ? weights[i] : 0.0))));
		d.box = cv::Rect2f(found[i]);
		out.push_back(d);
	}
	return out;
}
}  // namespace mrpt_yesslam
