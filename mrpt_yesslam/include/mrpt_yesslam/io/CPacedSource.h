#pragma once
// A recording played back as a camera delivers it: each frame no earlier than its recorded time
// after the first (times a speed factor). Behind CLiveSource this is `yesslam --realtime`: the
// live path (capture thread, dropping when SLAM falls behind) on recorded data, which is how the
// live behaviour is tested without a camera.
#include <chrono>
#include <memory>

#include "mrpt_yesslam/io/CInputSource.h"

namespace mrpt_yesslam
{
/** Delivers the frames of another source at the pace of their timestamps. */
class CPacedSource : public CInputSource
{
   public:
	/** `speed` > 0: 1 = as recorded, 2 = twice as fast. */
	CPacedSource(std::unique_ptr<CInputSource> source, double speed = 1.0);
	/** The source's next frame, once its time has come (it waits). */
	mrpt::obs::CObservation3DRangeScan::Ptr next() override;
	std::size_t sizeHint() const override { return source_->sizeHint(); }
	std::size_t skipped() const override { return source_->skipped(); }
	const std::string& path() const override { return source_->path(); }
	std::optional<double> depthTime(double colourTime) const override { return source_->depthTime(colourTime); }

   private:
	std::unique_ptr<CInputSource> source_;
	const double speed_;
	double firstStamp_ = 0;
	std::chrono::steady_clock::time_point start_;
	bool started_ = false;
};
}  // namespace mrpt_yesslam
