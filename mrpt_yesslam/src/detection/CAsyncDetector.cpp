#include "mrpt_yesslam/detection/CAsyncDetector.h"

#include <stdexcept>

namespace mrpt_yesslam
{
CAsyncDetector::CAsyncDetector(std::unique_ptr<CObjectDetector> detector) : det_(std::move(detector))
{
	if (!det_) throw std::invalid_argument("CAsyncDetector needs a detector");
}

void CAsyncDetector::submit(const cv::Mat& bgr, double timestamp)
{
	if (pending_.valid()) throw std::logic_error("CAsyncDetector::submit: the previous frame was not collected with get()");
	pending_ = worker_.submit([this, bgr, timestamp] { return det_->detect(bgr, timestamp); });
}

std::vector<TDetection> CAsyncDetector::get()
{
	if (!pending_.valid()) throw std::logic_error("CAsyncDetector::get: no frame was submitted");
	auto pending = std::move(pending_);
	return pending.get();
}
}  // namespace mrpt_yesslam
