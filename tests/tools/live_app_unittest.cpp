// yesslam's live path from the command line without a camera: recorded input played as a camera
// (--realtime: capture thread, dropping when SLAM falls behind), --record and its bit-for-bit
// replay, and the errors of OpenNI2 input on a machine without a device.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>

#include "TestUtils.h"
#include "mrpt_yesslam/io/COniWriter.h"
#include "mrpt_yesslam/io/COpenNI2Source.h"
#include "mrpt_yesslam/io/CRawlogSource.h"
#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/io/Trajectory.h"

using namespace yesslam_test;
namespace fs = std::filesystem;

namespace
{
// A number of stats.json's "input" block.
long inputCount(const std::string& statsPath, const std::string& key)
{
	const std::string js = readText(statsPath);
	std::smatch m;
	if (!std::regex_search(js, m, std::regex("\"" + key + "\": ([0-9]+)"))) return -1;
	return std::stol(m[1]);
}

// The ate_rmse yesslam printed (a large number when missing, so that bounds fail).
double ateOf(const std::string& out)
{
	const auto p = out.find("ate_rmse: ");
	return p == std::string::npos ? 1e9 : std::stod(out.substr(p + 10));
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
	const std::string seq = walkingSequence60();
	const auto r = runTool("yesslam", {"--input", seq, "--out", d / "run", "--realtime", "--speed", "10", "--record",
									   d / "recordings/captured.rawlog", "--no-dense-map", "--quiet"});
	ASSERT_EQ(r.exitCode, 0) << r.err;
	const long captured = inputCount(d / "run/stats.json", "captured_frames"),
			   dropped = inputCount(d / "run/stats.json", "dropped_frames");
	const long frames = inputCount(d / "run/stats.json", "frames");
	EXPECT_EQ(captured, 60);
	EXPECT_GT(dropped, 0);
	EXPECT_EQ(frames + dropped, captured);
	EXPECT_NE(readText(d / "run/stats.json").find("\"live\": true"), std::string::npos);
	EXPECT_NE(r.out.find("dropped"), std::string::npos) << r.out;
	EXPECT_EQ(static_cast<long>(mrpt_yesslam::readTumTrajectory(d / "run/trajectory.txt").size()), frames);
	// Into a folder the run made (issue 63 item 6).
	EXPECT_EQ(static_cast<long>(rawlogFrames(d / "recordings/captured.rawlog")), captured)
		<< "dropped frames are recorded too";
}

TEST(LiveApp, ARecordedRunReplaysToTheSameTrajectory)
{
	// --record while SLAM runs sequentially, then the recording as input: the same frames (exact
	// depth, same stamps) give the same trajectory, pose for pose.
	TempDir d("live_replay");
	const std::string seq = walkingSequence60();
	fs::create_directories(d / "rec");
	fs::copy_file(seq + "/detections.txt", d / "rec/detections.txt");
	const auto first = runTool("yesslam", {"--input", seq, "--out", d / "a", "--sequential", "--record",
										   d / "rec/run.rawlog", "--no-dense-map", "--quiet"});
	ASSERT_EQ(first.exitCode, 0) << first.err;
	EXPECT_NE(first.out.find("recorded:        60 frames"), std::string::npos) << first.out;
	// The camera's readout (the simulated sequence's own) went with the recording, in its camera
	// file: the replay uses it without being told (issue 62 item 5).
	EXPECT_TRUE(fs::exists(d / "rec/run_camera.txt"));
	const auto again = runTool("yesslam", {"--input", d / "rec/run.rawlog", "--out", d / "b", "--sequential", "--gt",
										   seq + "/groundtruth.txt", "--no-dense-map", "--quiet"});
	EXPECT_NE(again.out.find("from the recording's camera file"), std::string::npos) << again.out;
	ASSERT_EQ(again.exitCode, 0) << again.err;
	const std::string ta = readText(d / "a/trajectory.txt"), tb = readText(d / "b/trajectory.txt");
	EXPECT_FALSE(ta.empty());
	EXPECT_EQ(ta, tb);
	EXPECT_EQ(inputCount(d / "b/stats.json", "frames"), 60);
}

TEST(LiveApp, WithoutACameraOrWithBadLiveOptionsNothingStarts)
{
	TempDir d("live_errors");
	const std::string seq = walkingSequence60();
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
	// A recording's new folder is made (issue 63 item 6); one under a file cannot be.
	fails({"--input", seq, "--out", d / "run", "--record", seq + "/rgb.txt/x.rawlog"},
		  {"x.rawlog", "cannot make its folder"});
	fails({"--out", d / "run"}, {"--input is required"});
	// A recording is data that cannot be made again (issue 30 item 8): an existing file is not
	// replaced unless asked, and the input itself never.
	writeText(d / "old.rawlog", "an earlier recording");
	fails({"--input", seq, "--out", d / "run", "--record", d / "old.rawlog"}, {"old.rawlog", "exists", "--overwrite"});
	EXPECT_EQ(readText(d / "old.rawlog"), "an earlier recording");
	const auto again =
		runTool("yesslam", {"--input", seq, "--out", d / "ok", "--record", d / "old.rawlog", "--overwrite",
							"--max-frames", "3", "--sequential", "--no-dense-map", "--quiet", "--detector", "none"});
	EXPECT_EQ(again.exitCode, 0) << again.err;
	EXPECT_EQ(rawlogFrames(d / "old.rawlog"), 3u);
	fails({"--input", d / "old.rawlog", "--out", d / "run", "--record", d / "old.rawlog", "--overwrite"},
		  {"old.rawlog", "names the input itself"});
}

TEST(LiveApp, AnOniRecordingPlaysThroughOpenNI2ToTheSameTrajectory)
{
	// The live path through the real OpenNI2 library and its file driver (libOniFile): the
	// recording yesslam-oni wrote, played one frame per request in sequential mode, gives the
	// trajectory of the folder itself, pose for pose (exact depth, same times, same intrinsics);
	// its ground truth was copied beside it and is found.
	TempDir d("live_oni");
	const std::string seq = walkingSequence60(), oni = walkingOniRecording(d.path());
	EXPECT_TRUE(fs::exists(d / "walking_groundtruth.txt"));
	const auto folder =
		runTool("yesslam", {"--input", seq, "--out", d / "folder", "--sequential", "--no-dense-map", "--quiet"});
	ASSERT_EQ(folder.exitCode, 0) << folder.err;
	// Neither the recording nor a camera says that the simulated camera had a global shutter (a
	// camera is taken for a rolling-shutter Kinect or Xtion): the runs say it.
	std::ofstream(d / "global_shutter.ini") << "[Tracking]\nrollingShutter = 0\n";
	const auto live = runTool("yesslam", {"--input", "openni2:" + oni, "--out", d / "oni", "--sequential", "--camera",
										  seq + "/calibration.txt", "--no-dense-map", "--record", d / "oni.rawlog",
										  "--quiet", "--config", d / "global_shutter.ini"});
	ASSERT_EQ(live.exitCode, 0) << live.err;
	EXPECT_NE(live.out.find("camera:          "), std::string::npos) << live.out;
	EXPECT_NE(live.out.find("(recording)"), std::string::npos) << live.out;
	EXPECT_EQ(readText(d / "oni/trajectory.txt"), readText(d / "folder/trajectory.txt"));
	EXPECT_EQ(inputCount(d / "oni/stats.json", "dropped_frames"), 0);
	const double ate = ateOf(live.out);
	EXPECT_LT(ate, 0.03) << "evaluated against the ground truth found beside the recording";
	// What --record kept of that run replays to the same trajectory.
	const auto replay =
		runTool("yesslam", {"--input", d / "oni.rawlog", "--out", d / "replay", "--sequential", "--no-dense-map",
							"--quiet", "--gt", seq + "/groundtruth.txt", "--config", d / "global_shutter.ini"});
	ASSERT_EQ(replay.exitCode, 0) << replay.err;
	EXPECT_EQ(readText(d / "replay/trajectory.txt"), readText(d / "oni/trajectory.txt"));
	// Without --camera the intrinsics come from the field of view the recording states: close.
	const auto fov = runTool("yesslam", {"--input", "openni2:" + oni, "--out", d / "fov", "--sequential",
										 "--no-dense-map", "--quiet", "--config", d / "global_shutter.ini"});
	ASSERT_EQ(fov.exitCode, 0) << fov.err;
	EXPECT_LT(ateOf(fov.out), 0.03);
}

TEST(LiveApp, AnOniPlayedFasterThanSlamDropsFrames)
{
	TempDir d("live_oni_speed");
	const std::string oni = walkingOniRecording(d.path());
	// Ten times the recorded rate (parallel mode: frames as a camera delivers them).
	const auto fast = runTool(
		"yesslam", {"--input", "openni2:" + oni, "--out", d / "fast", "--speed", "10", "--no-dense-map", "--quiet"});
	ASSERT_EQ(fast.exitCode, 0) << fast.err;
	EXPECT_GT(inputCount(d / "fast/stats.json", "dropped_frames"), 0);
	EXPECT_EQ(inputCount(d / "fast/stats.json", "frames") + inputCount(d / "fast/stats.json", "dropped_frames"),
			  inputCount(d / "fast/stats.json", "captured_frames"));
}

TEST(LiveApp, BadRecordingsAndBadConversionsAreRefusedInOneLine)
{
	TempDir d("live_oni_bad");
	const std::string oni = walkingOniRecording(d.path());
	// A recording cut short and one that is not a recording at all: OpenNI2 refuses them; yesslam
	// says which file, in one line, and starts nothing.
	fs::copy_file(oni, d / "cut.oni");
	fs::resize_file(d / "cut.oni", fs::file_size(oni) / 3);
	writeText(d / "text.oni", "this is not an OpenNI recording\n");
	for (const std::string& bad : {std::string(d / "cut.oni"), std::string(d / "text.oni")})
	{
		const auto r = runTool("yesslam", {"--input", "openni2:" + bad, "--out", d / "run"});
		EXPECT_EQ(r.exitCode, 1) << r.err;
		EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
		EXPECT_NE(r.err.find(bad + ": OpenNI2's file driver cannot play it"), std::string::npos) << r.err;
		EXPECT_FALSE(fs::exists(d / "run"));
	}
	// yesslam-oni: a missing input is an error; a folder that is not there for the output is made
	// (issue 30: it was an error), one that cannot be made is an error naming the output.
	const auto missing = runTool("yesslam-oni", {"--input", d / "nothing", "--output", d / "x.oni"});
	EXPECT_EQ(missing.exitCode, 1);
	EXPECT_NE(missing.err.find("not found"), std::string::npos) << missing.err;
	const auto newDir = runTool("yesslam-oni", {"--input", walkingSequence60(), "--output", d / "no/dir/x.oni",
												"--max-frames", "3", "--quiet"});
	EXPECT_EQ(newDir.exitCode, 0) << newDir.err;
	EXPECT_TRUE(fs::exists(d / "no/dir/x.oni"));
	EXPECT_TRUE(fs::exists(d / "no/dir/detections.txt"));
	writeText(d / "file", "not a folder");
	const auto noDir = runTool("yesslam-oni", {"--input", walkingSequence60(), "--output", d / "file/dir/x.oni"});
	EXPECT_EQ(noDir.exitCode, 1);
	EXPECT_NE(noDir.err.find("x.oni"), std::string::npos) << noDir.err;
	EXPECT_FALSE(fs::exists(d / "x.oni"));
}

TEST(LiveApp, AnOniAtANonAsciiOrLongPathPlaysThroughAShortLink)
{
	// OpenNI2's file driver crashed (SIGSEGV, no message) on a path with non-ASCII bytes and
	// refused one of 256 characters or more as "not an OpenNI recording" (issue 30 item 1): such
	// a recording is opened through a short link in a private temporary folder, gone afterwards.
	TempDir d("live_oni_path");
	const std::string oni = walkingOniRecording(d.path());
	const std::string umlaut = d / "p\xc3\xbc/t\xc3\xbc.oni";  // "pü/tü.oni"
	std::string longDir = d / "long";
	while (longDir.size() < 280) longDir += "/a_rather_long_folder_name";
	const std::string longPath = longDir + "/walking.oni";
	fs::create_directories(fs::path(umlaut).parent_path());
	fs::create_directories(longDir);
	fs::copy_file(oni, umlaut);
	fs::copy_file(oni, longPath);
	// With the recording's camera file (its intrinsics and readout go with it; issue 62 item 5).
	for (const std::string& path : {umlaut, longPath})
		fs::copy_file(mrpt_yesslam::recordingCameraPath(oni), mrpt_yesslam::recordingCameraPath(path));
	fs::create_directories(d / "tmp");
	setenv("TMPDIR", (d / "tmp").c_str(), 1);  // where the links go (the tools inherit it)
	// No detector: the copies have no detections.txt beside them.
	const auto ref = runTool("yesslam", {"--input", "openni2:" + oni, "--out", d / "ref", "--sequential",
										 "--no-dense-map", "--quiet", "--max-frames", "12", "--detector", "none"});
	ASSERT_EQ(ref.exitCode, 0) << ref.err;
	for (const std::string& path : {umlaut, longPath})
	{
		const std::string out = d / ("run" + std::to_string(path.size()));
		const auto r = runTool("yesslam", {"--input", "openni2:" + path, "--out", out, "--sequential", "--no-dense-map",
										   "--quiet", "--max-frames", "12", "--detector", "none"});
		ASSERT_EQ(r.exitCode, 0) << path.size() << " characters: " << r.err;
		EXPECT_EQ(readText(out + "/trajectory.txt"), readText(d / "ref/trajectory.txt"))
			<< path.size() << " characters";
	}
	unsetenv("TMPDIR");
	for (const auto& e : fs::directory_iterator(d / "tmp"))
		EXPECT_NE(e.path().filename().string().rfind("yesslam-oni-", 0), 0u) << "left behind: " << e.path();
}

TEST(LiveApp, AnOniHasTheInputsFrameRateAndOneDepthUnit)
{
	// Issue 28 item 7: every .oni said 30 fps whatever its input (OpenNI2 applications pace
	// playback and choose modes by it), and a frame in another depth unit was stored with the
	// first frame's factor (wrong depths, no error).
	TempDir d("oni_rate_units");
	auto frames = makeSyntheticFrames(6, 64, 48);
	for (std::size_t k = 0; k < frames.size(); k++)
	{
		frames[k].tRgb = 1000.0 + static_cast<double>(k) / 15.0;  // 15 Hz
		frames[k].tDepth = frames[k].tRgb + 0.002;
	}
	writeTumFolder(d / "seq", frames);
	{
		mrpt_yesslam::COniWriter w(d / "rate.oni");
		auto src = mrpt_yesslam::openInputSource(d / "seq", mrpt_yesslam::CInputSource::TOptions());
		while (auto obs = src->next()) w.write(*obs);
		w.finish();
		EXPECT_EQ(w.framesPerSecond(), 15u);
	}
	// OpenNI2 itself reads the rate back.
	mrpt_yesslam::COpenNI2Source::TOptions so;
	so.uri = d / "rate.oni";
	so.camera = d / "seq/calibration.txt";
	mrpt_yesslam::COpenNI2Source oni(so);
	EXPECT_NE(oni.description().find("depth 64x48@15"), std::string::npos) << oni.description();

	// A second frame in another depth unit: refused, naming the file, nothing left behind.
	auto src = mrpt_yesslam::openInputSource(d / "seq", mrpt_yesslam::CInputSource::TOptions());
	auto a = src->next(), b = src->next();
	ASSERT_TRUE(a && b);
	b->rangeUnits = a->rangeUnits * 5;
	expectInputError(
		[&]
		{
			mrpt_yesslam::COniWriter w(d / "units.oni");
			w.write(*a);
			w.write(*b);
		},
		{"units.oni", "one depth unit"});
	EXPECT_FALSE(fs::exists(d / "units.oni"));
}

TEST(LiveApp, ARecordingIsPairedByTimeWhenAColourFrameIsMissingAndColourIsLate)
{
	// Issue 28 item 7: playing an .oni in order took one frame of each stream per request, so one
	// colour frame missing (as cameras' recordings have) paired every later depth frame with the
	// next moment's colour. Pairs are now made by time: frame k's depth encodes k, its colour too.
	TempDir d("oni_pairing");
	auto frames = makeSyntheticFrames(10, 64, 48);
	writeTumFolder(d / "seq", frames);
	{
		mrpt_yesslam::COniWriter w(d / "gap.oni");
		auto src = mrpt_yesslam::openInputSource(d / "seq", mrpt_yesslam::CInputSource::TOptions());
		int k = 0;
		while (auto obs = src->next())
		{
			obs->rangeImage.setConstant(static_cast<float>(0.5 + 0.1 * k) / obs->rangeUnits);
			obs->intensityImage =
				mrpt::img::CImage(cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(20 * k)), mrpt::img::DEEP_COPY);
			mrpt_yesslam::TOniStreams streams;
			streams.colourDelay = 0.008;  // colour taken 8 ms after depth
			streams.colour = k != 4;
			w.write(*obs, streams);
			k++;
		}
		w.finish();
	}
	// In order (sequential runs). Not at the recorded pace: OpenNI2's file player thread crashes now
	// and then (SIGSEGV inside libOniFile while Device::close joins it) when this recording (a
	// colour frame missing) is closed after being played to its end at pace: 5 of 40 runs under gdb,
	// also with the player put into manual mode before closing. Paced playback stays covered by
	// AnOniPlayedFasterThanSlamDropsFrames (complete streams; no such crash seen there).
	mrpt_yesslam::COpenNI2Source::TOptions so;
	so.uri = d / "gap.oni";
	so.camera = d / "seq/calibration.txt";
	so.playbackSpeed = -1.0;
	mrpt_yesslam::COpenNI2Source oni(so);
	std::vector<int> seen;
	while (auto f = oni.next())
	{
		const int fromDepth = static_cast<int>(std::lround((f->rangeImage(24, 32) * f->rangeUnits - 0.5) / 0.1));
		const int fromColour = f->intensityImage.asCvMatRef().at<cv::Vec3b>(24, 32)[0] / 20;
		EXPECT_EQ(fromDepth, fromColour) << "frame " << seen.size() << " pairs depth " << fromDepth << " with colour "
										 << fromColour;
		EXPECT_NEAR(mrpt_yesslam::observationTime(*f), frames[static_cast<std::size_t>(fromDepth)].tRgb, 0.01)
			<< "the depth frame's time";
		seen.push_back(fromDepth);
	}
	EXPECT_EQ(seen, (std::vector<int>{0, 1, 2, 3, 5, 6, 7, 8, 9}));
	EXPECT_EQ(oni.skipped(), 1u) << "frame 4's depth had no colour";
}
