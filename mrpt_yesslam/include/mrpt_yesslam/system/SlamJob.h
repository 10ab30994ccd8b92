#pragma once
// The work behind apps/yesslam: run the system over a rawlog or TUM folder and write the results
// (trajectory, keyframes, map scene, stats, configuration used, evaluation against ground truth).
#include <cstdint>
#include <functional>
#include <string>

#include "mrpt_yesslam/eval/EvalReport.h"
#include "mrpt_yesslam/system/CYesSlamSystem.h"

namespace mrpt_yesslam
{
/** Inputs of a run. */
struct TSlamJobOptions
{
	std::string input;	//!< .rawlog or TUM folder
	std::string outDir;	 //!< created if missing
	/** Ground truth; empty = the one found beside the input (findGroundTruthFor), if any. */
	std::string groundTruth;
	std::size_t maxFrames = 0;	//!< 0 = all
	TYesSlamOptions slam;
	/** Optional: called after each frame (CYesSlamSystem::setFrameCallback). */
	std::function<void(const TFrame&)> onFrame;
};

/** What a run produced. */
struct TSlamJobSummary
{
	TSlamStats stats;
	bool interrupted = false;
	std::string groundTruth;  //!< the file evaluated against, empty if none
	bool evaluated = false;
	TEvalReport eval;
	std::string evalProblem;  //!< why there is no evaluation although ground truth exists
	std::string detector;  //!< the detector used, in words
	double seconds = 0;	 //!< wall time of the frame loop
	/** The dense map written (all zero with dense mapping off). */
	struct TDense
	{
		std::size_t cloudPoints = 0, outliersRemoved = 0, occupiedLeaves = 0, freeLeaves = 0;
		std::uintmax_t plyBytes = 0, otBytes = 0, btBytes = 0;
		double buildMs = 0;	 //!< fusion, filtering and octree at the end of the run
	} dense;
};

/** Picks the detector for "auto": the file backend when a detections.txt lies beside the input
 * (yesslam-sim output, yesslam-detect output copied there), yolo when a model is configured, else
 * hog (OpenCV's built-in people detector needs no model). Also fills the file backend's path from
 * the input when it is empty. */
void resolveDetector(CObjectDetector::TOptions& det, const std::string& input);

/** Runs SLAM over the input and writes OUT/trajectory.txt, keyframes.txt, map.3Dscene, stats.json,
 * config_used.ini (and eval.json with ground truth; dense_cloud.ply, map.ot, map.bt with dense mapping). `progress(done, total, status)` after each
 * frame; `cancel()` stops early and what exists is saved. A bad frame in the middle of the input
 * saves what exists, then throws the InputError. */
TSlamJobSummary runSlamJob(
	const TSlamJobOptions& opts, const std::function<void(std::size_t, std::size_t, const std::string&)>& progress = {},
	const std::function<bool()>& cancel = {});
}  // namespace mrpt_yesslam
