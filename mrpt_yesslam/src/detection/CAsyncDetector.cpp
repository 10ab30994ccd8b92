#include "mrpt_yesslam/detection/CAsyncDetector.h"

#include <stdexcept>

namespace mrpt_yesslam
{
CAsyncDetector::CAsyncDetector(std::unique_ptr<CObjectDetector> detector) : det_(std::move(detector))
{
	if (!det_) throw std::invalid_argument("CAsyncDetector needs a detector");
	worker_ = std::thread([this] { loop(); });
}

CAsyncDetector::~CAsyncDetector()
{
	{
		std::lock_guard<std::mutex> lk(m_);
		stop_ = true;
	}
	cv_.notify_all();
	worker_.join();
}

void CAsyncDetector::submit(const cv::Mat& bgr, double timestamp)
{
	{
		std::lock_guard<std::mutex> lk(m_);
		if (inFlight_) throw std::logic_error("CAsyncDetector::submit: the previous frame was not collected with get()");
		inFlight_ = true;
		job_.emplace(bgr, timestamp);
		result_.reset();
		error_ = nullptr;
	}
	cv_.notify_all();
}

std::vector<TDetection> CAsyncDetector::get()
{
	std::unique_lock<std::mutex> lk(m_);
	if (!inFlight_) throw std::logic_error("CAsyncDetector::get: no frame was submitted");
	cv_.wait(lk, [this] { return result_.has_value() || error_ != nullptr; });
	inFlight_ = false;
	if (error_)
	{
		auto e = error_;
		error_ = nullptr;
		std::rethrow_exception(e);
	}
	auto r = std::move(*result_);
	result_.reset();
	return r;
}

void CAsyncDetector::loop()
{
	for (;;)
	{
		std::pair<cv::Mat, double> job;
		{
			std::unique_lock<std::mutex> lk(m_);
			cv_.wait(lk, [this] { return stop_ || job_.has_value(); });
			if (stop_ && !job_) return;
			job = std::move(*job_);
			job_.reset();
		}
		std::vector<TDetection> r;
		std::exception_ptr err;
		try
		{
			r = det_->detect(job.first, job.second);
		}
		catch (...)
		{
			err = std::current_exception();
		}
		{
			std::lock_guard<std::mutex> lk(m_);
			if (err)
				error_ = err;
			else
				result_ = std::move(r);
		}
		cv_.notify_all();
	}
}
}  // namespace mrpt_yesslam
