#include "mrpt_yesslam/io/CPrefetchingSource.h"

#include <algorithm>

namespace mrpt_yesslam
{
CPrefetchingSource::CPrefetchingSource(std::unique_ptr<CInputSource> source, std::size_t depth)
	: source_(std::move(source)), sizeHint_(source_->sizeHint()), path_(source_->path())
{
	for (std::size_t i = 0; i < std::max<std::size_t>(1, depth); i++) readAhead();
}

mrpt::obs::CObservation3DRangeScan::Ptr CPrefetchingSource::readOne()
{
	if (sourceEnded_) return nullptr;
	try
	{
		auto obs = source_->next();
		skipped_ = source_->skipped();
		sourceEnded_ = obs == nullptr;
		return obs;
	}
	catch (...)
	{
		// Not read again after an error: a source is left at its end once it has thrown.
		skipped_ = source_->skipped();
		sourceEnded_ = true;
		throw;
	}
}

void CPrefetchingSource::readAhead()
{
	reader_.submitInto(ahead_, [this] { return readOne(); });
}

mrpt::obs::CObservation3DRangeScan::Ptr CPrefetchingSource::next()
{
	if (delivered_ || ahead_.empty()) return nullptr;
	auto pending = std::move(ahead_.front());
	ahead_.pop_front();
	mrpt::obs::CObservation3DRangeScan::Ptr obs;
	try
	{
		obs = pending.get();
	}
	catch (...)
	{
		// Once: later calls report the end of the stream, as a source that threw would be left.
		delivered_ = true;
		ahead_.clear();
		throw;
	}
	if (!obs)
	{
		delivered_ = true;
		ahead_.clear();
		return nullptr;
	}
	readAhead();
	return obs;
}
}  // namespace mrpt_yesslam
