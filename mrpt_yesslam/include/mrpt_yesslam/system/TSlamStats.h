#pragma once
// The figures of a SLAM run (what stats.json reports), apart from the system that counts them so
// that exporters (system/SlamExport) need not include the system.
#include <cstddef>
#include <map>
#include <algorithm>
#include <string>
#include <vector>

#include "mrpt_yesslam/loop/CLoopClosing.h"
#include "mrpt_yesslam/loop/CLoopDetector.h"

namespace mrpt_yesslam
{
/** Where a frame's pose comes from (frames.csv column `pose`): how the run had it, and for a lost frame
 * whether trajectory_smoothed.txt fills it in. */
enum class EPoseSource
{
	None,         //!< no pose at all: before the map was made, or before the first localisation in a loaded map
	Tracked,      //!< tracked online (a robot had it while it moved)
	Coasted,      //!< lost: the motion model's guess, as a robot had it while it moved
	Interpolated  //!< lost; trajectory_smoothed.txt fills it in between the tracked poses around it (trajectory.txt:
				  //!< coasted)
};
/** "none", "tracked", "coasted" or "interpolated". */
const char* poseSourceName(EPoseSource s);

/** One processed frame as frames.csv lists it: what tracking made of it, the map's size after it,
 * and its per-stage times (so slow frames and slow stretches of a run can be found). */
struct TFrameLogRow
{
	std::size_t frame = 0;
	double timestamp = 0;
	bool tracked = false, keyFrame = false, relocalised = false;
	std::size_t features = 0, staticFeatures = 0, detections = 0, inliers = 0;
	std::size_t keyFramesInMap = 0, mapPoints = 0;
	/** detectMs: the detector's own time (on its thread when it runs beside ORB extraction);
	 * detectWaitMs: what the frame waited for it (all of it when detection runs in line). */
	float detectMs = 0, maskMs = 0, orbMs = 0, trackMs = 0, keyFrameMs = 0, detectWaitMs = 0;
	EPoseSource pose = EPoseSource::None;  //!< what trajectory.txt holds for it
};

/** Statistics of a run (stats.json). */
struct TSlamStats
{
	std::size_t frames = 0, trackedFrames = 0, lostFrames = 0, relocalisations = 0;
	/** Frames whose solution rested on few inliers and left the motion model's course: not tracked
	 * ([Tracking] weakInliers); counted in lostFrames too. */
	std::size_t refusedPoses = 0;
	std::size_t keyFrames = 0, forcedKeyFrames = 0, mapPoints = 0;
	std::size_t culledKeyFrames = 0;  //!< erased as redundant by local mapping
	std::size_t keyFramesInMap = 0;   //!< keyFrames - culledKeyFrames
	/** Map points tracking erased as moving: in a group the geometric check found moving, or seen through. */
	std::size_t movingPointsErased = 0;
	TLoopDetectionStats loops;        //!< loop detection counts
	std::size_t loopCorrections = 0;  //!< loops whose correction was applied to the map
	std::size_t globalBundleRuns = 0,
				globalBundleApplied =
					0;  //!< global BA after corrections (applied: not overtaken by a newer correction)
	std::size_t globalBundleCancelled = 0;  //!< global BAs stopped early: a newer correction made them stale
	std::vector<TLoopRecord> loopRecords;   //!< every corrected loop, in order
	/** Metres the current keyframe moved in the largest loop correction (0 without one). */
	double largestLoopCorrection() const
	{
		double m = 0;
		for (const auto& r : loopRecords) m = std::max(m, r.correction.correctionMetres);
		return m;
	}
	std::size_t denseKeyFrames = 0, densePoints = 0;  //!< keyframe clouds of the dense map and their stored points
	std::size_t denseBytes = 0;                       //!< memory those clouds take
	std::size_t denseDroppedClouds = 0;  //!< culled keyframes' clouds dropped ([DenseMapping] culledCloudsMB)
	/** Per stage: milliseconds of every frame (detect, mask, orb, track, keyframe) or keyframe (mapping). */
	std::map<std::string, std::vector<double>> stageMs;
};
}  // namespace mrpt_yesslam
