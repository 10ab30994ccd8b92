#pragma once
// The system facade (as stella_vslam's system): one call per RGB-D frame builds the frame
// (CFrameBuilder: detection, dynamic masking, ORB), tracks it (CTracker) and takes the keyframe
// decision (CKeyFrameInserter) in the caller's thread; local mapping (CLocalMapper) runs on its
// own stage thread ([System] parallel=true: a CWorkerPool with one worker and a bounded queue, every
// keyframe processed in order) or in order after each keyframe (parallel=false: deterministic, what
// the tests use). An exception in the mapping stage reaches the caller of processFrame() or
// waitForMapping(). At any time it can give the trajectory, keyframes and map.
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/opengl/COpenGLScene.h>

#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <optional>
#include <memory>
#include <mutex>
#include <shared_mutex>
#include <string>
#include <thread>

#include "mrpt_yesslam/geometry/DepthNoise.h"
#include "mrpt_yesslam/data/CSparseMap.h"
#include "mrpt_yesslam/dense/CDenseSemanticMapper.h"
#include "mrpt_yesslam/dense/COccupancyGridBuilder.h"
#include "mrpt_yesslam/detection/CObjectDetector.h"
#include "mrpt_yesslam/dynamic/CDynamicObjectMasker.h"
#include "mrpt_yesslam/feature/COrbExtractor.h"
#include "mrpt_yesslam/io/CInputSource.h"
#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/keyframes/CKeyFrameInserter.h"
#include "mrpt_yesslam/io/WorldFrame.h"
#include "mrpt_yesslam/place/CBowDatabase.h"
#include "mrpt_yesslam/loop/CLoopClosing.h"
#include "mrpt_yesslam/place/CVocabulary.h"
#include "mrpt_yesslam/keyframes/CRecentFrames.h"
#include "mrpt_yesslam/mapping/CLocalMapper.h"
#include "mrpt_yesslam/system/CFrameBuilder.h"
#include "mrpt_yesslam/system/CFrameRecords.h"
#include "mrpt_yesslam/system/TSlamStats.h"
#include "mrpt_yesslam/tracking/COnlinePoseFilter.h"
#include "mrpt_yesslam/tracking/CTracker.h"
#include "mrpt_yesslam/util/CCallbackSlot.h"
#include "mrpt_yesslam/util/CWorkerPool.h"
#include "mrpt_yesslam/util/CWriterFirstMutex.h"
#include "mrpt_yesslam/util/OptionTable.h"

namespace mrpt_yesslam
{
/** Every stage's options: one INI/YAML file, one section per stage. */
struct TYesSlamOptions
{
	/** Section [System]. */
	struct TSystem : public TTableOptions<TSystem>
	{
		bool parallel = true;  //!< local mapping in its own thread (false: sequential, deterministic)
		/** The pose trajectory.txt gives a frame a keyframe was made from: "tracked" (hung from the
		 * keyframe it was tracked against, as every frame) or "keyframe" (hung from its own
		 * keyframe: its final pose, as keyframes.txt has it). */
		std::string keyFrameFramePose = "tracked";
		/** Dynamic-object handling as a whole (false: the baseline, every feature is used as
		 * ORB-SLAM2 would; see TYesSlamOptions::effective for what that switches off). */
		bool dynamicFilter = true;
		std::size_t minInitPoints = 100;  //!< static keypoints with depth needed for the first keyframe
		std::size_t frameBuffer =
			8;  //!< recent frames kept for delayed (semantic) keyframe decisions (>= [KeyFrames] interval)
		bool asyncDetection = true;    //!< detect on a worker thread while ORB features are extracted
		std::size_t mappingQueue = 4;  //!< parallel: keyframes waiting for local mapping before tracking waits
		/** Localisation in a loaded map only: no keyframes, no map changes (needs loadMap). */
		bool localizeOnly = false;
		/** zup: exports (trajectories, dense cloud, OctoMaps, scene, saved map's octree) in x forward,
		 * y left, z up, levelled by the floor (io/WorldFrame.h); optical: the first keyframe's camera
		 * frame, as before. A loaded map keeps the frame it was saved in. */
		std::string worldFrame = "zup";
		/** With a map file to save (yesslam --save-map): the map is saved to it this often while the
		 * run goes (CMapCheckpointer; 0 = at the end only), so that a killed run keeps its map. */
		double checkpointSeconds = 30;

