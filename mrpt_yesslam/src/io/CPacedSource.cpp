#include "mrpt_yesslam/io/CPacedSource.h"

#include <thread>

#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
CPacedSource::CPacedSource(std::unique_ptr<CInputSource> source, double speed)
	: source_(std::move(source)), speed_(speed)
{
	if (!(speed > 0)) throw InputError("", "the playback speed must be > 0");
}

mrpt::obs::CObservation3DRangeScan::Ptr CPacedSource::next()
{
	auto obs = source_->next();
	if (!obs) return obs;
	const double t = observationTime(*obs);
	if (!started_)
	{
		started_ = true;
		firstStamp_ = t;
		start_ = std::chrono::steady_clock::now();
		return obs;
	}
	// Against the first frame's time, not the previous one's: reading time does not accumulate.
	// A frame stamped earlier than the first (out of order) is delivered at once.
	const double due = std::max(0.0, (t - firstStamp_) / speed_);
	std::this_thread::sleep_until(
		start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(due)));
	return obs;
}
}  // namespace mrpt_yesslam
