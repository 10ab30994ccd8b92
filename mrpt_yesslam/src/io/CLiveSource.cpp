#include "mrpt_yesslam/io/CLiveSource.h"

#include <algorithm>
#include <chrono>

namespace mrpt_yesslam
{
namespace
{
double steadySeconds()
{
	return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

CLiveSource::CLiveSource(std::unique_ptr<CInputSource> source, std::size_t slots, bool dropWhenBehind,
						 std::function<void(const mrpt::obs::CObservation3DRangeScan::Ptr&)> onCaptured)
	: source_(std::move(source)),
	  sizeHint_(source_->sizeHint()),
	  path_(source_->path()),
	  slots_(std::max<std::size_t>(1, slots)),
	  drop_(dropWhenBehind),
	  onCaptured_(std::move(onCaptured))
{
	done_ = capture_.submit([this] { captureLoop(); });
}

CLiveSource::~CLiveSource()
{
	stop();
	// The capture thread may be blocked inside the source's next() (a camera waiting for its
	// frame): the pool's destructor waits for it to return, which a source must do within its
	// own timeout.
}

void CLiveSource::stop()
{
	stop_ = true;
	std::lock_guard<std::mutex> lk(mtx_);
	space_.notify_all();
}

void CLiveSource::captureLoop()
{
	try
	{
		while (!stop_)
		{
			auto obs = source_->next();
			unpaired_ = source_->skipped();  // the source is read on this thread only
			if (!obs) break;
			if (onCaptured_) onCaptured_(obs);
			std::unique_lock<std::mutex> lk(mtx_);
			const double now = steadySeconds();
			if (firstCapture_ < 0) firstCapture_ = now;
			lastCapture_ = now;
			// Counted once its fate is known, so that captured = delivered + dropped + waiting
			// holds whenever stats() looks (a frame blocked on a full slot is not yet captured).
			if (drop_)
			{
				while (waiting_.size() >= slots_)
				{
					waiting_.pop_front();
					dropped_++;
				}
			}
			else
				space_.wait(lk, [&] { return waiting_.size() < slots_ || stop_; });
			captured_++;
			if (stop_)
			{
				dropped_++;  // captured while the run stopped: never delivered
				break;
			}
			waiting_.push_back(std::move(obs));
			ready_.notify_all();
		}
	}
	catch (...)
	{
		std::lock_guard<std::mutex> lk(mtx_);
		error_ = std::current_exception();
	}
	std::lock_guard<std::mutex> lk(mtx_);
	ended_ = true;
	ready_.notify_all();
}

mrpt::obs::CObservation3DRangeScan::Ptr CLiveSource::next()
{
	std::unique_lock<std::mutex> lk(mtx_);
	if (delivered_) return nullptr;
	ready_.wait(lk, [&] { return !waiting_.empty() || ended_; });
	if (!waiting_.empty())
	{
		auto obs = std::move(waiting_.front());
		waiting_.pop_front();
		taken_++;
		space_.notify_all();
		return obs;
	}
	delivered_ = true;
	if (error_)
	{
		auto e = error_;
		error_ = nullptr;
		std::rethrow_exception(e);
	}
	return nullptr;
}

TLiveStats CLiveSource::stats() const
{
	std::lock_guard<std::mutex> lk(mtx_);
	TLiveStats s;
	s.captured = captured_;
	s.delivered = taken_;
	s.dropped = dropped_;
	s.waiting = waiting_.size();
	s.unpaired = unpaired_;
	if (captured_ > 1 && lastCapture_ > firstCapture_)
		s.captureFps = static_cast<double>(captured_ - 1) / (lastCapture_ - firstCapture_);
	return s;
}
}  // namespace mrpt_yesslam