		/** Every option once: key, member, range, help (load, dump and keys come from it). */
		COptionTable table();
	};

	/** Section [Output]: how trajectory_smoothed.txt (CYesSlamSystem::smoothedTrajectory) is made
	 * from the keyframe-carried poses after the run; trajectory.txt and trajectory_online.txt never
	 * use a later frame. */
	struct TOutput : public TTableOptions<TOutput>
	{
		/** Lost frames between two tracked ones are placed between them, by time. */
		bool lostInterpolate = true;
		/** What mapping moved each tracked frame by since it was tracked is averaged over this many
		 * tracked frames either side and applied to the pose tracking measured (0 = off). */
		int correctionWindow = 3;
		/** Each tracked frame's position is the value at its stamp of a parabola fitted in time
		 * through up to this many tracked frames either side (0 = off). */
		int smoothingWindow = 8;

		COptionTable table();
	};

	TDepthNoise camera;  //!< section [Camera]: the depth sensor's noise, for every stage
	CInputSource::TOptions input;
	CObjectDetector::TOptions detector;
	CDynamicObjectMasker::TOptions masker;
	CGeometricDynamicCheck::TOptions geometric;  //!< section [GeometricCheck]
	COrbExtractor::TOptions orb;
	CTracker::TOptions tracking;
	COnlinePoseFilter::TOptions onlinePose;  //!< section [OnlinePose]
	CKeyFrameInserter::TOptions keyFrames;
	CLocalMapper::TOptions mapping;
	CLoopCloser::TOptions loop;            //!< section [LoopClosing]
	CDenseSemanticMapper::TOptions dense;  //!< section [DenseMapping]
	COccupancyGridBuilder::TOptions grid;  //!< section [Grid2D]: the 2D occupancy grid of the outputs
	TSystem system;
	TOutput output;

	/** Loads every section from a config file (unknown keys warn on stderr; wrong types throw). */
	void loadFromFile(const std::string& path);
	/** All sections as INI text (what the app saves as config_used.ini). */
	std::string dump() const;
	/** The options a run uses: with [System] dynamicFilter = false, every dynamic mechanism of the
	 * other sections is off too (masks and held masks, the geometric check and its mover check,
	 * see-through culling, the dense map's exclusion), so that the baseline is the baseline. */
	TYesSlamOptions effective() const;
};

/** Per-frame outcome. */
struct TFrameReport
{
	std::size_t frameId = 0;
	bool tracked = false, initialised = false, keyFrame = false, relocalised = false;
	bool poseRefused = false;  //!< a weak solution far from the motion model was not taken ([Tracking] weakInliers)
	std::size_t movingPointsErased = 0;  //!< map points this frame found moving (erased)
	std::size_t features = 0, staticFeatures = 0, detections = 0, dynamicDetections = 0, inliers = 0;
	/** The frame's online pose, T_w_c in the map's frame (fixed for the whole run: the first
	 * keyframe's camera, or a loaded map's; worldFrame() gives the outputs' z-up frame once fixed),
	 * exactly as onlineTrajectory() records it; empty for a frame before the map was made or before
	 * the first localisation in a loaded map. `tracked` false with a pose: coasted (lost). */
	std::optional<mrpt::poses::CPose3D> pose;
};

/** The SLAM system. */
class CYesSlamSystem
{
   public:
	/** Builds every stage; throws InputError for invalid options or a detector that cannot load. */
	explicit CYesSlamSystem(const TYesSlamOptions& opts);
	~CYesSlamSystem();
	CYesSlamSystem(const CYesSlamSystem&) = delete;
	CYesSlamSystem& operator=(const CYesSlamSystem&) = delete;

