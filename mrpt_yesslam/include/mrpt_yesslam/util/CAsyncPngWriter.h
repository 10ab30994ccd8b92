#pragma once
// PNG encoding in worker threads. Encoding (zlib) took about half of yesslam-sim's time per frame,
// while the renderer waited; with the writes in the background the next frame renders meanwhile.
// Files are still written atomically (writePngAtomically) and are byte-identical to synchronous
// writes; the queue is bounded so memory stays flat when the disk is slow.
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <opencv2/core.hpp>
#include <string>
#include <thread>
#include <vector>

namespace mrpt_yesslam
{
/** Writes PNG files atomically from worker threads. */
class CAsyncPngWriter
{
   public:
	/** `threads` workers; write() blocks while `maxQueued` images wait. */
	explicit CAsyncPngWriter(std::size_t threads = 2, std::size_t maxQueued = 16);
	/** Waits for the queued writes (errors are dropped here; call finish() to see them). */
	~CAsyncPngWriter();
	CAsyncPngWriter(const CAsyncPngWriter&) = delete;
	CAsyncPngWriter& operator=(const CAsyncPngWriter&) = delete;

	/** Queues `img` (shared, not copied: the caller must not modify it afterwards) for `path`;
	 * `after` runs in the worker once the file is in place. Rethrows an earlier write's error. */
	void write(const std::string& path, const cv::Mat& img, std::function<void()> after = {}, int compression = -1);
	/** Waits until every queued file is written; rethrows the first error (an InputError). */
	void finish();
	/** Seconds the workers have spent encoding and writing so far (summed over workers). */
	double busySeconds();

   private:
	struct TJob
	{
		std::string path;
		cv::Mat img;
		std::function<void()> after;
		int compression = -1;
	};
	void loop();
	void rethrow();

	std::mutex mtx_;
	std::condition_variable cv_, space_, idle_;
	std::deque<TJob> jobs_;
	std::size_t maxQueued_, busy_ = 0;
	double busySeconds_ = 0;
	bool stop_ = false;
	std::exception_ptr error_;
	std::vector<std::thread> workers_;
};
}  // namespace mrpt_yesslam
