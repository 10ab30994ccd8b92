#include "mrpt_yesslam/util/CWorkerPool.h"

#include <algorithm>

namespace mrpt_yesslam
{
CWorkerPool::CWorkerPool(std::size_t threads, std::size_t maxQueued) : maxQueued_(maxQueued)
{
	for (std::size_t i = 0; i < std::max<std::size_t>(1, threads); i++) threads_.emplace_back([this] { loop(); });
}

CWorkerPool::~CWorkerPool()
{
	std::deque<std::function<void()>> dropped;
	{
		std::lock_guard<std::mutex> lk(mutex_);
		stop_ = true;
		dropped.swap(jobs_);  // destroyed below, outside the lock: breaks their promises
	}
	work_.notify_all();
	space_.notify_all();
	for (auto& t : threads_) t.join();
}

void CWorkerPool::enqueue(std::function<void()> job)
{
	{
		std::unique_lock<std::mutex> lk(mutex_);
		space_.wait(lk, [&] { return stop_ || maxQueued_ == 0 || jobs_.size() < maxQueued_; });
		jobs_.push_back(std::move(job));
	}
	work_.notify_one();
}

void CWorkerPool::loop()
{
	for (;;)
	{
		std::function<void()> job;
		{
			std::unique_lock<std::mutex> lk(mutex_);
			work_.wait(lk, [&] { return stop_ || !jobs_.empty(); });
			if (stop_) return;
			job = std::move(jobs_.front());
			jobs_.pop_front();
			running_++;
		}
		space_.notify_one();
		job();  // a packaged task: exceptions are stored in its future
		{
			std::lock_guard<std::mutex> lk(mutex_);
			running_--;
		}
		idle_.notify_all();
	}
}

void CWorkerPool::waitIdle()
{
	std::unique_lock<std::mutex> lk(mutex_);
	idle_.wait(lk, [&] { return running_ == 0 && jobs_.empty(); });
}

std::size_t CWorkerPool::queued() const
{
	std::lock_guard<std::mutex> lk(mutex_);
	return jobs_.size();
}
}  // namespace mrpt_yesslam