	/** Processes one RGB-D frame (validated by the input source). Never throws for hard frames: a
	 * frame that cannot be tracked gets a motion-model pose and tracked = false. `depthTime`: when
	 * the depth image was taken, where the source knows it and it is not the frame's timestamp
	 * (CInputSource::depthTime); keypoint depth is then moved to the colour image's moment. */
	TFrameReport processFrame(const mrpt::obs::CObservation3DRangeScan& obs,
							  std::optional<double> depthTime = std::nullopt);
	/** Same, from images: BGR colour, depth in metres (CV_32F, 0 = none), intrinsics. */
	TFrameReport processFrame(const cv::Mat& bgr, const cv::Mat& depthMetres, double timestamp,
							  const mrpt::img::TCamera& camera, std::optional<double> depthTime = std::nullopt);
	/** Recorded input: starts the detection of the frame that the `ahead`-th processFrame() call
	 * from now will get (0: the next call's frame; 1: the one after, already read), so that it
	 * overlaps the tracking of the frames before it (with [System] asyncDetection; without, it does
	 * nothing). The observation must stay alive and unchanged until it is processed; nothing else
	 * changes (the same detections, the same results). Not for live input: reading a frame ahead
	 * would delay the current one. */
	void detectAhead(const mrpt::obs::CObservation3DRangeScan& frame, std::size_t ahead = 1);
	/** Waits for local mapping (and the dense stage) to finish the keyframes queued so far; throws std::runtime_error
	 * if local mapping failed (once per failure). Every stage has settled when it returns or throws. */
	void waitForMapping();
	/** Waits until no stage (dense, mapping, loop, global BA) has work queued or running, ignoring
	 * their failures (already reported, or to be dropped): after an error, before the outputs. */
	void settle() noexcept;
	/** The run is over: lets go of the recent frames kept for Algorithm 1's delayed choice (with a
	 * dense map each holds its colour and depth images, 2 MB at 640 x 480, about 17 MB in all;
	 * no output needs them). A frame processed after it starts with an empty buffer. Not while
	 * processFrame runs (the buffer is the frame thread's). */
	void releaseRecentFrames() { recent_.clear(); }
	/** Once the run is over, the detector lets go of its network (about 8 MB; class names stay for
	 * the outputs); processFrame() afterwards fails. */
	void releaseDetectorModel() { builder_.releaseDetectorModel(); }
	/** Called on the mapping stage after each keyframe's local mapping, with the keyframe's id (for
	 * consumers of new keyframes); what it throws is reported as a mapping failure. May be set or
	 * replaced from any thread at any time, as the other two callbacks; a call already running
	 * then still finishes (util/CCallbackSlot.h: what a callback uses, it owns). */
	void setKeyFrameCallback(std::function<void(TKeyFrameId)> cb) { keyFrameCallback_.set(std::move(cb)); }
	/** Called after each accepted loop has been corrected (on the loop-closing stage in parallel
	 * mode, while local mapping goes on), with the loop; what it throws is reported as a
	 * loop-closing failure. */
	void setLoopCallback(std::function<void(const TLoop&)> cb)
	{
		if (loopClosing_) loopClosing_->setCallback(std::move(cb));
	}
	/** Called on the caller's thread at the end of each processFrame with the frame as tracking left
	 * it (features with their dynamic and uncertain flags, the map point of each inlier, the pose):
	 * for viewers and for benchmarks that score the frame against labels. */
	void setFrameCallback(std::function<void(const TFrame&)> cb) { frameCallback_.set(std::move(cb)); }

