#include "mrpt_yesslam/system/CMapCheckpointer.h"

#include <algorithm>
#include <stdexcept>

#include "mrpt_yesslam/system/CYesSlamSystem.h"

namespace mrpt_yesslam
{
struct CMapCheckpointer::TOctree
{
	CYesSlamSystem::TFramedOctree built;
	std::chrono::steady_clock::time_point due;  //!< the next build (none yet: now)
};

CMapCheckpointer::CMapCheckpointer(const CYesSlamSystem& sys, std::string path, double seconds)
	: sys_(sys),
	  path_(std::move(path)),
	  every_(std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds))),
	  octree_(std::make_unique<TOctree>())
{
	if (!(seconds > 0)) throw std::invalid_argument("CMapCheckpointer: the interval must be positive");
	due_ = std::chrono::steady_clock::now() + every_;
}

CMapCheckpointer::~CMapCheckpointer()
{
	stop();
}

void CMapCheckpointer::tick()
{
	if (stopped_ || (pending_.valid() && pending_.wait_for(std::chrono::seconds(0)) != std::future_status::ready))
		return;
	const auto now = std::chrono::steady_clock::now();
	if (now < due_) return;
	// The next one is due an interval after this one starts: a save longer than the interval is
	// followed by the next at once, never by two at a time.
	due_ = now + every_;
	try
	{
		pending_ = worker_.submit([this] { save(); });  // save() keeps its own errors
	}
	catch (const std::exception& e)  // could not be queued: a failed checkpoint, not a failed run
	{
		std::lock_guard<std::mutex> lk(statsMtx_);
		stats_.failed++, stats_.lastError = std::string("the checkpoint could not be started: ") + e.what();
	}
}

void CMapCheckpointer::save()
{
	const auto t0 = std::chrono::steady_clock::now();
	std::string error;
	bool built = false, wrote = false;
	try
	{
		if (sys_.denseMapper() && t0 >= octree_->due)
		{
			// A build that fails waits as a finished one would: the map is saved with the last tree.
			try
			{
				octree_->built = sys_.checkpointOctree();
				built = true;
			}
			catch (const std::exception& e)
			{
				error = std::string("the semantic OctoMap: ") + e.what();
			}
			octree_->due = t0 + 10 * (std::chrono::steady_clock::now() - t0);
		}
		wrote = sys_.checkpointMap(path_, &octree_->built);  // false: no keyframe yet, nothing to keep
	}
	catch (const std::exception& e)
	{
		error = e.what()[0] ? e.what() : "unknown error";
	}
	catch (...)
	{
		error = "unknown error";
	}
	const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
	{
		std::lock_guard<std::mutex> lk(statsMtx_);
		stats_.octrees += built ? 1 : 0;
		stats_.saved += wrote ? 1 : 0;  // also with the last tree after a failed build
		if (!error.empty()) stats_.failed++, stats_.lastError = error;
		stats_.lastMs = ms;
		stats_.maxMs = std::max(stats_.maxMs, ms);
	}
}

void CMapCheckpointer::stop()
{
	stopped_ = true;
	if (pending_.valid()) pending_.wait();
	octree_->built = {};  // not held through the end of the run's own outputs (its peak of memory)
}

CMapCheckpointer::TStats CMapCheckpointer::stats() const
{
	std::lock_guard<std::mutex> lk(statsMtx_);
	return stats_;
}
}  // namespace mrpt_yesslam
