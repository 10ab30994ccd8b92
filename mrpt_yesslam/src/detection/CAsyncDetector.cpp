#include "mrpt_yesslam/detection/CAsyncDetector.h"

#include <algorithm>
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
	pending_.emplace_back(
		timestamp, worker_.submit(
					   [this, bgr, timestamp]
					   {
						   const auto t0 = std::chrono::steady_clock::now();
						   auto d = det_->detect(bgr, timestamp);
						   return std::make_pair(std::move(d), msSince(t0));
					   }));
}

bool CAsyncDetector::submitted(double timestamp) const
{
	return std::any_of(pending_.begin(), pending_.end(), [&](const auto& p) { return p.first == timestamp; });
}

std::vector<TDetection> CAsyncDetector::get(double timestamp, double* detectMs)
{
	const auto it = std::find_if(pending_.begin(), pending_.end(), [&](const auto& p) { return p.first == timestamp; });
	if (it == pending_.end()) throw std::logic_error("CAsyncDetector::get: that frame was not submitted");
	auto pending = std::move(it->second);
	pending_.erase(it);
	// Frames older than this one that were never collected (detected ahead, then skipped by the
	// caller) are dropped: their futures are let go, the worker finishes them in the background.
	// Newer ones stay: the next frame may have been submitted before this one was (the first frame
	// of a run is submitted when it is processed, after the second was read ahead).
	pending_.erase(std::remove_if(pending_.begin(), pending_.end(), [&](const auto& p) { return p.first < timestamp; }), pending_.end());
	auto [d, ms] = pending.get();
	if (detectMs) *detectMs = ms;
	return std::move(d);
}

std::vector<TDetection> CAsyncDetector::get(double* detectMs)
{
	if (pending_.empty()) throw std::logic_error("CAsyncDetector::get: no frame was submitted");
	return get(pending_.front().first, detectMs);  // the first submitted (the oldest, for in-order callers)
}
}  // namespace mrpt_yesslam