	/** A pose for every processed frame that has one (frames before the map was made or before
	 * the first localisation in a loaded map have none and are left out, as ORB-SLAM2 does): the
	 * pose tracking measured relative to its reference keyframe, carried by that keyframe's
	 * current (optimised) pose, as ORB-SLAM2 saves trajectories (trajectory.txt). No later frame
	 * changes a frame's pose; lost frames keep their coasted pose. */
	TTrajectory trajectory() const;
	/** trajectory() smoothed after the run with later frames as well as earlier ones ([Output]
	 * correctionWindow, smoothingWindow, lostInterpolate: CFrameRecords::smoothed), as
	 * trajectory_smoothed.txt: not what a robot could have had while it moved. */
	TTrajectory smoothedTrajectory() const;
	/** The pose each frame had when it was processed, in the map as it was then (tracked or
	 * coasted; frames without a pose left out): what a robot had while it moved, never corrected
	 * by later optimisation or filled in after the fact. */
	TTrajectory onlineTrajectory() const;
	/** Keyframe poses with their frames' timestamps. */
	TTrajectory keyFrameTrajectory() const;
	/** One row per processed frame, in order (frames.csv), with where its pose comes from
	 * (EPoseSource: an "interpolated" frame is coasted in trajectory(), filled in by smoothedTrajectory()). */
	std::vector<TFrameLogRow> frameLog() const;
	/** The rows and online poses (map frame) of the frames processed after the first `first`, as
	 * the run has them now: what a journal appends while the run goes (CRunJournal). */
	CFrameRecords::TSince framesSince(std::size_t first) const { return records_.since(first); }
	/** The dense semantic map from every keyframe's cloud at its current pose, in worldFrame()
	 * (call after waitForMapping for the final map); throws std::logic_error with dense mapping off. */
	TDenseMap buildDenseMap() const;
	/** The frame every export is in ([System] worldFrame): a loaded map's own; else found at the
	 * first call from the map as it is then (call after waitForMapping) and kept, so that the
	 * trajectories, the dense map and the saved map agree. */
	TWorldFrame worldFrame() const;
	/** The dense mapper; null with [DenseMapping] enabled = false. */
	const CDenseSemanticMapper* denseMapper() const { return dense_.get(); }
	/** Run statistics so far. */
	TSlamStats stats() const;
	const CSparseMap& map() const { return map_; }
	/** The frame tracker (read only: its velocity, reference keyframe, last frame's anchor). */
	const CTracker& tracker() const { return tracker_; }
	/** The map for a stage that corrects it from outside the system (tests inject a loop
	 * correction between frames with it); the system's own stages need no such access. */
	CSparseMap& mutableMap() { return map_; }
	/** Moves keyframes to `poses` (with their points and the frames hanging from them) as a loop
	 * correction does, under the map-update lock: for a correction from outside the system (an
	 * external pose graph, a global alignment) while frames are being processed on another thread.
	 * A global BA it makes stale (solving the map from before it) runs again. */
	void correctMap(const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses);
	/** Test only: `hook` runs inside every frame's tracking, with the map-update lock held (the
	 * interleaving tests put a correction there). */
	void setTrackingHook(std::function<void()> hook) { tracker_.setHook(std::move(hook)); }
	/** Test only: `hook` runs between each loop's detection and its correction (CLoopClosing::setHook). */
	void setLoopHook(std::function<void(const TLoop&)> hook)
	{
		if (loopClosing_) loopClosing_->setHook(std::move(hook));
	}
	/** Test only: `hook` runs as each keyframe's loop-detection task starts (CLoopClosing::setTaskHook). */
	void setLoopTaskHook(std::function<void(TKeyFrameId)> hook)
	{
		if (loopClosing_) loopClosing_->setTaskHook(std::move(hook));
	}
	/** Test only: `hook` runs in each global BA before its solve (CLoopCloser::setGlobalBundleHook). */
	void setGlobalBundleHook(std::function<void()> hook)
	{
		if (loopClosing_) loopClosing_->setGlobalBundleHook(std::move(hook));
	}
	/** Starts from a saved map (call before the first frame): its keyframes' words go into the
	 * place-recognition database and the first frames are placed in it by relocalisation, so the
	 * trajectory is in the saved map's frame. Throws InputError naming the file (see loadMapFile). */
	void loadMap(const std::string& path);
	/** Saves the sparse map (call after waitForMapping), with the semantic OctoMap when given
	 * (buildDenseMap's), else the one loaded with the map by a run without a dense map; throws
	 * InputError naming the file. */
	void saveMap(const std::string& path, const CSemanticOcTree* octree = nullptr) const;
	/** A semantic OctoMap with the world frame it was built in (checkpointOctree). */
	struct TFramedOctree
	{
		std::shared_ptr<const CSemanticOcTree> tree;  //!< null without a dense map
		TWorldFrame frame;
	};
	/** The semantic OctoMap of the dense store as it is now, at the keyframes' poses of one state
	 * of the map, in the world frame the end of the run would find now (the run's own is not fixed
	 * by it); callable while frames are processed on another thread. */
	TFramedOctree checkpointOctree() const;
	/** Saves the map as it is now, while frames are processed on another thread (a checkpoint:
	 * CMapCheckpointer): the sparse map in one state of the map, with `octree` and its frame (null:
	 * the one loaded with the map, in the run's frame); atomic and synced to the disk. False when
	 * the map has no keyframe yet (nothing written); throws InputError naming the file. */
	bool checkpointMap(const std::string& path, const TFramedOctree* octree = nullptr) const;
	const CObjectDetector* detector() const { return builder_.detector(); }
	/** The vocabulary of place recognition (null when none could be loaded and none was required). */
	std::shared_ptr<const CVocabulary> vocabulary() const { return vocabulary_; }
	/** The loops accepted so far, oldest first. */
	std::vector<TLoop> loops() const;
	/** Every loop candidate appearance gave and where it stopped (loop_candidates.csv). */
	std::vector<TLoopCandidate> loopCandidates() const;
	const TYesSlamOptions& options() const { return opts_; }
	/** config_used.ini's text: options(), except that a value "auto" chose stays "auto", with the
	 * choice in a comment (re-run with --localize-only, the file must choose again, not keep
	 * the mapping run's choice). */
	std::string configUsed() const;

