#include "mrpt_yesslam/util/CAsyncPngWriter.h"

#include "mrpt_yesslam/util/AtomicFile.h"

#include <chrono>

namespace mrpt_yesslam
{
CAsyncPngWriter::CAsyncPngWriter(std::size_t threads, std::size_t maxQueued) : maxQueued_(std::max<std::size_t>(1, maxQueued))
{
	for (std::size_t i = 0; i < std::max<std::size_t>(1, threads); i++) workers_.emplace_back([this] { loop(); });
}

CAsyncPngWriter::~CAsyncPngWriter()
{
	{
		std::lock_guard<std::mutex> lk(mtx_);
		stop_ = true;
	}
	cv_.notify_all();
	for (auto& t : workers_) t.join();
}

void CAsyncPngWriter::loop()
{
	for (;;)
	{
		TJob job;
		{
			std::unique_lock<std::mutex> lk(mtx_);
			cv_.wait(lk, [&] { return stop_ || !jobs_.empty(); });
			if (jobs_.empty()) return;	// stopping and drained
			job = std::move(jobs_.front());
			jobs_.pop_front();
			busy_++;
		}
		space_.notify_one();
		std::exception_ptr err;
		const auto t0 = std::chrono::steady_clock::now();
		try
		{
			writePngAtomically(job.path, job.img, job.compression);
			if (job.after) job.after();
		}
		catch (...)
		{
			err = std::current_exception();
		}
		{
			std::lock_guard<std::mutex> lk(mtx_);
			if (err && !error_) error_ = err;
			busy_--;
			busySeconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
		}
		idle_.notify_all();
	}
}

void CAsyncPngWriter::rethrow()
{
	if (error_)
	{
		auto e = error_;
		error_ = nullptr;
		std::rethrow_exception(e);
	}
}

void CAsyncPngWriter::write(const std::string& path, const cv::Mat& img, std::function<void()> after, int compression)
{
	{
		std::unique_lock<std::mutex> lk(mtx_);
		rethrow();
		space_.wait(lk, [&] { return jobs_.size() < maxQueued_; });
		jobs_.push_back({path, img, std::move(after), compression});
	}
	cv_.notify_one();
}

void CAsyncPngWriter::finish()
{
	std::unique_lock<std::mutex> lk(mtx_);
	idle_.wait(lk, [&] { return jobs_.empty() && busy_ == 0; });
	rethrow();
}

double CAsyncPngWriter::busySeconds()
{
	std::lock_guard<std::mutex> lk(mtx_);
	return busySeconds_;
}
}  // namespace mrpt_yesslam
