#pragma once
// Map checkpoints while a run goes (issue 68 item 2): a process killed by kill -9, the
// out-of-memory killer or a power cut keeps the map of a few seconds before it died, which a
// later run loads (--load-map), localises in and extends. RTAB-Map keeps its map in a database it
// writes as it goes; we rewrite one file atomically instead, so that it is always a whole map.
#include <chrono>
#include <cstddef>
#include <memory>
#include <mutex>
#include <string>

#include "mrpt_yesslam/util/CWorkerPool.h"
#include <future>

namespace mrpt_yesslam
{
class CYesSlamSystem;

/** Saves `sys`'s map to one file every so many seconds (CYesSlamSystem::checkpointMap) on a thread
 * of its own (a one-thread CWorkerPool), so that tracking never waits for the file: the frame thread only asks (tick),
 * and a save still running when the next is due is not doubled. The semantic OctoMap (a build of the whole dense store,
 * seconds on a long run) is rebuilt only once ten times its last build's time has passed, so that it takes at most a
 * tenth of a core; a checkpoint in between carries the last one built. Not thread-safe: one caller. */
class CMapCheckpointer
{
   public:
	/** What the checkpoints did. */
	struct TStats
	{
		std::size_t saved = 0, failed = 0;
		std::size_t octrees = 0;       //!< semantic OctoMaps built for them
		double lastMs = 0, maxMs = 0;  //!< wall time of a save (snapshot, octree, file)
		std::string lastError;         //!< why the last failed save failed (empty: none failed)
	};

	/** Checkpoints of `sys` (which must outlive this) to `path` every `seconds` (> 0) of wall time,
	 * the first `seconds` after construction. */
	CMapCheckpointer(const CYesSlamSystem& sys, std::string path, double seconds);
	~CMapCheckpointer();  //!< waits for a save under way (stop)
	CMapCheckpointer(const CMapCheckpointer&) = delete;
	CMapCheckpointer& operator=(const CMapCheckpointer&) = delete;

	/** Starts a save in the background when one is due and none is under way (call once a frame). */
	void tick();
	/** Waits for a save under way and starts no more (before the run's own end-of-run save of the
	 * same file); idempotent. */
	void stop();
	TStats stats() const;

   private:
	void save();

	const CYesSlamSystem& sys_;
	const std::string path_;
	const std::chrono::steady_clock::duration every_;
	std::chrono::steady_clock::time_point due_;
	struct TOctree;                    // the last OctoMap built and when the next is due
	std::unique_ptr<TOctree> octree_;  // the worker's own (one save at a time)
	bool stopped_ = false;
	mutable std::mutex statsMtx_;
	TStats stats_;
	std::future<void> pending_;  //!< the save under way, or the last one
	CWorkerPool worker_{1};      //!< last: stopped first, before what its task uses
};
}  // namespace mrpt_yesslam
