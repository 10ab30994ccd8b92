#pragma once
// Reads frames ahead on its own thread, so that image decoding (PNG, JPEG, gz: 10-20 ms a frame)
// overlaps with the SLAM stages of the frame before instead of adding to them. A decorator over any
// CInputSource: order, frames and errors are exactly those of the source it wraps.
#include <condition_variable>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>

#include "mrpt_yesslam/io/CInputSource.h"

namespace mrpt_yesslam
{
/** A CInputSource that delivers the frames of another one, read up to `depth` frames ahead. */
class CPrefetchingSource : public CInputSource
{
   public:
	/** Starts reading `source` ahead at once; depth >= 1 frames are held at most. */
	CPrefetchingSource(std::unique_ptr<CInputSource> source, std::size_t depth);
	/** Stops the reader (after the frame it is reading) and joins it. */
	~CPrefetchingSource() override;
	CPrefetchingSource(const CPrefetchingSource&) = delete;
	CPrefetchingSource& operator=(const CPrefetchingSource&) = delete;

	/** The source's next frame; an error the source threw at this position is rethrown here. */
	mrpt::obs::CObservation3DRangeScan::Ptr next() override;
	std::size_t sizeHint() const override { return sizeHint_; }
	std::size_t skipped() const override;
	const std::string& path() const override { return path_; }

   private:
	void run();

	std::unique_ptr<CInputSource> source_;
	const std::size_t depth_;
	const std::size_t sizeHint_;
	const std::string path_;
	mutable std::mutex mutex_;
	std::condition_variable changed_;
	std::deque<mrpt::obs::CObservation3DRangeScan::Ptr> queue_;
	std::exception_ptr error_;	//!< what the source threw after the queued frames
	bool finished_ = false;	 //!< the source has ended (or thrown)
	bool stop_ = false;	 //!< the consumer is gone
	std::size_t skipped_ = 0;
	std::thread reader_;
};
}  // namespace mrpt_yesslam