   private:
	/** Adds frame `f` as a keyframe (under the frame's shared map-update lock); its dense cloud and
	 * local mapping follow in dispatchKeyFrame, after the lock is released. Returns the keyframe
	 * pinned against culling until its own local mapping is done. */
	CSparseMap::TPin insertKeyFrame(const std::shared_ptr<const TFrame>& f, bool forced);
	/** The dense stage and local mapping of a new keyframe (`pin`'s): queued in parallel mode, run
	 * here otherwise; the pin goes with it to mapKeyFrame. */
	void dispatchKeyFrame(CSparseMap::TPin pin, const std::shared_ptr<const TFrame>& f);
	double motionToReference(const TFrame& f) const;
	/** Computes keyframe `kf`'s words and puts them in the place-recognition database (no-op
	 * without a vocabulary or for a bad keyframe). */
	void addWords(TKeyFrameId kf);
	/** Local mapping of one keyframe (on the stage thread in parallel mode). */
	void mapKeyFrame(TKeyFrameId kf);
	/** Collects finished mapping tasks (all queued ones with `wait`); rethrows the first failure. */
	void collectMapping(bool wait);
	/** The export frame [System] worldFrame asks for, from the map as it is now (worldFrame() keeps
	 * its first answer). */
	TWorldFrame findWorldFrame() const;
	/** worldFrame() once fixed, else findWorldFrame() without fixing it (checkpoints). */
	TWorldFrame currentWorldFrame() const;

