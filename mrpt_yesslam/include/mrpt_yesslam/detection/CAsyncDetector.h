#pragma once
// Runs a detector on its own thread, so that detection of a frame overlaps the ORB extraction of
// the same frame in the tracking thread (detection is the slowest stage on a CPU), and, when the
// caller knows the next frame (recorded input), the tracking of the frame before it too. Frames are
// detected in the order submitted; get() collects them by the caller's frame number (a key: stamps
// repeat in some recordings, and a rawlog without stamps gives every frame the same one).
#include <deque>
#include <future>
#include <memory>
#include <utility>

#include "mrpt_yesslam/detection/CObjectDetector.h"
#include "mrpt_yesslam/util/CWorkerPool.h"

namespace mrpt_yesslam
{
/** A detector plus a worker thread. */
class CAsyncDetector
{
   public:
	/** Takes ownership of the detector and starts the worker. */
	explicit CAsyncDetector(std::unique_ptr<CObjectDetector> detector);
	/** Stops the worker (waits for a frame in flight). */
	~CAsyncDetector() = default;
	CAsyncDetector(const CAsyncDetector&) = delete;
	CAsyncDetector& operator=(const CAsyncDetector&) = delete;

	/** Queues detection of frame number `key` (increasing with the frames), stamped `timestamp`,
	 * in place of a frame submitted under that key before; the image is shared, not copied, and
	 * must not be modified until its get() returns (or the detector is destroyed). */
	void submit(const cv::Mat& bgr, double timestamp, std::size_t key);
	/** Queues a frame numbered one past the last one submitted. */
	void submit(const cv::Mat& bgr, double timestamp);
	/** Whether frame `key` was submitted with stamp `timestamp` and not yet collected (the stamp
	 * guards against a caller whose numbering slipped: a frame it never built). */
	bool submitted(std::size_t key, double timestamp) const;
	/** Waits for the detections of frame `key` (submitted earlier); lower-numbered frames never
	 * collected are dropped. Rethrows the detector's exception, if any; throws std::logic_error if
	 * that frame was not submitted. `detectMs`: how long the detector itself took on the worker
	 * (not the wait here, which is what is left of it after the caller's own work). */
	std::vector<TDetection> get(std::size_t key, double* detectMs = nullptr);
	/** get() of the first frame still waiting to be collected. */
	std::vector<TDetection> get(double* detectMs = nullptr);
	/** The wrapped detector (class names etc.; do not call detect() on it while a frame is in flight). */
	const CObjectDetector& detector() const { return *det_; }
	/** Waits until the detector thread is idle (the results stay to be collected), then the
	 * detector lets go of its model (CObjectDetector::releaseModel). */
	void releaseModel();

   private:
	std::unique_ptr<CObjectDetector> det_;
	/** A frame in flight: its key and stamp, and the detections with the detector's time. */
	struct TPending
	{
		std::size_t key;
		double timestamp;
		std::future<std::pair<std::vector<TDetection>, double>> result;
	};
	std::deque<TPending> pending_;  //!< in submission order
	std::size_t nextKey_ = 0;       //!< one past the highest key submitted
	CWorkerPool worker_{1};         //!< last: stopped before the detector it runs is destroyed
};
}  // namespace mrpt_yesslam
