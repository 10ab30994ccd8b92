#pragma once
// Helpers shared by the test executables: paths into ../shared (missing files fail loudly),
// scratch folders, running our tools, and writing small TUM folders with known content.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "mrpt_yesslam/data/TFrame.h"
#include "mrpt_yesslam/sim/CSequenceSimulator.h"

namespace yesslam_test
{
/** Full path of a file under ../shared; throws (failing the test) if it does not exist. */
std::string sharedFile(const std::string& relative);

/** A fresh empty folder under the build tree's temp area, removed at destruction. */
class TempDir
{
   public:
	explicit TempDir(const std::string& tag);
	~TempDir();
	const std::string& path() const { return path_; }
	std::string operator/(const std::string& name) const { return path_ + "/" + name; }

   private:
	std::string path_;
};

/** Result of running a command. */
struct RunResult
{
	int exitCode = -1;
	std::string out, err;
};

/** Runs one of our tools (by name, from the build's rawlog_tools folder) with arguments. */
RunResult runTool(const std::string& tool, const std::vector<std::string>& args);
/** Runs any program (a path, or a name looked up in PATH; exit code 127 if not found). */
RunResult runCommand(const std::string& program, const std::vector<std::string>& args);

/** One frame of a synthetic TUM folder. */
struct SyntheticFrame
{
	double tRgb, tDepth;
	cv::Mat bgr;    //!< CV_8UC3
	cv::Mat depth;  //!< CV_16UC1 raw values
};

/** Frames with deterministic content: a colour gradient + frame index, depth = base + 7*x + 3*y + k
 * so that every raw value (including odd ones) must survive exactly. */
std::vector<SyntheticFrame> makeSyntheticFrames(int n, int w = 64, int h = 48);

/** Writes rgb/, depth/, rgb.txt, depth.txt, calibration.txt for the frame size (fx 535.4 fy 539.2,
 * depth_scale 5000) and optionally groundtruth.txt into `folder`. */
void writeTumFolder(const std::string& folder, const std::vector<SyntheticFrame>& frames, bool withGroundTruth = true,
					bool withCalibration = true);

/** Expects `f()` to throw mrpt_yesslam::InputError with a one-line message containing every fragment. */
template <typename F>
void expectInputError(F&& f, const std::vector<std::string>& fragments)
{
	try
	{
		f();
		ADD_FAILURE() << "no error raised; expected one mentioning " << (fragments.empty() ? "" : fragments[0]);
	}
	catch (const std::runtime_error& e)
	{
		const std::string m = e.what();
		for (const auto& fr : fragments)
			EXPECT_NE(m.find(fr), std::string::npos) << "message: " << m << "\nmissing: " << fr;
		EXPECT_EQ(m.find('\n'), std::string::npos) << "message must be one line: " << m;
	}
}

/** Writes a text file. */
void writeText(const std::string& path, const std::string& content);
/** A whole file's bytes ("" when it cannot be read). */
std::string readText(const std::string& path);

/** The TUM fr3 colour camera (640x480, no distortion). */
mrpt::img::TCamera fr3Camera();
/** A tracked frame at pose `Twc` observing `world` exactly: keypoint j at the projection of point j
 * (octave `octave`), depth = its z, a random descriptor; `ids` are its matched map points. */
std::shared_ptr<mrpt_yesslam::TFrame> observeWorld(std::size_t id, const mrpt::poses::CPose3D& Twc,
												   const std::vector<mrpt::math::TPoint3D>& world,
												   std::vector<mrpt_yesslam::TPointId> ids, std::mt19937& rng,
												   int octave = 0);

/** A yesslam-sim sequence rendered once into the build tree's cache (ctest runs every test in its
 * own process): rendered into a private folder renamed into place, so that tests running in
 * parallel never see half a sequence. Returns its folder. */
std::string cachedSequence(const std::string& name, const mrpt_yesslam::TSimOptions& opts);
/** The generated walking sequence of the system and tool tests (yesslam-sim walking_xyz, 60
 * frames, detections.txt and ground truth), made once and cached. */
std::string walkingSequence60();
/** walkingSequence60() as an OpenNI2 recording `dir`/walking.oni written by yesslam-oni, with its
 * detections.txt beside it (fails the test if the conversion fails). */
std::string walkingOniRecording(const std::string& dir);
}  // namespace yesslam_test
