#pragma once
// Runs a detector on its own thread, so that detection of a frame overlaps the ORB extraction of
// the same frame in the tracking thread (detection is the slowest stage on a CPU). One frame in
// flight at a time: submit(), do other work, then get().
#include <future>
#include <memory>

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

	/** Starts detection of a frame; the image is shared, not copied, and must not be modified until
	 * get() returns. Throws std::logic_error if a frame is already in flight. */
	void submit(const cv::Mat& bgr, double timestamp);
	/** Waits for the submitted frame's detections; rethrows the detector's exception, if any.
	 * `detectMs`: how long the detector itself took on the worker (not the wait here, which is
	 * what is left of it after the caller's own work). */
	std::vector<TDetection> get(double* detectMs = nullptr);
	/** The wrapped detector (class names etc.; do not call detect() on it while a frame is in flight). */
	const CObjectDetector& detector() const { return *det_; }

   private:
	std::unique_ptr<CObjectDetector> det_;
	std::future<std::vector<TDetection>> pending_;
	/** The detector's time on the frame in flight: written by the worker before its result, read
	 * after get()'s wait (the future orders the two). */
	double lastMs_ = 0;
	CWorkerPool worker_{1};	 //!< last: stopped before the detector it runs is destroyed
};
}  // namespace mrpt_yesslam
