#include "mrpt_yesslam/util/StageTasks.h"

#include <stdexcept>
#include <string>

namespace mrpt_yesslam
{
void collectTasks(std::deque<std::future<void>>& tasks, bool wait, const char* stage)
{
	while (!tasks.empty())
	{
		auto& f = tasks.front();
		if (!wait && f.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
		std::future<void> done = std::move(f);
		tasks.pop_front();
		try
		{
			done.get();
		}
		catch (const std::exception& e)
		{
			throw std::runtime_error(std::string(stage) + " failed: " + e.what());
		}
	}
}

bool waitForTasks(std::deque<std::future<void>>& tasks, std::mutex* mtx) noexcept
{
	bool any = false;
	for (;;)
	{
		std::future<void> f;
		{
			std::unique_lock<std::mutex> lk;
			if (mtx) lk = std::unique_lock<std::mutex>(*mtx);
			if (tasks.empty()) return any;
			f = std::move(tasks.front());
			tasks.pop_front();
		}
		any = true;
		if (f.valid()) f.wait();  // wait(), not get(): a failure is not rethrown
	}
}
}  // namespace mrpt_yesslam
