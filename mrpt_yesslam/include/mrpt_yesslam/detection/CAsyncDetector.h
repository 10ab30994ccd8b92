#pragma once
// Runs a detector on its own thread, so that detection of a frame overlaps the ORB extraction of
// the same frame in the tracking thread (detection is the slowest stage on a CPU), and, when the
// caller knows the next frame (recorded input), the tracking of the frame before it too. Frames are
// detected in the order submitted; get() collects them by timestamp.
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

	/** Queues detection of a frame; the image is shared, not copied, and must not be modified until
	 * its get() returns (or the detector is destroyed). */
	void submit(const cv::Mat& bgr, double timestamp);
	/** Whether the frame stamped `timestamp` was submitted and not yet collected. */
	bool submitted(double timestamp) const;
	/** Waits for the detections of the frame stamped `timestamp` (submitted earlier); older frames
	 * never collected are dropped. Rethrows the detector's exception, if
	 * any; throws std::logic_error if that frame was not submitted. `detectMs`: how long the
	 * detector itself took on the worker (not the wait here, which is what is left of it after the
	 * caller's own work). */
	std::vector<TDetection> get(double timestamp, double* detectMs = nullptr);
	/** get() of the first frame still waiting to be collected. */
	std::vector<TDetection> get(double* detectMs = nullptr);
	/** The wrapped detector (class names etc.; do not call detect() on it while a frame is in flight). */
	const CObjectDetector& detector() const { return *det_; }

   private:
	std::unique_ptr<CObjectDetector> det_;
	/** Frames in flight, oldest first: timestamp, and the detections with the detector's time. */
	std::deque<std::pair<double, std::future<std::pair<std::vector<TDetection>, double>>>> pending_;
	CWorkerPool worker_{1};	 //!< last: stopped before the detector it runs is destroyed
};
}  // namespace mrpt_yesslam
