#include "mrpt_yesslam/detection/CAsyncDetector.h"

#include <chrono>
#include <stdexcept>

#include "mrpt_yesslam/util/Stopwatch.h"

namespace mrpt_yesslam
{
CAsyncDetector::CAsyncDetector(std::unique_ptr<CObjectDetector> detector) : det_(std::move(detector))
{
	if (!det_) throw std::invalid_argument("CAsyncDetector needs a detector");
}

void CAsyncDetector::submit(const cv::Mat& bgr, double timestamp)
{
	if (pending_.valid()) throw std::logic_error("CAsyncDetector::submit: the previous frame was not collected with get()");
	pending_ = worker_.submit(
		[this, bgr, timestamp]
		{
			const auto t0 = std::chrono::steady_clock::now();
			auto d = det_->detect(bgr, timestamp);
			lastMs_ = msSince(t0);
			return d;
		});
}

std::vector<TDetection> CAsyncDetector::get(double* detectMs)
{
	if (!pending_.valid()) throw std::logic_error("CAsyncDetector::get: no frame was submitted");
	auto pending = std::move(pending_);
	auto d = pending.get();
	if (detectMs) *detectMs = lastMs_;
	return d;
}
}  // namespace mrpt_yesslam
