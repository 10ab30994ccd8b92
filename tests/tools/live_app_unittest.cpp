// yesslam's live path from the command line without a camera: recorded input played as a camera
// (--realtime: capture thread, dropping when SLAM falls behind), --record and its bit-for-bit
// replay, and the errors of OpenNI2 input on a machine without a device.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>

#include "TestUtils.h"
#include "mrpt_yesslam/io/CRawlogSource.h"
#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/sim/CSequenceSimulator.h"

using namespace yesslam_test;
namespace fs = std::filesystem;

namespace
{
// The generated walking sequence the system tests use (yesslam-sim walking_xyz, 60 frames, with
// its detections.txt and ground truth).
std::string walking60()
{
	mrpt_yesslam::TSimOptions o;
	o.preset = "walking_xyz";
	o.frames = 60;
	return cachedSequence("system_walking_xyz_60", o);
}

// A number of stats.json's "input" block.
long inputCount(const std::string& statsPath, const std::string& key)
{
	const std::string js = readText(statsPath);
	std::smatch m;
	if (!std::regex_search(js, m, std::regex("\"" + key + "\": ([0-9]+)"))) return -1;
	return std::stol(m[1]);
}

std::size_t rawlogFrames(const std::string& path)
{
	mrpt_yesslam::CRawlogSource src(path);
	std::size_t n = 0;
	while (src.next()) n++;
	return n;
}
}  // namespace

TEST(LiveApp, ACameraFasterThanSlamHasItsFramesDroppedAndCounted)
{
	// The recording played 10 times faster than it was recorded (300 fps): SLAM cannot keep up, so
	// the capture thread drops the oldest waiting frames; everything captured is still recorded.
	TempDir d("live_app");
	const std::string seq = walking60();
	const auto r = runTool(
		"yesslam", {"--input", seq, "--out", d / "run", "--realtime", "--speed", "10", "--record", d / "captured.rawlog", "--no-dense-map", "--quiet"});
	ASSERT_EQ(r.exitCode, 0) << r.err;
	const long captured = inputCount(d / "run/stats.json", "captured_frames"), dropped = inputCount(d / "run/stats.json", "dropped_frames");
	const long frames = inputCount(d / "run/stats.json", "frames");
	EXPECT_EQ(captured, 60);
	EXPECT_GT(dropped, 0);
	EXPECT_EQ(frames + dropped, captured);
	EXPECT_NE(readText(d / "run/stats.json").find("\"live\": true"), std::string::npos);
	EXPECT_NE(r.out.find("dropped"), std::string::npos) << r.out;
	EXPECT_EQ(static_cast<long>(mrpt_yesslam::readTumTrajectory(d / "run/trajectory.txt").size()), frames);
	EXPECT_EQ(static_cast<long>(rawlogFrames(d / "captured.rawlog")), captured) << "dropped frames are recorded too";
}

TEST(LiveApp, ARecordedRunReplaysToTheSameTrajectory)
{
	// --record while SLAM runs sequentially, then the recording as input: the same frames (exact
	// depth, same stamps) give the same trajectory, pose for pose.
	TempDir d("live_replay");
	const std::string seq = walking60();
	fs::create_directories(d / "rec");
	fs::copy_file(seq + "/detections.txt", d / "rec/detections.txt");
	const auto first = runTool(
		"yesslam", {"--input", seq, "--out", d / "a", "--sequential", "--record", d / "rec/run.rawlog", "--no-dense-map", "--quiet"});
	ASSERT_EQ(first.exitCode, 0) << first.err;
	EXPECT_NE(first.out.find("recorded:        60 frames"), std::string::npos) << first.out;
	const auto again = runTool(
		"yesslam", {"--input", d / "rec/run.rawlog", "--out", d / "b", "--sequential", "--gt", seq + "/groundtruth.txt", "--no-dense-map", "--quiet"});
	ASSERT_EQ(again.exitCode, 0) << again.err;
	const std::string ta = readText(d / "a/trajectory.txt"), tb = readText(d / "b/trajectory.txt");
	EXPECT_FALSE(ta.empty());
	EXPECT_EQ(ta, tb);
	EXPECT_EQ(inputCount(d / "b/stats.json", "frames"), 60);
}

TEST(LiveApp, WithoutACameraOrWithBadLiveOptionsNothingStarts)
{
	TempDir d("live_errors");
	const std::string seq = walking60();
	auto fails = [&](const std::vector<std::string>& args, const std::vector<std::string>& fragments)
	{
		const auto r = runTool("yesslam", args);
		EXPECT_EQ(r.exitCode, 1) << r.err;
		EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
		for (const auto& f : fragments) EXPECT_NE(r.err.find(f), std::string::npos) << r.err << "\nmissing: " << f;
		EXPECT_FALSE(fs::exists(d / "run")) << "a run that cannot start leaves no folder";
	};
	// The test machines have no camera: OpenNI2 itself (real library, real drivers) finds none.
	fails({"--input", "openni2", "--out", d / "run"}, {"no OpenNI2 device found", "lsusb"});
	fails({"--list-devices"}, {"no OpenNI2 device found"});
	fails({"--input", "openni2:" + (d / "missing.oni"), "--out", d / "run"}, {"missing.oni", "not found"});
	fails({"--input", "openni2", "--out", d / "run", "--realtime"}, {"--realtime is for recorded input"});
	fails({"--input", seq, "--out", d / "run", "--realtime", "--speed", "0"}, {"--speed must be in (0, 100]"});
	fails({"--input", "openni2", "--out", d / "run", "--width", "-640"}, {"--width must be a whole number"});
	fails({"--input", seq, "--out", d / "run", "--record", d / "no/such/folder/x.rawlog"}, {"x.rawlog"});
	fails({"--out", d / "run"}, {"--input is required"});
}
