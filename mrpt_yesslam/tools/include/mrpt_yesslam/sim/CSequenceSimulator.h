#pragma once
#include <mrpt/img/TCamera.h>
// yesslam-sim's engine: renders a dynamic office sequence (colour, depth with Kinect-like noise,
// class and instance labels), the camera's ground truth, per-object boxes and visibility, and
// simulated detector output, and writes them as a TUM folder, an MRPT rawlog and a .3Dscene.
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace mrpt_yesslam
{
/** A named scenario modelled on a TUM fr3 sequence. */
struct TSimPreset
{
	std::string name, description;
	std::string motion;            //!< xyz | rpy | halfsphere | static | loop | tour | pan
	int walking = 0, sitting = 0;  //!< default people
	std::size_t frames = 600;
	/** The real sensor model without --real-sensor (a preset made to look like real frames). */
	bool realSensor = false;
	/** Walls without posters: the bare painted walls of a lab. */
	bool bareWalls = false;
	/** The colour/depth offset of the camera the preset copies (TSimOptions::depthOffsetMs). */
	double depthOffsetMs = 0;
};

/** The presets, in the order --list-presets prints them. */
const std::vector<TSimPreset>& simPresets();

/** The version of the simulator's model of world and sensor: a hash of its sources, written into
 * meta.json ("model"), so that a sequence made by another model is not taken for this one's. */
std::string simulatorModelHash();

/** Everything yesslam-sim can be told. */
struct TSimOptions
{
	std::string preset = "walking_xyz";
	std::string outDir;
	uint32_t seed = 1;
	/** The room's own seed (0 = `seed`): two passes with the same roomSeed and different seeds see
	 * the same room in the same world frame, with other noise, detections and people's timing. */
	uint32_t roomSeed = 0;
	std::size_t frames = 0;         //!< 0 = the preset's
	int people = -1;                //!< -1 = the preset's; walking presets add walkers, sitting presets sitters
	std::string trajectoryFile;     //!< replay a TUM trajectory (its stamps and motion) instead of the preset's motion
	std::string texturesDir;        //!< photos instead of procedural textures
	std::string detNoise = "yolo";  //!< none | yolo
	bool noise = true;              //!< depth and colour sensor noise
	bool motionBlur = false;
	bool autoExposure = false;
	/** The sensor as measured on the real Xtion/Kinect frames of ../shared (bench/bench_realism.sh):
	 * depth noise smooth over tens of pixels beside the per-pixel part, depth lost in blobs (at
	 * silhouettes, on some dark surfaces) and in the registration border, an optically soft colour
	 * image; motion blur and auto exposure on. */
	bool realSensor = false;
	/** Each depth image is taken up to this many ms before or after its colour image (0 = with
	 * it): the offset drifts through [-ms, +ms] and back every 444 frames, 0.15 ms a frame at
	 * 16.7 ms, as between the two free-running 30 Hz streams of the real Bonn Xtion. -1 = the
	 * preset's (16.7 for crowd, the real Bonn frames' own; else 0). */
	double depthOffsetMs = -1;
	/** Rolling shutter: the rows of colour and depth image are read top to bottom over this many
	 * ms, each from the camera's pose and the people's positions at its own moment (the stamp is
	 * the middle row's); 0 = global shutter; -1 = the sensor's: 28 with realSensor (Kinect and
	 * Xtion read both images with rolling-shutter CMOS sensors; Kerl et al., ICCV 2015, simulate
	 * 28 ms), else 0. */
	double readoutMs = -1;
	bool movingChair = false;  //!< a chair pushed across the room (not a person)
	/** The preset's camera motion runs this many times faster (frames stay at 30 Hz): a shorter
	 * sequence with the same path (tests), or a harder one. People keep their pace. */
	double speed = 1.0;
	/** This many of the moving people (lowest instance ids first) never appear in detections.txt:
	 * movers the detector never reports, which only a geometric check can reject (issue 14). */
	std::size_t undetectedPeople = 0;
	double missRate = 0;  //!< each detection of a moving object is also dropped with this probability
	bool writeRawlog = true;
	bool overlays = false;    //!< also write labels/overlay/ (colour with labels and boxes drawn)
	std::string commandLine;  //!< recorded in meta.json
};

/** What a run produced. */
struct TSimSummary
{
	std::size_t frames = 0;
	double meanDynamicShare = 0, maxDynamicShare = 0;  //!< share of pixels on moving objects
	std::size_t detections = 0;
	double seconds = 0;
	bool interrupted = false;
	/** Seconds spent per stage (setup, render, labels, depth, noise, objects, rawlog, png, finish),
	 * in pipeline order; png is the writer threads' time, which overlaps the others. */
	std::vector<std::pair<std::string, double>> stageSeconds;
};

/** The intrinsics to give CFBORender so that its images follow `K` with pixel centres at integer
 * coordinates (TUM's convention); CFBORender samples pixel k at k + 0.5. */
mrpt::img::TCamera openGlIntrinsics(const mrpt::img::TCamera& K);

/** Runs a simulation; throws InputError for bad options (unknown preset, unwritable folder,
 * unreadable trajectory). `progress(done,total)` after each frame; `cancel()` stops early and
 * keeps what was written. */

TSimSummary runSimulation(const TSimOptions& opts, const std::function<void(std::size_t, std::size_t)>& progress = {},
						  const std::function<bool()>& cancel = {});
}  // namespace mrpt_yesslam
