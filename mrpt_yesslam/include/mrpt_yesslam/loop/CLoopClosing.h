#pragma once
// The loop-closing stage (ORB-SLAM2's LoopClosing thread, stella_vslam's global_optimization_module):
// each keyframe local mapping hands over is looked up for a loop (eq. 18-23), an accepted loop is
// corrected (essential graph, CLoopCloser), and a correction asks for a global bundle adjustment
// (eq. 24). In parallel mode detection and correction run on one stage thread and global BA on
// another, one at a time (a request while one runs makes it run once more afterwards); in
// sequential mode everything runs in the caller's thread. Corrections and the global-BA write-back
// hold the system's map-update lock exclusively (the protocol at CYesSlamSystem::mapUpdateMtx_).
#include <deque>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "mrpt_yesslam/loop/CLoopCloser.h"
#include "mrpt_yesslam/loop/CLoopDetector.h"
#include "mrpt_yesslam/util/CCallbackSlot.h"
#include "mrpt_yesslam/util/CWorkerPool.h"
#include "mrpt_yesslam/util/CWriterFirstMutex.h"

namespace mrpt_yesslam
{
/** One loop closed during a run (stats.json's "loop_corrections"): the pair, how sure detection was,
 * and what its correction did to the map. */
struct TLoopRecord
{
	TKeyFrameId current = 0, matched = 0;
	/** The two keyframes' stamps, seconds as in the trajectories (to check a loop against a
	 * ground truth); 0 when the keyframe was gone. */
	double currentStamp = 0, matchedStamp = 0;
	double score = 0;  //!< S_Loop of the pair (eq. 23)
	std::size_t ransacInliers = 0;
	TLoopCorrection correction;  //!< what the correction moved, fused and optimised
	double correctMs = 0;        //!< the whole correction, pose graph included
};

/** What the loop-closing stage did so far. */
struct TLoopStageStats
{
	TLoopDetectionStats loops;        //!< loop detection counts
	std::size_t loopCorrections = 0;  //!< loops whose correction was applied to the map
	std::size_t globalBundleRuns = 0, globalBundleApplied = 0, globalBundleCancelled = 0;
	std::vector<TLoopRecord> loopRecords;  //!< every corrected loop, in order
	/** loop_detect (every keyframe looked up), loop_correct, global_ba: milliseconds of each. */
	std::map<std::string, std::vector<double>> stageMs;
};

/** The loop-closing stage over one map. */
class CLoopClosing
{
   public:
	/** `mapUpdate`: the system's map-update lock (outlives the stage); `parallel`: detection and
	 * global BA on stage threads of their own. */
	CLoopClosing(std::unique_ptr<CLoopDetector> detector, std::unique_ptr<CLoopCloser> closer, bool globalBundle,
				 CSparseMap& map, CWriterFirstMutex& mapUpdate, bool parallel);
	/** Waits for the queued work (failures are dropped: reported already, or never asked for). */
	~CLoopClosing();
	CLoopClosing(const CLoopClosing&) = delete;
	CLoopClosing& operator=(const CLoopClosing&) = delete;

	/** Hands keyframe `kf` over after its local mapping: pinned against culling until its loop is
	 * done, then detected (and corrected) on the stage, or here in sequential mode. False when `kf`
	 * was culled already (nothing to close from it). */
	bool submit(TKeyFrameId kf);
	/** Collects finished detections (all queued ones with `wait`); rethrows the first failure. */
	void collect(bool wait);
	/** Waits for the global BAs asked for so far; rethrows a failure. */
	void waitForGlobalBundle();
	/** Waits until nothing is queued or running, ignoring failures; true when it waited for any. */
	bool settle() noexcept;
	/** Keyframes before `id` belong to an earlier session (a loaded map). */
	void setSessionStart(TKeyFrameId id);
	/** Called after each corrected loop, on the stage's thread; what it throws is a loop-closing failure. */
	void setCallback(std::function<void(const TLoop&)> cb) { callback_.set(std::move(cb)); }
	/** Test only: `hook` runs between a loop's detection (its two keyframes pinned) and its
	 * correction, on the stage's thread, without the map-update lock: where local mapping's culling
	 * and a BA may land in a run. Set before the first keyframe. */
	void setHook(std::function<void(const TLoop&)> hook) { hook_ = std::move(hook); }
	/** Test only: `hook` runs as each keyframe's detection task starts (on the stage's thread in
	 * parallel mode, where what it throws is a loop-closing failure; sequentially it reaches the
	 * caller of submit() as it is). Set before the first keyframe. */
	void setTaskHook(std::function<void(TKeyFrameId)> hook) { taskHook_ = std::move(hook); }
	/** Test only: `hook` runs in each global BA before its solve (CLoopCloser::setGlobalBundleHook). */
	void setGlobalBundleHook(std::function<void()> hook) { closer_->setGlobalBundleHook(std::move(hook)); }
	/** What the stage did so far (a copy). */
	TLoopStageStats stats() const;
	/** The loops accepted so far, oldest first. */
	std::vector<TLoop> loops() const;
	/** Every candidate appearance gave so far and where it stopped, oldest first (a copy). */
	std::vector<TLoopCandidate> candidates() const;

   private:
	/** Detection for `kf` and the correction of an accepted loop. */
	void closeLoops(TKeyFrameId kf);
	void requestGlobalBundle();
	/** Runs global BAs while one is asked for (on the global-BA stage, or here in sequential mode);
	 * one whose result a correction made stale runs again. */
	void runPendingGlobalBundles();
	/** One global BA; true when a correction made its result stale (dropped). */
	bool runGlobalBundle();

	std::unique_ptr<CLoopDetector> detector_;  //!< used on the loop-closing stage only
	std::unique_ptr<CLoopCloser> closer_;      //!< corrections on the loop-closing stage, global BA on its own
	const bool globalBundle_;
	CSparseMap& map_;
	CWriterFirstMutex& mapUpdate_;
	CCallbackSlot<const TLoop&> callback_;
	std::function<void(const TLoop&)> hook_;     //!< setHook
	std::function<void(TKeyFrameId)> taskHook_;  //!< setTaskHook
	mutable std::mutex statsMtx_;
	TLoopStageStats stats_;                   //!< guarded by statsMtx_
	std::vector<TLoop> loops_;                //!< guarded by statsMtx_
	std::vector<TLoopCandidate> candidates_;  //!< guarded by statsMtx_

	// Global BA: requested after corrections, collected by waitForGlobalBundle (parallel mode).
	std::mutex gbaMtx_;
	bool gbaPending_ = false, gbaRunning_ = false;  //!< guarded by gbaMtx_
	std::deque<std::future<void>> gbaTasks_;        //!< guarded by gbaMtx_
	std::unique_ptr<CWorkerPool> gbaStage_;         //!< outlives the loop stage, which feeds it
	// Detection and correction (parallel mode): fed by the mapping stage, collected by collect().
	std::mutex loopTasksMtx_;
	std::deque<std::future<void>> loopTasks_;  //!< guarded by loopTasksMtx_
	std::unique_ptr<CWorkerPool> loopStage_;
};
}  // namespace mrpt_yesslam
