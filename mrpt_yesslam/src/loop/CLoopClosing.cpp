#include "mrpt_yesslam/loop/CLoopClosing.h"

#include <algorithm>
#include <cstdlib>  // defines __GLIBC__ where it applies
#include <shared_mutex>
#include <string>
#include <utility>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "mrpt_yesslam/util/StageTasks.h"
#include "mrpt_yesslam/util/Stopwatch.h"

namespace mrpt_yesslam
{
CLoopClosing::CLoopClosing(std::unique_ptr<CLoopDetector> detector, std::unique_ptr<CLoopCloser> closer,
						   bool globalBundle, CSparseMap& map, CWriterFirstMutex& mapUpdate, bool parallel)
	: detector_(std::move(detector)),
	  closer_(std::move(closer)),
	  globalBundle_(globalBundle),
	  map_(map),
	  mapUpdate_(mapUpdate)
{
	if (parallel)
	{
		gbaStage_ = std::make_unique<CWorkerPool>(1);
		loopStage_ = std::make_unique<CWorkerPool>(1);
	}
}

CLoopClosing::~CLoopClosing()
{
	// The loop stage first: its corrections queue global BAs.
	if (loopStage_) loopStage_->waitIdle();
	if (gbaStage_) gbaStage_->waitIdle();
}

bool CLoopClosing::submit(TKeyFrameId kf)
{
	// Pinned from here to its correction, so that culling on the next keyframes (local mapping,
	// while this stage works) cannot erase it under the loop (issue 40 b); closeLoops adopts the pin.
	CSparseMap::TPin pin = map_.pinned(kf);
	if (!pin) return false;  // culled already
	if (!loopStage_)
	{
		pin.release();
		closeLoops(kf);
		return true;
	}
	// Detection and correction on their own stage (ORB-SLAM2's LoopClosing thread): local mapping
	// goes on with the next keyframes meanwhile instead of waiting for them.
	std::lock_guard<std::mutex> lk(loopTasksMtx_);
	loopStage_->submitInto(loopTasks_, [this, kf] { closeLoops(kf); });  // if it throws, `pin` is undone
	pin.release();
	return true;
}

void CLoopClosing::closeLoops(TKeyFrameId kf)
{
	// `kf` was pinned when it was submitted; the matched keyframe is pinned once known. Both pins
	// are undone however closeLoops ends.
	const CSparseMap::TPin kfPin = map_.adoptPin(kf);
	CSparseMap::TPin matchedPin;
	if (taskHook_) taskHook_(kf);
	auto t0 = SteadyClock::now();
	std::optional<TLoop> loop = detector_->detect(kf);
	const double loopMs = msSince(t0);
	std::vector<TLoopCandidate> candidates = detector_->takeCandidates();
	std::optional<std::pair<TKeyFrameId, TKeyFrameId>> detected;
	if (loop) detected = std::make_pair(loop->current, loop->matched);
	if (loop)
	{
		matchedPin = map_.pinned(loop->matched);
		if (!matchedPin) loop.reset();  // culled during detection (it was not in the current one's local window)
	}
	if (loop && hook_) hook_(*loop);
	std::optional<double> correctMs;
	TLoopCorrection correction;
	if (loop)
	{
		std::unique_lock<CWriterFirstMutex> lk(mapUpdate_);
		t0 = SteadyClock::now();
		correction = closer_->correct(*loop);
		correctMs = msSince(t0);
		// A correction that moved nothing (a keyframe of the pair gone) closed no loop: not counted,
		// no global BA, no callback.
		if (correction.groupKeyFrames == 0) loop.reset();
	}
	// The pair's stamps, read from the map before the statistics' lock (no lock taken inside it).
	TLoopRecord rec;
	if (loop)
	{
		rec = {loop->current, loop->matched, 0, 0, loop->score, loop->ransacInliers, correction, *correctMs};
		for (const auto& k : map_.keyFramePoses())
		{
			if (k.id == rec.current) rec.currentStamp = k.timestamp;
			if (k.id == rec.matched) rec.matchedStamp = k.timestamp;
		}
	}
	{
		std::lock_guard<std::mutex> sl(statsMtx_);
		stats_.stageMs["loop_detect"].push_back(loopMs);
		stats_.loops = detector_->stats();
		// An accepted loop whose correction never came (a keyframe gone) is no loop closed.
		if (detected && !loop)
			for (auto& c : candidates)
				if (c.query == detected->first && c.candidate == detected->second && std::string(c.stage) == "accepted")
					c.stage = "dropped";
		// The first kCandidateRecords (the file is for analysis; an hours-long run must not grow with it).
		constexpr std::size_t kCandidateRecords = 100000;
		const std::size_t room = kCandidateRecords - std::min(kCandidateRecords, candidates_.size());
		candidates_.insert(candidates_.end(), candidates.begin(),
						   candidates.begin() + static_cast<std::ptrdiff_t>(std::min(room, candidates.size())));
		if (loop)
		{
			loops_.push_back(*loop);
			stats_.loopCorrections++;
			stats_.stageMs["loop_correct"].push_back(*correctMs);
			stats_.loopRecords.push_back(rec);
		}
	}
	if (!loop) return;
	requestGlobalBundle();
	callback_(*loop);
}

bool CLoopClosing::runGlobalBundle()
{
	const auto t0 = SteadyClock::now();
	const TBundleStats st = closer_->globalBundleAdjust(&mapUpdate_);  // write-back exclusive
	const double ms = msSince(t0);
#if defined(__GLIBC__)
	// The global problem (every keyframe, point and cost, Ceres' Jacobians) is freed at once, and glibc keeps it in the
	// arena of the thread that ran it, resident until the run's end. Handed back as SlamJob does before the outputs,
	// cheaply, once per loop; under a sanitizer's or another allocator this trims glibc's unused arenas only.
	malloc_trim(0);
#endif
	std::lock_guard<std::mutex> sl(statsMtx_);
	stats_.globalBundleRuns++;
	if (st.applied) stats_.globalBundleApplied++;
	if (st.cancelled) stats_.globalBundleCancelled++;
	stats_.stageMs["global_ba"].push_back(ms);
	return st.cancelled || (!st.applied && st.keyFrames > 0);  // an empty map has nothing to apply
}

void CLoopClosing::requestGlobalBundle()
{
	if (!globalBundle_) return;
	std::unique_lock<std::mutex> lk(gbaMtx_);
	gbaPending_ = true;
	if (gbaRunning_) return;
	gbaRunning_ = true;
	if (!gbaStage_)
	{
		lk.unlock();
		runPendingGlobalBundles();
		return;
	}
	try
	{
		gbaStage_->submitInto(gbaTasks_, [this] { runPendingGlobalBundles(); });
	}
	catch (...)
	{
		gbaRunning_ = gbaPending_ = false;  // never queued: the next request starts one
		throw;
	}
}

void CLoopClosing::runPendingGlobalBundles()
{
	for (;;)
	{
		{
			std::lock_guard<std::mutex> l(gbaMtx_);
			if (!gbaPending_)
			{
				gbaRunning_ = false;
				return;
			}
			gbaPending_ = false;
		}
		bool stale = false;
		try
		{
			stale = runGlobalBundle();
		}
		catch (...)
		{
			std::lock_guard<std::mutex> l(gbaMtx_);
			gbaRunning_ = gbaPending_ = false;
			throw;
		}
		// A correction landed while it solved (a loop's, which asks for its own global BA anyway,
		// or one from outside, CYesSlamSystem::correctMap, which asks for none): the map it was
		// for still needs one. Only a correction makes a solve stale, so this ends.
		if (stale)
		{
			// A loop's correction is written in steps under the exclusive lock: the next solve reads
			// the map once it is whole.
			{
				std::shared_lock<CWriterFirstMutex> whole(mapUpdate_);
			}
			std::lock_guard<std::mutex> l(gbaMtx_);
			gbaPending_ = true;
		}
	}
}

void CLoopClosing::collect(bool wait)
{
	// The stage is fed by the mapping stage (another thread): its futures are taken out under the
	// lock and waited for outside it.
	for (;;)
	{
		std::deque<std::future<void>> ready;
		{
			std::lock_guard<std::mutex> lk(loopTasksMtx_);
			while (!loopTasks_.empty() &&
				   (wait || loopTasks_.front().wait_for(std::chrono::seconds(0)) == std::future_status::ready))
			{
				ready.push_back(std::move(loopTasks_.front()));
				loopTasks_.pop_front();
			}
		}
		if (ready.empty()) return;
		try
		{
			collectTasks(ready, true, "loop closing");
		}
		catch (...)
		{
			// The tasks after the failed one may still run: back at the queue's front, so that
			// settle() waits for them before the error path writes the outputs (issue 40 d).
			std::lock_guard<std::mutex> lk(loopTasksMtx_);
			for (auto it = ready.rbegin(); it != ready.rend(); ++it) loopTasks_.push_front(std::move(*it));
			throw;
		}
	}
}

void CLoopClosing::waitForGlobalBundle()
{
	for (;;)
	{
		std::future<void> f;
		{
			std::lock_guard<std::mutex> lk(gbaMtx_);
			if (gbaTasks_.empty()) return;
			f = std::move(gbaTasks_.front());
			gbaTasks_.pop_front();
		}
		try
		{
			f.get();
		}
		catch (const std::exception& e)
		{
			throw std::runtime_error(std::string("global bundle adjustment failed: ") + e.what());
		}
	}
}

bool CLoopClosing::settle() noexcept
{
	return waitForTasks(loopTasks_, &loopTasksMtx_) | waitForTasks(gbaTasks_, &gbaMtx_);
}

void CLoopClosing::setSessionStart(TKeyFrameId id)
{
	detector_->setSessionStart(id);
}

TLoopStageStats CLoopClosing::stats() const
{
	std::lock_guard<std::mutex> sl(statsMtx_);
	return stats_;
}

std::vector<TLoopCandidate> CLoopClosing::candidates() const
{
	std::lock_guard<std::mutex> sl(statsMtx_);
	return candidates_;
}

std::vector<TLoop> CLoopClosing::loops() const
{
	std::lock_guard<std::mutex> sl(statsMtx_);
	return loops_;
}
}  // namespace mrpt_yesslam
