#pragma once
// Reads frames ahead on its own thread, so that image decoding (PNG, JPEG, gz) overlaps with the SLAM stages of the
// frame before instead of adding to them. A decorator over any CInputSource: order, frames and errors are exactly those
// of the source it wraps.
#include <atomic>
#include <deque>
#include <future>
#include <memory>

#include "mrpt_yesslam/io/CInputSource.h"
#include "mrpt_yesslam/util/CWorkerPool.h"

namespace mrpt_yesslam
{
/** A CInputSource that delivers the frames of another one, read up to `depth` frames ahead. */
class CPrefetchingSource : public CInputSource
{
   public:
	/** Starts reading `source` ahead at once; depth >= 1 frames are held at most. */
	CPrefetchingSource(std::unique_ptr<CInputSource> source, std::size_t depth);
	/** Stops the reader (after the frame it is reading). */
	~CPrefetchingSource() override = default;
	CPrefetchingSource(const CPrefetchingSource&) = delete;
	CPrefetchingSource& operator=(const CPrefetchingSource&) = delete;

	/** The source's next frame; an error the source threw at this position is rethrown here. */
	mrpt::obs::CObservation3DRangeScan::Ptr next() override;
	std::size_t sizeHint() const override { return sizeHint_; }
	std::size_t skipped() const override { return skipped_; }
	const std::string& path() const override { return path_; }
	std::optional<double> depthTime(double colourTime) const override { return source_->depthTime(colourTime); }

   private:
	/** Runs on the reader thread: the source's next frame, nothing once it has ended or thrown. */
	mrpt::obs::CObservation3DRangeScan::Ptr readOne();
	void readAhead();

	std::unique_ptr<CInputSource> source_;
	const std::size_t sizeHint_;
	const std::string path_;
	std::atomic<std::size_t> skipped_{0};
	bool sourceEnded_ = false;  //!< reader thread only
	bool delivered_ = false;    //!< consumer: the end (or the error) has been handed out
	std::deque<std::future<mrpt::obs::CObservation3DRangeScan::Ptr>> ahead_;
	CWorkerPool reader_{1};  //!< last: stopped before the source it reads is destroyed
};
}  // namespace mrpt_yesslam