	TYesSlamOptions opts_;
	std::string askedBoxes_;  //!< [GeometricCheck] boxes as given, before effective() resolved it
	CFrameBuilder builder_;
	CSparseMap map_;
	CTracker tracker_;
	CKeyFrameInserter inserter_;
	CLocalMapper mapper_;
	std::shared_ptr<const CVocabulary> vocabulary_;
	std::shared_ptr<CBowDatabase> bowDatabase_;
	std::unique_ptr<CDenseSemanticMapper> dense_;  //!< keyframe clouds on the dense stage
	CCallbackSlot<TKeyFrameId> keyFrameCallback_;
	CCallbackSlot<const TFrame&> frameCallback_;

	CFrameRecords records_;             //!< every frame's pose record and frames.csv row (thread-safe)
	COnlinePoseFilter onlineFilter_;    //!< the online pose from the tracked ones (frame thread only)
	std::uint64_t lastGeneration_ = 0;  //!< the map's correction generation the previous frame saw
	CRecentFrames recent_;              //!< what Algorithm 1 may still choose from
	std::size_t nextFrameId_ = 0;
	bool everTracked_ = false;                      //!< a frame has had a pose (later lost frames coast from it)
	std::optional<double> lastFrameTime_;           //!< the previous frame's stamp (the frame period bounds a readout)
	std::optional<std::size_t> lastKeyFrameFrame_;  //!< frame id of the newest keyframe
	std::optional<TKeyFrameId>
		lastKeyFrame_;  //!< the newest keyframe (Algorithm 1's F_ref with motionReference = previous)
	mutable std::mutex worldFrameMtx_;
	mutable std::optional<TWorldFrame> worldFrame_;  //!< worldFrame() once found, or the loaded map's
	/** The loaded map's semantic OctoMap, kept as it was by a run without a dense map (saved again with it). */
	std::unique_ptr<CSemanticOcTree> loadedOctree_;
	TSlamStats stats_;
	mutable std::mutex statsMtx_;

	// Dense stage (parallel mode): keyframe clouds, collected by the caller like mapping tasks.
	std::deque<std::future<void>> denseTasks_;
	std::unique_ptr<CWorkerPool> denseStage_;
	/** The cloud of one keyframe (on the dense stage in parallel mode). */
	void denseKeyFrame(TKeyFrameId kf, const std::shared_ptr<const TFrame>& f);

	/** The map-update lock (ORB-SLAM2's mMutexMapUpdate), the back end's one protocol:
	 * - shared: a frame's tracking and keyframe insertion (processFrame, from reading the last
	 *   frame's pose to the new keyframes' insertion; setLastFrame again), and a keyframe's local mapping;
	 * - exclusive: a loop correction (from its reading of the poses to its write-back) and the
	 *   global-BA write-back (its solve runs unlocked and is refused if a correction landed).
	 * So a correction never lands inside a frame's tracking (the frame is tracked and anchored in
	 * one state of the map; one landing before setLastFrame shows as a new generation there), nor
	 * between a local BA's or another correction's reading and writing. Stage submissions and the
	 * sequential mode's inline mapping run after processFrame releases it. Loop keyframes are
	 * pinned against culling while a loop is pending (CSparseMap::pinKeyFrame). A waiting writer
	 * goes before new readers (CWriterFirstMutex): tracking and local mapping overlap most of the
	 * time, and a reader-preferring lock could hold a correction back indefinitely. */
	mutable CWriterFirstMutex mapUpdateMtx_;  // mutable: a checkpoint (const) reads the map under it

	/** Loop detection, correction and global BA (their own stages in parallel mode), fed by local
	 * mapping: after the lock it takes, destroyed after the mapping stage that feeds it. */
	std::unique_ptr<CLoopClosing> loopClosing_;

	// Local mapping stage (parallel mode): futures of queued keyframes, collected by the caller.
	std::deque<std::future<void>> mappingTasks_;
	std::unique_ptr<CWorkerPool> mappingStage_;  //!< last: stopped first
};
}  // namespace mrpt_yesslam
