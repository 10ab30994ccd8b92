#pragma once
// Worker threads running submitted tasks in submission order, each task's result or exception
// handed back through a std::future. The one threading mechanism of the library (a stage thread
// over a bounded queue, as Basalt's and Kimera-VIO's pipelines): reading input ahead
// (CPrefetchingSource: one worker, so reads stay in order), detecting asynchronously
// (CAsyncDetector), writing PNGs in the background (CAsyncPngWriter) and local mapping
// (CYesSlamSystem: one worker, every keyframe in order, pausable for map-wide corrections), so that
// queueing, waking, pausing, stopping and passing exceptions to the consumer are written and
// tested once.
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

namespace mrpt_yesslam
{
/** A fixed set of worker threads with a FIFO task queue; submit() returns the task's future. */
class CWorkerPool
{
   public:
	/** Starts `threads` workers (at least one); submit() blocks while `maxQueued` tasks wait to
	 * start (0 = no limit), so a fast producer cannot fill memory. */
	explicit CWorkerPool(std::size_t threads = 1, std::size_t maxQueued = 0);
	/** Drops the tasks that have not started (their futures then report broken_promise) and
	 * waits for the running ones. */
	~CWorkerPool();
	CWorkerPool(const CWorkerPool&) = delete;
	CWorkerPool& operator=(const CWorkerPool&) = delete;

	/** Queues `f()`; its return value, or what it throws, comes out of the future's get(). */
	template <typename F>
	auto submit(F&& f) -> std::future<std::invoke_result_t<std::decay_t<F>>>
	{
		using R = std::invoke_result_t<std::decay_t<F>>;
		// std::function needs a copyable callable; the task itself is move-only.
		auto task = std::make_shared<std::packaged_task<R()>>(std::forward<F>(f));
		auto future = task->get_future();
		enqueue([task] { (*task)(); });
		return future;
	}

	/** Queues `f()` and puts its future at the back of `futures`, the caller's record of its tasks
	 * in flight (a std::deque of futures it waits on in order). The slot is made before the task is
	 * queued, so a queued task never loses its future (a push_back after submit could throw with the
	 * task already running, and nobody would wait for it); if queueing fails, `futures` is as it was
	 * and the error is rethrown: the task never runs. */
	template <typename Futures, typename F>
	void submitInto(Futures& futures, F&& f)
	{
		futures.emplace_back();
		try
		{
			futures.back() = submit(std::forward<F>(f));
		}
		catch (...)
		{
			futures.pop_back();
			throw;
		}
	}

	/** Returns once the queue is empty and no task is running. */
	void waitIdle();
	/** Tasks waiting to start. */
	std::size_t queued() const;

   private:
	void enqueue(std::function<void()> job);
	void loop();

	mutable std::mutex mutex_;
	std::condition_variable work_, space_, idle_;
	std::deque<std::function<void()>> jobs_;
	const std::size_t maxQueued_;
	std::size_t running_ = 0;
	bool stop_ = false;
	std::vector<std::thread> threads_;
};
}  // namespace mrpt_yesslam
