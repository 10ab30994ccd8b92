#pragma once
// PNG encoding in worker threads. Encoding (zlib) took about half of yesslam-sim's time per frame,
// while the renderer waited; with the writes in the background the next frame renders meanwhile.
// Files are still written atomically (writePngAtomically) and are byte-identical to synchronous
// writes; the queue is bounded so memory stays flat when the disk is slow.
#include <atomic>
#include <deque>
#include <functional>
#include <future>
#include <opencv2/core.hpp>
#include <string>

#include "mrpt_yesslam/util/CWorkerPool.h"

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
	 * `after` runs in the worker once the file is in place. Rethrows the error of an earlier write
	 * (once the writes queued before it are done). */
	void write(const std::string& path, const cv::Mat& img, std::function<void()> after = {}, int compression = -1);
	/** Waits until every queued file is written; rethrows the first error (an InputError). */
	void finish();
	/** Seconds the workers have spent encoding and writing so far (summed over workers). */
	double busySeconds() const { return static_cast<double>(busyNs_.load()) * 1e-9; }

   private:
	std::atomic<long long> busyNs_{0};
	std::deque<std::future<void>> pending_;  //!< in submission order
	CWorkerPool pool_;                       //!< last: its workers stop before the members they use go
};
}  // namespace mrpt_yesslam
