#include "mrpt_yesslam/system/CYesSlamSystem.h"

#include <mrpt/config/CConfigFileBase.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "mrpt_yesslam/util/Stopwatch.h"
#include "mrpt_yesslam/feature/DepthMoment.h"
#include "mrpt_yesslam/feature/RollingShutter.h"
#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/util/ConfigFile.h"
#include "mrpt_yesslam/util/Error.h"
#include "mrpt_yesslam/util/StageTasks.h"

namespace mrpt_yesslam
{
CYesSlamSystem::CYesSlamSystem(const TYesSlamOptions& opts)
	: opts_(opts.effective()),
	  askedBoxes_(opts.geometric.boxes),
	  builder_(createObjectDetector(opts_.detector), opts_.masker, opts_.orb, opts_.system.dynamicFilter,
			   opts_.system.asyncDetection, opts_.geometric),
	  tracker_(opts_.tracking, map_, opts_.orb.scaleFactor, opts_.geometric, opts_.camera),
	  inserter_(opts_.keyFrames),
	  mapper_(opts_.mapping, map_, opts_.orb.scaleFactor, opts_.tracking.maxDepth, opts_.camera),
	  records_(opts_.output.lostInterpolate, opts_.output.correctionWindow, opts_.output.smoothingWindow),
	  onlineFilter_(opts_.onlinePose),
	  recent_(opts_.system.frameBuffer)
{
	tracker_.setMapReadOnly(opts_.system.localizeOnly);
	// Algorithm 1 may name any frame of the interval that just closed: the buffer must hold it.
	const auto& sem = opts_.keyFrames.semantic;
	const std::size_t longest = static_cast<std::size_t>(std::max(sem.interval, sem.shortInterval));
	if (opts_.keyFrames.policy == "semantic" && opts_.system.frameBuffer < longest)
		throw InputError("", "[System] frameBuffer (" + std::to_string(opts_.system.frameBuffer) +
								 ") must be at least [KeyFrames] interval (" + std::to_string(longest) +
								 "): a keyframe chosen in the interval would be lost");
	if (opts_.system.mappingQueue < 1) throw InputError("", "[System] mappingQueue must be >= 1");
	// Place recognition. Loop closing needs the vocabulary, and so does a vocabulary the user names;
	// without either, the shipped one still serves relocalisation when it is there.
	const bool required = opts_.loop.detection.enabled || !opts_.loop.detection.vocabulary.empty();
	const std::string vocabPath =
		!opts_.loop.detection.vocabulary.empty() ? opts_.loop.detection.vocabulary : CVocabulary::shippedPath();
	if (vocabPath.empty())
	{
		if (required)
			throw InputError("",
							 "no vocabulary for loop closing: the shipped share/mrpt_yesslam/vocabulary was not found "
							 "(set YESSLAM_SHARE_DIR or [LoopClosing] vocabulary), or run with loop closing off");
	}
	else if (required || std::filesystem::exists(vocabPath))
	{
		vocabulary_ = std::make_shared<const CVocabulary>(CVocabulary::load(vocabPath));
		bowDatabase_ = std::make_shared<CBowDatabase>(vocabulary_->numWords());
		tracker_.setPlaceRecognition(vocabulary_, bowDatabase_);
		if (opts_.loop.detection.enabled)
		{
			loopClosing_ = std::make_unique<CLoopClosing>(
				std::make_unique<CLoopDetector>(opts_.loop.detection, map_, vocabulary_, bowDatabase_,
												opts_.keyFrames.semantic, opts_.orb.scaleFactor,
												opts_.tracking.maxDepth, opts_.camera),
				std::make_unique<CLoopCloser>(opts_.loop, map_, opts_.orb.scaleFactor, opts_.camera),
				opts_.loop.globalBundleAdjustment, map_, mapUpdateMtx_, opts_.system.parallel);
		}
	}
	if (opts_.dense.enabled)
	{
		const auto* det = builder_.detector();
		dense_ = std::make_unique<CDenseSemanticMapper>(opts_.dense, opts_.masker,
														det ? static_cast<int>(det->classNames().size()) : 1);
		builder_.setKeepImages(true);
	}
	if (opts_.system.parallel)
	{
		if (dense_) denseStage_ = std::make_unique<CWorkerPool>(1, opts_.dense.queue);
		mappingStage_ = std::make_unique<CWorkerPool>(1, opts_.system.mappingQueue);
	}
}

std::vector<TLoop> CYesSlamSystem::loops() const
{
	return loopClosing_ ? loopClosing_->loops() : std::vector<TLoop>();
}
std::vector<TLoopCandidate> CYesSlamSystem::loopCandidates() const
{
	return loopClosing_ ? loopClosing_->candidates() : std::vector<TLoopCandidate>();
}

CYesSlamSystem::~CYesSlamSystem()
{
	// Let the queued keyframes finish (their futures would otherwise break), ignoring failures: a
	// destructor must not throw, and a failure has been or will not be reported.
	if (mappingStage_) mappingStage_->waitIdle();
	loopClosing_.reset();  // waits for the loop stage and the global BA it asked for
	if (denseStage_) denseStage_->waitIdle();
}

void CYesSlamSystem::denseKeyFrame(TKeyFrameId kf, const std::shared_ptr<const TFrame>& f)
{
	const TStageClock clock;
	dense_->addKeyFrame(kf, *f);
	const double ms = clock.wallMs(), cpu = clock.cpuMs();
	std::lock_guard<std::mutex> sl(statsMtx_);
	stats_.stageMs["dense"].push_back(ms);
	stats_.stageMs["dense_cpu"].push_back(cpu);
}

void CYesSlamSystem::addWords(TKeyFrameId kf)
{
	if (!vocabulary_) return;
	const CKeyFrame k = map_.keyFrame(kf);
	if (k.bad || !k.features) return;
	auto bow = vocabulary_->bowOf(*k.features, opts_.loop.detection.directLevel);
	if (map_.setKeyFrameBow(kf, bow)) bowDatabase_->add(kf, std::move(bow));
}

void CYesSlamSystem::mapKeyFrame(TKeyFrameId kf)
{
	const CSparseMap::TPin pin = map_.adoptPin(kf);  // insertKeyFrame's, undone however this ends
	const TStageClock clock;
	// The keyframe's words first (ORB-SLAM2's ProcessNewKeyFrame), so that relocalisation and loop
	// detection find it; culled keyframes leave the database with the map. The words and the
	// database (its own lock) are nothing a loop correction writes: outside the map-update lock.
	addWords(kf);
	TMappingStats st;
	{
		// Waits while a loop correction is written (counted in the mapping time: that is the stall).
		std::shared_lock<CWriterFirstMutex> lk(mapUpdateMtx_);
		st = mapper_.step(kf);
	}
	if (bowDatabase_)
		for (const auto e : st.erasedKeyFrames) bowDatabase_->erase(e);
	if (dense_ && !st.erasedKeyFrames.empty()) dense_->keyFramesCulled(st.erasedKeyFrames);
	const double ms = clock.wallMs(), cpu = clock.cpuMs();
	{
		std::lock_guard<std::mutex> sl(statsMtx_);
		stats_.stageMs["mapping"].push_back(ms);
		stats_.stageMs["mapping_cpu"].push_back(cpu);
		stats_.culledKeyFrames += st.erasedKeyFrames.size();
	}
	// The loop stage pins the keyframe until its loop is done; one culled already has none to close.
	if (loopClosing_) loopClosing_->submit(kf);
	keyFrameCallback_(kf);
}

void CYesSlamSystem::collectMapping(bool wait)
{
	collectTasks(denseTasks_, wait, "dense mapping");
	collectTasks(mappingTasks_, wait, "local mapping");
	if (loopClosing_) loopClosing_->collect(wait);
}

void CYesSlamSystem::settle() noexcept
{
	// Mapping tasks queue loop tasks, which queue global BAs: until every queue stays empty.
	for (bool any = true; any;)
		any = waitForTasks(denseTasks_) | waitForTasks(mappingTasks_) | (loopClosing_ && loopClosing_->settle());
}

void CYesSlamSystem::waitForMapping()
{
	// The first failure is rethrown only once every stage has settled: the caller then writes its
	// outputs from a map no stage is still changing (issue 40 d).
	struct TSettle
	{
		CYesSlamSystem& s;
		~TSettle() { s.settle(); }
	} settleOnExit{*this};
	collectMapping(true);
	// Then the global BA the last keyframes may have asked for.
	if (loopClosing_) loopClosing_->waitForGlobalBundle();
}

TFrameReport CYesSlamSystem::processFrame(const mrpt::obs::CObservation3DRangeScan& obs,
										  std::optional<double> depthTime)
{
	cv::Mat bgr = obs.intensityImage.asCvMatRef();
	if (bgr.channels() == 1) cv::cvtColor(bgr, bgr, cv::COLOR_GRAY2BGR);
	return processFrame(bgr, depthInMetres(obs), observationTime(obs), obs.cameraParamsIntensity, depthTime);
}

void CYesSlamSystem::detectAhead(const mrpt::obs::CObservation3DRangeScan& frame, std::size_t ahead)
{
	if (!builder_.detectsAhead()) return;
	cv::Mat bgr = frame.intensityImage.asCvMatRef();
	if (bgr.channels() == 1) cv::cvtColor(bgr, bgr, cv::COLOR_GRAY2BGR);  // as processFrame makes it
	// Keyed by the frame's number, not its stamp: stamps repeat in some recordings.
	builder_.detectAhead(bgr, observationTime(frame), nextFrameId_ + ahead);
}

double CYesSlamSystem::motionToReference(const TFrame& f) const
{
	// Eq. 12-16 against the reference: tracking's (the keyframe sharing most points: D then says
	// how far the view is from the map it is tracked against), or Algorithm 1's own F_ref, the
	// keyframe its last interval chose ([KeyFrames] motionReference = previous; a candidate refused
	// for N_in <= 20 never became a keyframe, so the one before stays F_ref there).
	std::optional<TKeyFrameId> ref = tracker_.referenceKeyFrame();
	if (opts_.keyFrames.motionReference == "previous" && lastKeyFrame_) ref = map_.goodAncestor(*lastKeyFrame_);
	if (!ref) return 0;
	return motionToKeyFrame(f, map_.keyFrame(*ref));
}

CSparseMap::TPin CYesSlamSystem::insertKeyFrame(const std::shared_ptr<const TFrame>& f, bool forced)
{
	// Pinned until its own local mapping is done (mapKeyFrame unpins): in parallel mode it is in the
	// map, covisible, while it waits in the mapping queue, and culling around an earlier keyframe
	// must not erase it before its words, points and loop detection were made (ORB-SLAM2 cannot:
	// its local mapping inserts a keyframe into the map itself; a review's finding). Pinned as it is
	// added (the mapping stage may be culling right then), and owned by the caller until then: a
	// frame that fails before its keyframes are dispatched undoes it.
	CSparseMap::TPin pin = map_.addPinnedKeyFrame(f, opts_.tracking.maxDepth);
	const TKeyFrameId kf = pin.id();
	tracker_.setReferenceKeyFrame(kf, f->id);  // the frame tracked last is anchored to it when it is that frame
	inserter_.keyFrameInserted(f->id);
	lastKeyFrameFrame_ = f->id;
	lastKeyFrame_ = kf;
	{
		std::lock_guard<std::mutex> sl(statsMtx_);
		stats_.keyFrames++;
		if (forced) stats_.forcedKeyFrames++;
	}
	return pin;
}

void CYesSlamSystem::dispatchKeyFrame(CSparseMap::TPin pin, const std::shared_ptr<const TFrame>& f)
{
	// The pin goes with the keyframe to mapKeyFrame, which adopts it; should the keyframe never get
	// there (a stage could not queue it), it is undone as this returns.
	const TKeyFrameId kf = pin.id();
	if (dense_)
	{
		// The frame (with its images) travels to the dense stage; the cloud is kept in keyframe
		// coordinates, so the order against local mapping does not matter.
		if (denseStage_)
			denseStage_->submitInto(denseTasks_, [this, kf, f] { denseKeyFrame(kf, f); });
		else
			denseKeyFrame(kf, f);
	}
	if (mappingStage_)
	{
		// Every keyframe in order, as in sequential mode; a full queue holds tracking back.
		mappingStage_->submitInto(mappingTasks_, [this, kf] { mapKeyFrame(kf); });
		pin.release();
		return;
	}
	pin.release();
	mapKeyFrame(kf);
}

TFrameReport CYesSlamSystem::processFrame(const cv::Mat& bgr, const cv::Mat& depth, double timestamp,
										  const mrpt::img::TCamera& camera, std::optional<double> depthTime)
{
	try
	{
		collectMapping(false);  // a failure of the mapping stage ends the run here, with its message
	}
	catch (...)
	{
		settle();  // after the stages stopped changing the map (issue 40 d)
		throw;
	}
	TFrameReport rep;
	std::map<std::string, double> ms;
	const std::shared_ptr<TFrame> f = builder_.build(bgr, depth, timestamp, camera, nextFrameId_++, &ms);
	rep.frameId = f->id;

	const TStageClock rest;  // the rest of the frame's features: counted in "orb"
	// Under 0.1 ms apart the depth moves by micrometres: nothing to do.
	if (opts_.tracking.depthMoment && depthTime && std::abs(*depthTime - timestamp) > 1e-4)
		if (const auto motion = tracker_.motionOver(*depthTime - timestamp))
			moveDepthToColourMoment(f->features, depth, CPinholeCamera(f->camera), *motion);
	// The motion model's (mean) velocity corrects almost as well as the true motion's would. A camera reads its rows
	// within a frame period, so a readout longer than the time since the last frame (a faster camera than the one
	// assumed) is cut to it: scaled past the frame motion, its noise grew and the correction diverged.
	if (opts_.tracking.rollingShutter > 0)
	{
		double readout = opts_.tracking.rollingShutter;
		if (lastFrameTime_ && timestamp > *lastFrameTime_) readout = std::min(readout, timestamp - *lastFrameTime_);
		if (const auto motion = tracker_.motionOver(readout))
			unrollShutter(f->features, CPinholeCamera(f->camera), *motion);
	}
	lastFrameTime_ = timestamp;
	rest.addTo(ms, "orb");
	const TStageClock track;
	rep.features = f->size();
	rep.staticFeatures = f->features.numStatic();
	rep.detections = f->detections.size();
	rep.dynamicDetections = static_cast<std::size_t>(
		std::count_if(f->detections.begin(), f->detections.end(), [](const TDetection& x) { return x.dynamic; }));

	std::optional<CKeyFrameInserter::TDecision> decision;
	bool initialising = false;
	// Shared over the frame's tracking and keyframe insertion (mapUpdateMtx_): no correction lands
	// inside them; the keyframes it makes are mapped after the lock is released.
	std::shared_lock<CWriterFirstMutex> frameLock(mapUpdateMtx_);
	std::vector<std::pair<CSparseMap::TPin, std::shared_ptr<const TFrame>>> newKeyFrames;  // pinned until dispatched
	if (map_.numKeyFrames() == 0 && !opts_.system.localizeOnly)
	{
		std::size_t usable = 0;
		for (std::size_t i = 0; i < f->size(); i++) usable += f->usable(i, opts_.tracking.maxDepth);
		if (usable >= opts_.system.minInitPoints)
		{
			f->pose = mrpt::poses::CPose3D();  // the first keyframe defines the world frame
			f->tracked = true;
			f->numInliers = usable;
			initialising = true;
			rep.initialised = true;
		}
	}
	else
	{
		const auto r = tracker_.track(*f);
		rep.relocalised = r.relocalised;
		rep.poseRefused = r.implausible && !f->tracked;
		rep.movingPointsErased = r.movingPointsErased;
	}
	track.addTo(ms, "track");
	// The trajectory stores the pose relative to the reference keyframe as tracking saw it, before
	// this frame's keyframe (if any) goes through local BA, as ORB-SLAM2 does.
	CFrameRecords::TRecord rec;
	rec.t = f->timestamp;
	rec.tracked = f->tracked;
	everTracked_ = everTracked_ || f->tracked;
	rec.hasPose = everTracked_;
	rec.generation = map_.generation();  // no correction lands while this frame holds the map-update lock
	// What a robot gets: the tracked position filtered with the frames before it only; restarted
	// where the map jumped under the pose (a correction, a relocalisation).
	rec.measured = f->pose;
	rec.online =
		onlineFilter_.update(f->timestamp, f->pose, f->tracked, rep.relocalised || rec.generation != lastGeneration_);
	rec.jumped = onlineFilter_.jumped();
	lastGeneration_ = rec.generation;
	f->onlinePose = rec.online;
	if (rec.hasPose) rep.pose = rec.online;
	// Anchored as tracking read the map (not after the mapping steps below moved the keyframe);
	// a frame tracking did not see (before the map exists) keeps its absolute pose.
	rec.anchor = tracker_.anchorOf(f->id).value_or(TAnchor{std::nullopt, f->pose});

	const auto t0 = SteadyClock::now();
	std::shared_ptr<const TFrame> frame = f;
	recent_.push(frame, rec.anchor);
	if (initialising)
	{
		newKeyFrames.emplace_back(insertKeyFrame(frame, false), frame);
		inserter_.addFrame(*frame, {frame->id, 0}, 0);  // the selector's first reference; no new keyframe
		rep.keyFrame = true;
		// The frame of the first keyframe hangs from it like every later frame from its reference:
		// left absolute, a correction that moves the first keyframe left it behind.
		rec.pinTo({*lastKeyFrame_, mrpt::poses::CPose3D()});  // the map's first keyframe is this frame
	}
	else if (frame->tracked && !opts_.system.localizeOnly)
	{
		const auto ref = tracker_.referenceKeyFrame();
		CKeyFrameInserter::TReference refInfo;
		// All the reference's points, not only those three keyframes see as ORB-SLAM2 counts: without point fusion our
		// points gain observations slowly, and that count stays near zero for the first keyframes (counting only those,
		// no second keyframe was ever inserted).
		if (ref) refInfo.points = map_.numKeyFramePoints(*ref);
		const double D = opts_.keyFrames.policy == "semantic" ? motionToReference(*frame) : 0.0;
		decision = inserter_.addFrame(*frame, refInfo, D);
	}
	// Keyframe ids follow time: a decision for a frame not newer than the newest keyframe cannot
	// happen (forced keyframes restart the selector's interval). The buffer holds every frame of an
	// interval of consecutive usable frames (checked at construction), but Algorithm 1 does not count
	// lost frames or frames with too few static features (line 13), so an interval can outlast the
	// buffer when people cover the view: its choice then cannot be honoured and the next interval
	// chooses again (bench_dynamic.sh with whole-box masks stopped on this before).
	if (decision && !(lastKeyFrameFrame_ && decision->frameId <= *lastKeyFrameFrame_))
	{
		// At its pose in the map as it is now (CRecentFrames): a loop correction or global BA since
		// it was tracked would otherwise leave this keyframe and its new points in the old frame.
		if (const auto kf = recent_.tracked(decision->frameId, map_))
		{
			newKeyFrames.emplace_back(insertKeyFrame(kf, decision->forced), kf);
			// frames.csv marks the frame a keyframe is made from, Algorithm 1's earlier picks too (issue 43); [System]
			// keyFrameFramePose = keyframe also hangs it from its keyframe (ORB-SLAM2's; not the default: after local
			// BA it stood out of its neighbours and the real Bonn slice got worse; docs/benchmarks.md).
			const bool own = opts_.system.keyFrameFramePose == "keyframe";
			const TAnchor onKf{*lastKeyFrame_, mrpt::poses::CPose3D()};
			if (kf->id == frame->id)
			{
				rep.keyFrame = true;
				if (own) rec.pinTo(onKf);
			}
			else
				records_.markKeyFrame(kf->id, own ? std::optional<TAnchor>(onKf) : std::nullopt);
		}
	}
	frameLock.unlock();
	// Sequential mode maps here, and a failure there ends the run: the frame is recorded first (its
	// pose was tracked), as a failure of the mapping stage is reported after the frame that met it.
	std::exception_ptr mappingFailure;
	try
	{
		for (auto& [pin, kfFrame] : newKeyFrames) dispatchKeyFrame(std::move(pin), kfFrame);
	}
	catch (...)
	{
		mappingFailure = std::current_exception();
	}
	ms["keyframe"] = msSince(t0);
	const auto record = [&]
	{
		{
			// After the sequential mode's local mapping, as before the protocol: the frame's anchor
			// then keeps the tracked pose through that BA; a correction since tracking (a loop the
			// inline mapping closed, or another thread's) shows as a new generation (setLastFrame).
			std::shared_lock<CWriterFirstMutex> relock(mapUpdateMtx_);
			tracker_.setLastFrame(frame);
		}

		rep.tracked = frame->tracked;
		rep.inliers = frame->numInliers;
		TFrameLogRow row;
		row.frame = frame->id;
		row.timestamp = frame->timestamp;
		row.tracked = rep.tracked;
		row.keyFrame = rep.keyFrame;
		row.relocalised = rep.relocalised;
		row.features = rep.features;
		row.staticFeatures = rep.staticFeatures;
		row.detections = rep.detections;
		row.inliers = rep.inliers;
		row.keyFramesInMap = map_.numKeyFrames();
		row.mapPoints = map_.numPoints();
		const auto stage = [&ms](const char* k)
		{
			const auto it = ms.find(k);
			return it == ms.end() ? 0.f : static_cast<float>(it->second);
		};
		row.detectMs = stage("detect");
		row.detectWaitMs = stage("detect_wait");
		row.maskMs = stage("mask");
		row.orbMs = stage("orb");
		row.trackMs = stage("track");
		row.keyFrameMs = stage("keyframe");
		records_.add(rec, row);

		{
			std::lock_guard<std::mutex> sl(statsMtx_);
			stats_.frames++;
			if (frame->tracked)
				stats_.trackedFrames++;
			else
				stats_.lostFrames++;
			if (rep.relocalised) stats_.relocalisations++;
			if (rep.poseRefused) stats_.refusedPoses++;
			stats_.movingPointsErased += rep.movingPointsErased;
			for (const auto& [k, v] : ms) stats_.stageMs[k].push_back(v);
		}
	};
	if (mappingFailure)
	{
		// Recorded if it can be; the mapping's error is the one the caller gets either way, after
		// the stages settled. No frame callback for it: the run ends here.
		try
		{
			record();
		}
		catch (...)
		{
		}
		settle();  // after the stages stopped changing the map (issue 40 d)
		std::rethrow_exception(mappingFailure);
	}
	record();
	frameCallback_(*frame);  // outside the lock: it may ask for stats()
	return rep;
}

std::string CYesSlamSystem::configUsed() const
{
	// Without the dynamic filter (the baseline) every mode has it off: the file says so plainly.
	if (askedBoxes_ != "auto" || !opts_.system.dynamicFilter) return opts_.dump();
	TYesSlamOptions o = opts_;
	o.geometric.boxes = "auto";
	return "; [GeometricCheck] boxes = auto chose " + opts_.geometric.boxes +
		   " in this run (true only with --localize-only)\n" + o.dump();
}

namespace
{
std::map<TKeyFrameId, mrpt::poses::CPose3D> keyFramePoseMap(const CSparseMap& map)
{
	std::map<TKeyFrameId, mrpt::poses::CPose3D> poses;
	for (const auto& k : map.keyFramePoses()) poses[k.id] = k.pose;
	return poses;
}
}  // namespace

TTrajectory CYesSlamSystem::trajectory() const
{
	return records_.trajectory([this] { return keyFramePoseMap(map_); });
}

TTrajectory CYesSlamSystem::smoothedTrajectory() const
{
	return records_.smoothed([this] { return keyFramePoseMap(map_); });
}

TTrajectory CYesSlamSystem::onlineTrajectory() const
{
	return records_.online();
}

void CYesSlamSystem::correctMap(const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses)
{
	std::unique_lock<CWriterFirstMutex> lk(mapUpdateMtx_);
	map_.applyCorrection(poses);  // a global BA solving now is dropped and runs again (CLoopClosing)
}

std::vector<TFrameLogRow> CYesSlamSystem::frameLog() const
{
	return records_.frameLog();
}

TTrajectory CYesSlamSystem::keyFrameTrajectory() const
{
	TTrajectory out;
	for (const auto& k : map_.keyFramePoses())
		if (!k.bad) out.push_back(TStampedPose::fromPose(k.timestamp, k.pose));
	return out;
}

TSlamStats CYesSlamSystem::stats() const
{
	// The loop stage's figures first, outside this lock (the stage takes its own).
	TLoopStageStats l = loopClosing_ ? loopClosing_->stats() : TLoopStageStats();
	std::lock_guard<std::mutex> sl(statsMtx_);
	TSlamStats s = stats_;
	if (loopClosing_)
	{
		s.loops = l.loops;
		s.loopCorrections = l.loopCorrections;
		s.globalBundleRuns = l.globalBundleRuns;
		s.globalBundleApplied = l.globalBundleApplied;
		s.globalBundleCancelled = l.globalBundleCancelled;
		s.loopRecords = std::move(l.loopRecords);
		for (auto& [stage, ms] : l.stageMs) s.stageMs[stage] = std::move(ms);
	}
	s.mapPoints = map_.numPoints();
	s.keyFramesInMap = map_.numKeyFrames();
	if (dense_)
	{
		s.denseKeyFrames = dense_->numKeyFrames();
		s.densePoints = dense_->numStoredPoints();
		s.denseBytes = dense_->storedBytes();
		s.denseDroppedClouds = dense_->droppedClouds();
	}
	return s;
}

}  // namespace mrpt_yesslam
