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
	submit(bgr, timestamp, nextKey_);
}

void CAsyncDetector::submit(const cv::Mat& bgr, double timestamp, std::size_t key)
{
	nextKey_ = std::max(nextKey_, key + 1);
	pending_.erase(std::remove_if(pending_.begin(), pending_.end(), [&](const TPending& p) { return p.key == key; }),
				   pending_.end());
	pending_.push_back(TPending{key, timestamp,
								worker_.submit(
									[this, bgr, timestamp]
									{
										const auto t0 = std::chrono::steady_clock::now();
										auto d = det_->detect(bgr, timestamp);
										return std::make_pair(std::move(d), msSince(t0));
									})});
}

bool CAsyncDetector::submitted(std::size_t key, double timestamp) const
{
	return std::any_of(pending_.begin(), pending_.end(),
					   [&](const TPending& p) { return p.key == key && p.timestamp == timestamp; });
}

std::vector<TDetection> CAsyncDetector::get(std::size_t key, double* detectMs)
{
	const auto it = std::find_if(pending_.begin(), pending_.end(), [&](const TPending& p) { return p.key == key; });
	if (it == pending_.end()) throw std::logic_error("CAsyncDetector::get: that frame was not submitted");
	auto pending = std::move(it->result);
	pending_.erase(it);
	// Frames numbered below this one that were never collected (detected ahead, then skipped by
	// the caller) are dropped: their futures are let go, the worker finishes them in the
	// background. Higher-numbered ones stay, whatever order they were submitted in.
	pending_.erase(std::remove_if(pending_.begin(), pending_.end(), [&](const TPending& p) { return p.key < key; }),
				   pending_.end());
	auto [d, ms] = pending.get();
	if (detectMs) *detectMs = ms;
	return std::move(d);
}

void CAsyncDetector::releaseModel()
{
	// Including the dropped frames' tasks, which no future waits for (get() lets them finish in the background).
	worker_.waitIdle();
	det_->releaseModel();
}

std::vector<TDetection> CAsyncDetector::get(double* detectMs)
{
	if (pending_.empty()) throw std::logic_error("CAsyncDetector::get: no frame was submitted");
	return get(pending_.front().key, detectMs);  // the first submitted (the oldest, for in-order callers)
}
}  // namespace mrpt_yesslam
