#include "mrpt_yesslam/io/CPrefetchingSource.h"

#include <algorithm>

namespace mrpt_yesslam
{
CPrefetchingSource::CPrefetchingSource(std::unique_ptr<CInputSource> source, std::size_t depth)
	: source_(std::move(source)), depth_(std::max<std::size_t>(1, depth)), sizeHint_(source_->sizeHint()), path_(source_->path())
{
	reader_ = std::thread([this] { run(); });
}

CPrefetchingSource::~CPrefetchingSource()
{
	{
		std::lock_guard<std::mutex> lk(mutex_);
		stop_ = true;
	}
	changed_.notify_all();
	reader_.join();
}

void CPrefetchingSource::run()
{
	for (;;)
	{
		{
			std::unique_lock<std::mutex> lk(mutex_);
			changed_.wait(lk, [&] { return stop_ || queue_.size() < depth_; });
			if (stop_) return;
		}
		mrpt::obs::CObservation3DRangeScan::Ptr obs;
		std::exception_ptr err;
		try
		{
			obs = source_->next();
		}
		catch (...)
		{
			err = std::current_exception();
		}
		const bool more = obs != nullptr;
		{
			std::lock_guard<std::mutex> lk(mutex_);
			skipped_ = source_->skipped();
			if (more)
				queue_.push_back(std::move(obs));
			else
			{
				error_ = err;
				finished_ = true;
			}
		}
		changed_.notify_all();
		if (!more) return;
	}
}

mrpt::obs::CObservation3DRangeScan::Ptr CPrefetchingSource::next()
{
	std::unique_lock<std::mutex> lk(mutex_);
	changed_.wait(lk, [&] { return !queue_.empty() || finished_; });
	if (!queue_.empty())
	{
		auto obs = std::move(queue_.front());
		queue_.pop_front();
		lk.unlock();
		changed_.notify_all();
		return obs;
	}
	if (error_)
	{
		// Once: later calls report the end of the stream, as a source that threw would be left.
		auto e = error_;
		error_ = nullptr;
		std::rethrow_exception(e);
	}
	return nullptr;
}

std::size_t CPrefetchingSource::skipped() const
{
	std::lock_guard<std::mutex> lk(mutex_);
	return skipped_;
}
}  // namespace mrpt_yesslam
