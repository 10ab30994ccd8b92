#pragma once
// The work behind apps/yesslam: run the system over a rawlog or TUM folder and write the results
// (trajectory, keyframes, map scene, stats, configuration used, evaluation against ground truth).
#include <cstdint>
#include <functional>
#include <string>

#include "mrpt_yesslam/eval/EvalReport.h"
#include "mrpt_yesslam/eval/GroundTruthFormat.h"
#include "mrpt_yesslam/io/CLiveSource.h"
#include "mrpt_yesslam/system/CYesSlamSystem.h"

namespace mrpt_yesslam
{
/** What a run is doing: a tool says by it what a second Ctrl-C does now. */
enum class ESlamJobPhase
{
	Frames,        //!< reading and tracking frames
	FinalMapping,  //!< input closed, the mapping, loop and global-BA stages finishing their work
	Saving         //!< writing the outputs
};

/** What a second Ctrl-C does in `phase` (the line yesslam prints when it comes). */
const char* secondInterruptNote(ESlamJobPhase phase);

/** Inputs of a run. */
struct TSlamJobOptions
{
	std::string input;   //!< .rawlog, TUM folder, or "openni2[:URI]" (a camera, or an .oni file through OpenNI2)
	std::string outDir;  //!< created if missing
	/** Ground truth; empty = the one found beside the input (findGroundTruthFor), if any. */
	std::string groundTruth;
	/** What the ground truth's poses are: the camera's (TUM) or the Bonn dataset's markers. */
	EGroundTruthFormat groundTruthFormat = EGroundTruthFormat::Auto;
	std::size_t maxFrames = 0;  //!< 0 = all
	/** Recorded input: frames read and dropped before the first one processed (start elsewhere in a
	 * recording, e.g. to relocalise in a saved map from another place). */
	std::size_t skipFrames = 0;
	TYesSlamOptions slam;
	/** Live input: a camera, or recorded input played as one. */
	struct TLive
	{
		int width = 640, height = 480, fps = 30;  //!< OpenNI2 devices: the stream mode
		/** Recorded input delivered at its recorded pace through the capture thread, frames dropped
		 * when SLAM falls behind (what a camera would do); .oni files always play this way unless
		 * the system runs sequentially. */
		bool realtime = false;
		double speed = 1.0;           //!< realtime playback speed (2 = twice as fast as recorded)
		std::size_t slots = 1;        //!< captured frames waiting for SLAM at most; older ones are dropped
		double timeoutSeconds = 5.0;  //!< a camera silent this long is taken as unplugged
	} live;
	/** Every frame read (live: every frame captured, dropped ones included) is written to this
	 * .rawlog as it comes, so the run can be replayed; also on Ctrl-C. Empty = none. */
	std::string record;
	/** Whether `record` may replace an existing file (a recording is data that cannot be made
	 * again: without it, an existing file there is an error before the run). */
	bool overwrite = false;
	/** A saved map (.ysm) to start from: the run localises in it and extends it (with
	 * slam.system.localizeOnly: only localises; the map is not changed, dense mapping is off).
	 * Empty = start from nothing. */
	std::string loadMap;
	/** Where to save the sparse map at the end of the run (also on Ctrl-C and on errors); empty = not saved. */
	std::string saveMap;
	/** Optional: called after each frame (CYesSlamSystem::setFrameCallback). */
	std::function<void(const TFrame&)> onFrame;
	/** Optional: called when the run enters a phase (Frames first, then FinalMapping, then Saving). */
	std::function<void(ESlamJobPhase)> onPhase;
	/** Optional: called on the mapping stage after each keyframe's local mapping
	 * (CYesSlamSystem::setKeyFrameCallback); what it throws is a mapping failure. */
	std::function<void(TKeyFrameId)> onKeyFrame;
	/** Optional: called after each accepted loop's correction (CYesSlamSystem::setLoopCallback);
	 * what it throws is a loop-closing failure. */
	std::function<void(const TLoop&)> onLoop;
};

/** What a run produced. */
struct TSlamJobSummary
{
	TSlamStats stats;
	bool interrupted = false;
	/** What the user should know about the run that is no error (the app prints each as a warning). */
	std::vector<std::string> warnings;
	/** The median over the frames of each frame's median depth, m (0: no depth at all). */
	double typicalDepth = 0;
	/** The rolling-shutter readout the run corrected for (0: none) and where it came from
	 * ("none" when the camera's is not known). */
	TReadout readout;
	/** Outputs a second Ctrl-C skipped while saving (empty when all were written). */
	std::vector<std::string> skippedOutputs;
	std::string groundTruth;                                         //!< the file evaluated against, empty if none
	EGroundTruthFormat groundTruthFormat = EGroundTruthFormat::Tum;  //!< what its poses were taken as
	bool evaluated = false;
	TEvalReport eval;  //!< of trajectory.txt (each frame carried by its reference keyframe's final pose)
	/** Of trajectory_online.txt: the poses the run had while it went (what a robot had). */
	bool evaluatedOnline = false;
	TEvalReport evalOnline;
	/** Of trajectory_smoothed.txt (smoothed after the run with later frames too). */
	bool evaluatedSmoothed = false;
	TEvalReport evalSmoothed;
	std::string evalProblem;  //!< why there is no evaluation although ground truth exists
	std::string detector;     //!< the detector used, in words
	double seconds = 0;       //!< wall time of the frame loop
	/** The dense map written (all zero with dense mapping off). */
	struct TDense
	{
		std::size_t cloudPoints = 0, outliersRemoved = 0;
		/** Octree leaves by EVoxelState (the states map.bt gives; unknown ones are left out of it). */
		std::size_t occupiedLeaves = 0, freeLeaves = 0, unknownLeaves = 0;
		std::uintmax_t plyBytes = 0, otBytes = 0, btBytes = 0;
		double buildMs = 0;  //!< fusion, filtering and octree at the end of the run
		/** With --load-map: the octree started from the loaded map's (same resolution); else false. */
		bool priorMerged = false;
		/** The 2D grid (map_2d.*): cells by value; `gridProblem` says why none was written. */
		std::size_t gridOccupied = 0, gridFree = 0, gridUnknown = 0;
		double gridResolution = 0;
		bool gridFloorSeen = false;
		std::string gridProblem;
	} dense;
	/** The map loaded and the map saved (zero when none). */
	struct TMapFiles
	{
		std::size_t loadedKeyFrames = 0, loadedPoints = 0;
		std::uintmax_t savedBytes = 0;
		std::string saveError;  //!< why --save-map failed (the run's other outputs are written)
		/** The map saved while the run went ([System] checkpointSeconds; 0: off). */
		double checkpointSeconds = 0;
		std::size_t checkpoints = 0, checkpointFailures = 0;
		std::size_t checkpointOctrees = 0;  //!< semantic OctoMaps built for them (CMapCheckpointer)
		double checkpointMaxMs = 0;         //!< the longest checkpoint (wall time, in the background)
		std::string checkpointError;        //!< why the last failed checkpoint failed
	} mapFiles;
	/** Where the frames came from. */
	struct TInput
	{
		bool live = false;          //!< through the capture thread (camera, .oni, --realtime)
		std::string device;         //!< OpenNI2 device and modes, empty otherwise
		TLiveStats stats;           //!< captured and dropped frames (live only)
		bool disconnected = false;  //!< the camera stopped delivering before the run was ended
		std::size_t recorded = 0;   //!< frames written to TSlamJobOptions::record
		/** Entries of recorded input that could not become frames (a TUM folder's colour images
		 * without a depth image within [Input] maxDiff; a rawlog's other observations). */
		std::size_t skippedEntries = 0;
	} input;
};

/** Picks the detector for "auto": the file backend when a detections.txt lies beside the input
 * (yesslam-sim output, yesslam-detect output copied there), yolo when a model is configured, else
 * hog (OpenCV's built-in people detector needs no model). Also fills the file backend's path from
 * the input when it is empty. */
void resolveDetector(CObjectDetector::TOptions& det, const std::string& input);
/** The file an input names: the path itself, the URI of "openni2:URI", empty for "openni2". */
std::string inputFilePath(const std::string& input);

/** Runs SLAM over the input and writes OUT/trajectory.txt, keyframes.txt, map.3Dscene, stats.json,
 * config_used.ini (and eval.json with ground truth; dense_cloud.ply, map.ot, map.bt with dense mapping).
 * `progress(done, total, status)` after each frame; `cancel()` stops early and what exists is saved. The small outputs
 * are written first; once `abortSaving()` turns true, the outputs not yet begun are skipped (stats.json lists them). A
 * bad frame in the middle of the input saves what exists, then throws the InputError. */
TSlamJobSummary runSlamJob(const TSlamJobOptions& opts,
						   const std::function<void(std::size_t, std::size_t, const std::string&)>& progress = {},
						   const std::function<bool()>& cancel = {}, const std::function<bool()>& abortSaving = {});
}  // namespace mrpt_yesslam
