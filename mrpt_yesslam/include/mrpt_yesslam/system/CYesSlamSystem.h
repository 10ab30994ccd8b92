#pragma once
// The system facade (as stella_vslam's system): one call per RGB-D frame runs detection, dynamic
// masking, ORB extraction, tracking and the keyframe decision in the caller's thread; local mapping
// runs in its own thread ([System] parallel=true) or in order after each keyframe (parallel=false:
// deterministic, what the tests use). At any time it can give the trajectory, keyframes and map.
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/opengl/COpenGLScene.h>

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "mrpt_yesslam/data/CSparseMap.h"
#include "mrpt_yesslam/detection/CObjectDetector.h"
#include "mrpt_yesslam/dynamic/CDynamicObjectMasker.h"
#include "mrpt_yesslam/feature/COrbExtractor.h"
#include "mrpt_yesslam/io/CInputSource.h"
#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/keyframes/CKeyFrameInserter.h"
#include "mrpt_yesslam/mapping/CLocalMapper.h"
#include "mrpt_yesslam/tracking/CTracker.h"

namespace mrpt_yesslam
{
/** Every stage's options: one INI/YAML file, one section per stage. */
struct TYesSlamOptions
{
	/** Section [System]. */
	struct TSystem : public mrpt::config::CLoadableOptions
	{
		bool parallel = true;  //!< local mapping in its own thread (false: sequential, deterministic)
		bool dynamicFilter = true;	//!< mask dynamic objects (false: every feature is used, as ORB-SLAM2)
		std::size_t minInitPoints = 100;  //!< static keypoints with depth needed for the first keyframe
		std::size_t frameBuffer = 8;  //!< recent frames kept for delayed (semantic) keyframe decisions

		void loadFromConfigFile(const mrpt::config::CConfigFileBase& source, const std::string& section) override;
		void dumpToTextStream(std::ostream& out) const override;
		/** The keys loadFromConfigFile reads, for validateConfigSection. */
		static std::vector<TConfigKey> configKeys();
	};

	CInputSource::TOptions input;
	CObjectDetector::TOptions detector;
	CDynamicObjectMasker::TOptions masker;
	COrbExtractor::TOptions orb;
	CTracker::TOptions tracking;
	CKeyFrameInserter::TOptions keyFrames;
	CLocalMapper::TOptions mapping;
	TSystem system;

	/** Loads every section from a config file (unknown keys warn on stderr; wrong types throw). */
	void loadFromFile(const std::string& path);
	/** All sections as INI text (what the app saves as config_used.ini). */
	std::string dump() const;
};

/** Per-frame outcome. */
struct TFrameReport
{
	std::size_t frameId = 0;
	bool tracked = false, initialised = false, keyFrame = false, relocalised = false;
	std::size_t features = 0, staticFeatures = 0, detections = 0, dynamicDetections = 0, inliers = 0;
};

/** Statistics of a run (stats.json). */
struct TSlamStats
{
	std::size_t frames = 0, trackedFrames = 0, lostFrames = 0, relocalisations = 0;
	std::size_t keyFrames = 0, forcedKeyFrames = 0, mapPoints = 0;
	/** Per stage: milliseconds of every frame (detect, mask, orb, track, keyframe) or keyframe (mapping). */
	std::map<std::string, std::vector<double>> stageMs;
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
	 * frame that cannot be tracked gets a motion-model pose and tracked = false. */
	TFrameReport processFrame(const mrpt::obs::CObservation3DRangeScan& obs);
	/** Same, from images: BGR colour, depth in metres (CV_32F, 0 = none), intrinsics. */
	TFrameReport processFrame(const cv::Mat& bgr, const cv::Mat& depthMetres, double timestamp, const mrpt::img::TCamera& camera);
	/** Waits for local mapping to finish the keyframes queued so far. */
	void waitForMapping();

	/** A pose for every processed frame: its reference keyframe's current (optimised) pose composed
	 * with the frame's pose relative to it, as ORB-SLAM2 saves trajectories. */
	TTrajectory trajectory() const;
	/** Keyframe poses with their frames' timestamps. */
	TTrajectory keyFrameTrajectory() const;
	/** Coloured map points, keyframe frustums and the trajectory, for SceneViewer3D/yesslam-render. */
	mrpt::opengl::COpenGLScene::Ptr buildScene() const;
	/** Run statistics so far. */
	TSlamStats stats() const;
	/** stats() as JSON (per-stage median and p95 in ms). */
	std::string statsJson() const;
	const CSparseMap& map() const { return map_; }
	const CObjectDetector* detector() const { return detector_.get(); }
	const TYesSlamOptions& options() const { return opts_; }

   private:
	void insertKeyFrame(const std::shared_ptr<const TFrame>& f, bool forced);
	double motionToReference(const TFrame& f) const;
	void mappingLoop();

	TYesSlamOptions opts_;
	std::unique_ptr<CObjectDetector> detector_;
	CDynamicObjectMasker masker_;
	COrbExtractor extractor_;
	CSparseMap map_;
	CTracker tracker_;
	CKeyFrameInserter inserter_;
	CLocalMapper mapper_;

	struct TFrameRecord
	{
		double t = 0;
		std::size_t refKf = 0;
		bool hasRef = false;
		mrpt::poses::CPose3D relative;	//!< T_ref_frame (or T_w_frame without a reference)
		bool tracked = false;
	};
	std::vector<TFrameRecord> records_;
	std::deque<std::shared_ptr<const TFrame>> recent_;
	std::size_t nextFrameId_ = 0;
	TSlamStats stats_;
	mutable std::mutex statsMtx_;

	// Local mapping queue (parallel mode).
	std::thread worker_;
	std::mutex qMtx_;
	std::condition_variable qCv_, qDone_;
	std::deque<std::size_t> queue_;
	bool stop_ = false, busy_ = false;
};
}  // namespace mrpt_yesslam
