#pragma once
// The futures of a pipeline stage's queued work (CWorkerPool::submit), collected in order: with
// their failures (the caller reports them) or only waited for (settling after an error).
#include <deque>
#include <future>
#include <mutex>

namespace mrpt_yesslam
{
/** Takes the finished futures of `tasks` in order (all of them with `wait`); the first failure is
 * rethrown as std::runtime_error "<stage> failed: ...", the futures after it left queued. */
void collectTasks(std::deque<std::future<void>>& tasks, bool wait, const char* stage);
/** Waits for every future of `tasks` (taken out under `mtx` when given) without rethrowing a
 * failure; whether there was any. */
bool waitForTasks(std::deque<std::future<void>>& tasks, std::mutex* mtx = nullptr) noexcept;
}  // namespace mrpt_yesslam
