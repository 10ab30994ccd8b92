#pragma once
// The input chain of a run (private to SlamJob.cpp and SlamJobInput.cpp): the source with its
// capture or reader thread, and --record's writer.
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <chrono>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "mrpt_yesslam/io/CInputSource.h"
#include "mrpt_yesslam/io/CLiveSource.h"
#include "mrpt_yesslam/io/CRawlogWriter.h"
#include "mrpt_yesslam/jobs/SlamJob.h"
#include "mrpt_yesslam/util/CWorkerPool.h"

namespace mrpt_yesslam::job_detail
{
// The input chain of a run: the source; for live input the capture thread over it (a camera,
// an .oni file, or recorded input paced as a camera with --realtime), else the reader thread.
struct TInputChain
{
	std::unique_ptr<CInputSource> source;
	CLiveSource* live = nullptr;  //!< inside `source` when the input is live
	std::string device;
	std::function<bool()> disconnected = [] { return false; };
};

// --record: frames written on their own stage thread, so that compressing them never holds up the capture thread; a
// bounded queue keeps memory flat when the disk is slow.
class CRecorder
{
   public:
	explicit CRecorder(const std::string& path) : writer_(path) {}
	// Queues one frame; rethrows the error of an earlier write.
	void add(const mrpt::obs::CObservation3DRangeScan::Ptr& f)
	{
		std::lock_guard<std::mutex> lk(mtx_);
		if (!camera_) camera_ = f->cameraParamsIntensity;
		while (!pending_.empty() && pending_.front().wait_for(std::chrono::seconds(0)) == std::future_status::ready)
		{
			pending_.front().get();
			pending_.pop_front();
		}
		pool_.submitInto(pending_, [this, f] { writer_.write(*f); });
	}
	// Waits for the queued writes and renames the file into place; returns the frames written.
	std::size_t finish()
	{
		std::lock_guard<std::mutex> lk(mtx_);
		for (auto& p : pending_) p.get();
		pending_.clear();
		const std::size_t n = writer_.count();
		if (n > 0) writer_.commit();
		return n;
	}
	// The first frame's camera (none before a frame came).
	std::optional<mrpt::img::TCamera> camera()
	{
		std::lock_guard<std::mutex> lk(mtx_);
		return camera_;
	}

   private:
	CRawlogWriter writer_;
	std::mutex mtx_;
	std::deque<std::future<void>> pending_;
	std::optional<mrpt::img::TCamera> camera_;
	CWorkerPool pool_{1, 64};  //!< last: stopped before the writer it uses
};

/** Opens the input of `o` as `opts` configure it; `record` gets every captured frame of live input. */
TInputChain openInput(const TSlamJobOptions& o, const TYesSlamOptions& opts,
					  const std::function<void(const mrpt::obs::CObservation3DRangeScan::Ptr&)>& record);
}  // namespace mrpt_yesslam::job_detail
