#pragma once
// Live input: a camera delivers frames at its own rate whether SLAM keeps up or not. The capture
// runs on its own stage thread (CWorkerPool, the library's one thread mechanism) and hands over
// only the newest frames: when SLAM falls behind, the oldest waiting frame is dropped and counted,
// never queued without bound (as ORB-SLAM2's and RTAB-Map's camera nodes do by reading the
// latest frame). A decorator over any CInputSource: COpenNI2Source for a camera, CPacedSource to
// replay a recording at its recorded rate through the same path.
#include <atomic>
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>

#include "mrpt_yesslam/io/CInputSource.h"
#include "mrpt_yesslam/util/CWorkerPool.h"

namespace mrpt_yesslam
{
/** Counters of a live input, for stats.json and the status line. */
struct TLiveStats
{
	std::size_t captured = 0;   //!< frames the source delivered to the capture thread
	std::size_t delivered = 0;  //!< of those, frames SLAM took
	std::size_t dropped = 0;    //!< of those, frames replaced by a newer one before SLAM took them
	std::size_t waiting =
		0;  //!< of those, frames still waiting (a run stopped early): captured = delivered + dropped + waiting
	std::size_t unpaired = 0;  //!< frames of one stream the source found no partner for (never captured as frames)
	double captureFps = 0;     //!< captured frames per second since the first one
};

/** Reads a source on a capture thread and keeps at most `slots` frames for the consumer. */
class CLiveSource : public CInputSource
{
   public:
	/** Starts capturing at once. With `dropWhenBehind` the oldest waiting frame makes room for a
	 * new one (a camera); without, the capture thread waits for room (a file replayed as fast as
	 * it is processed: nothing lost, deterministic). `onCaptured` (optional) sees every captured
	 * frame on the capture thread, dropped ones included (recording: it must not take long, or
	 * capturing slows down; the frame is shared with SLAM and must not be modified). */
	CLiveSource(std::unique_ptr<CInputSource> source, std::size_t slots, bool dropWhenBehind,
				std::function<void(const mrpt::obs::CObservation3DRangeScan::Ptr&)> onCaptured = {});
	/** Stops the capture thread (after the frame it is reading). */
	~CLiveSource() override;
	CLiveSource(const CLiveSource&) = delete;
	CLiveSource& operator=(const CLiveSource&) = delete;

	/** The oldest waiting frame; waits for one. nullptr once the source has ended and every waiting
	 * frame was taken; an error of the source (or of onCaptured) is rethrown here once. */
	mrpt::obs::CObservation3DRangeScan::Ptr next() override;
	std::size_t sizeHint() const override { return sizeHint_; }
	std::size_t skipped() const override { return unpaired_; }
	const std::string& path() const override { return path_; }
	std::optional<double> depthTime(double colourTime) const override { return source_->depthTime(colourTime); }

	/** Frames captured and dropped so far (thread-safe). */
	TLiveStats stats() const;
	/** Ends capturing early: next() then delivers what waits and reports the end. */
	void stop();

   private:
	void captureLoop();

	std::unique_ptr<CInputSource> source_;
	const std::size_t sizeHint_;
	const std::string path_;
	const std::size_t slots_;
	const bool drop_;
	std::function<void(const mrpt::obs::CObservation3DRangeScan::Ptr&)> onCaptured_;

	mutable std::mutex mtx_;
	std::condition_variable ready_, space_;
	std::deque<mrpt::obs::CObservation3DRangeScan::Ptr> waiting_;
	bool ended_ = false, delivered_ = false;
	std::exception_ptr error_;
	std::atomic<bool> stop_{false};
	std::size_t captured_ = 0, dropped_ = 0, taken_ = 0;
	std::atomic<std::size_t> unpaired_{0};         //!< the source's skipped(), read on the capture thread
	double firstCapture_ = -1, lastCapture_ = -1;  //!< steady clock seconds
	std::future<void> done_;
	CWorkerPool capture_{1};  //!< last: stopped before what the loop uses is destroyed
};
}  // namespace mrpt_yesslam
