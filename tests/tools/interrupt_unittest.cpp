// Ctrl-C on a long run: the tool stops cleanly, and what it wrote is complete and readable.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <thread>

#include "TestUtils.h"
#include "mrpt_yesslam/io/CRawlogSource.h"
#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/io/WorldFrame.h"
#include "mrpt_yesslam/jobs/SlamJob.h"
#include "mrpt_yesslam/mapio/MapFile.h"

#include <cmath>

using namespace yesslam_test;
namespace fs = std::filesystem;

namespace
{
// rgb.txt and depth.txt listing the same two files `n` times at 30 Hz: minutes of work for a tool
// from two files on disk.
void writeRepeatedLists(const std::string& folder, const std::string& rgbFile, const std::string& depthFile, int n,
						double depthDelay)
{
	std::ostringstream rgb, depth;
	char buf[128];
	for (int k = 0; k < n; k++)
	{
		std::snprintf(buf, sizeof(buf), "%.6f %s\n", 1000.0 + k / 30.0, rgbFile.c_str());
		rgb << buf;
		std::snprintf(buf, sizeof(buf), "%.6f %s\n", 1000.0 + depthDelay + k / 30.0, depthFile.c_str());
		depth << buf;
	}
	writeText(folder + "/rgb.txt", rgb.str());
	writeText(folder + "/depth.txt", depth.str());
}

// A real Kinect frame pair (TUM fr1_desk, CC BY 4.0) listed 3000 times in `folder`: a still
// camera, minutes of work. Returns the folder ("" when the shared frames are missing).
std::string stillDeskSequence(const std::string& folder)
{
	const std::string src = sharedFile("data/tum_fr1_desk_9frames");
	fs::create_directories(folder + "/rgb");
	fs::create_directories(folder + "/depth");
	std::ifstream rl(src + "/rgb.txt"), dl(src + "/depth.txt");
	auto firstFile = [](std::ifstream& in)
	{
		std::string line;
		while (std::getline(in, line))
			if (!line.empty() && line[0] != '#') return line.substr(line.find(' ') + 1);
		return std::string();
	};
	const std::string rgbFile = firstFile(rl), depthFile = firstFile(dl);
	if (rgbFile.empty() || depthFile.empty()) return {};
	fs::copy_file(src + "/" + rgbFile, folder + "/rgb/0.png");
	fs::copy_file(src + "/" + depthFile, folder + "/depth/0.png");
	fs::copy_file(src + "/calibration.txt", folder + "/calibration.txt");
	writeRepeatedLists(folder, "rgb/0.png", "depth/0.png", 3000, 0.001);
	return folder;
}

// The poses a run's journal (trajectory_online.txt in `out`) holds so far.
long journaledPoses(const std::string& out)
{
	std::ifstream f(out + "/trajectory_online.txt");
	std::string line;
	long n = 0;
	while (std::getline(f, line))
		if (!line.empty() && line[0] != '#') n++;
	return n;
}

/** What an interrupted tool left: its exit code (or -1 if a signal killed it) and its stdout. */
struct TInterrupted
{
	int exitCode = -1;
	std::string out, err;
	bool ready = false;  //!< `ready()` turned true before the deadline (else it was interrupted anyway)
	/** The "frames: N" of its summary, -1 without one. */
	long frames() const
	{
		const auto p = out.find("frames:");
		return p == std::string::npos ? -1 : std::stol(out.substr(p + 7));
	}
};

// Runs one of our tools with `args`, waits (at most 60 s) until `ready()`, presses Ctrl-C (SIGINT,
// or sends `sig`) and waits for it to end.
// With `secondAfterMs` >= 0, Ctrl-C is pressed a second time that long after the first was handled.
TInterrupted interruptWhen(const std::string& tool, const std::vector<std::string>& args,
						   const std::function<bool()>& ready, int sig = SIGINT, int secondAfterMs = -1)
{
	TempDir tmp("sigint_log");
	const std::string log = tmp / "stdout.txt", path = std::string(YESSLAM_TOOLS_DIR) + "/" + tool;
	std::vector<char*> argv{const_cast<char*>(path.c_str())};
	for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
	argv.push_back(nullptr);
	TInterrupted r;
	const pid_t pid = fork();
	if (pid < 0) return r;
	if (pid == 0)
	{
		const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
		dup2(fd, 1);
		const int efd = ::open((log + ".err").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
		dup2(efd, 2);
		execv(path.c_str(), argv.data());
		_exit(127);
	}
	const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
	while (std::chrono::steady_clock::now() < deadline && !(r.ready = ready()))
		std::this_thread::sleep_for(std::chrono::milliseconds(50));
	kill(pid, sig);
	if (secondAfterMs >= 0)
	{
		// Only once the first was handled (its message is on stderr): two signals pending at once
		// are one signal, and on a loaded machine 5 ms can pass before the process runs at all.
		const auto handled = std::chrono::steady_clock::now() + std::chrono::seconds(10);
		while (std::chrono::steady_clock::now() < handled)
		{
			std::ifstream e(log + ".err");
			const std::string text((std::istreambuf_iterator<char>(e)), std::istreambuf_iterator<char>());
			if (text.find("stopping") != std::string::npos) break;
			std::this_thread::sleep_for(std::chrono::milliseconds(1));
		}
		std::this_thread::sleep_for(std::chrono::milliseconds(secondAfterMs));
		kill(pid, sig);
	}
	int status = 0;
	if (waitpid(pid, &status, 0) == pid && WIFEXITED(status)) r.exitCode = WEXITSTATUS(status);
	std::ifstream f(log), e(log + ".err");
	r.out.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
	r.err.assign(std::istreambuf_iterator<char>(e), std::istreambuf_iterator<char>());
	return r;
}
}  // namespace

TEST(Interrupt, Tum2RawlogSavesCompleteFramesOnSigint)
{
	TempDir d("sigint");
	// One real-sized frame listed 3000 times: a conversion of minutes, from two files on disk.
	const auto frames = makeSyntheticFrames(1, 640, 480);
	const std::string folder = d / "seq";
	writeTumFolder(folder, frames);
	writeRepeatedLists(folder, "rgb/1000.000000.png", "depth/1000.004000.png", 3000, 0.004);

	// Ctrl-C once the temporary rawlog has real content.
	const std::string out = d / "seq.rawlog";
	const auto r = interruptWhen("tum2rawlog", {"--input", folder, "--output", out, "--quiet"},
								 [&]
								 {
									 for (const auto& e : fs::directory_iterator(d.path()))
										 if (e.path().string().find("seq.rawlog.tmp.") != std::string::npos &&
											 fs::file_size(e.path()) > 2'000'000)
											 return true;
									 return false;
								 });
	ASSERT_TRUE(r.ready) << "conversion did not start";
	EXPECT_EQ(r.exitCode, 130) << "-1: killed by a signal";

	// The rawlog is in place, every frame in it is complete, and the count matches the summary.
	ASSERT_TRUE(fs::exists(out));
	const long reported = r.frames();
	ASSERT_GE(reported, 0) << r.out;
	mrpt_yesslam::CRawlogSource src(out);
	long n = 0;
	while (auto obs = src.next())
	{
		EXPECT_EQ(obs->rangeImage(7, 9), frames[0].depth.at<uint16_t>(7, 9));
		n++;
	}
	EXPECT_EQ(n, reported);
	EXPECT_GT(n, 0);
	EXPECT_LT(n, 3000);
	for (const auto& e : fs::directory_iterator(d.path()))
		EXPECT_EQ(e.path().string().find(".tmp."), std::string::npos) << "left behind: " << e.path();
}

TEST(Interrupt, SlamAppSavesTheTrajectorySoFarOnSigint)
{
	// A real Kinect frame pair (TUM fr1_desk, CC BY 4.0) listed 3000 times: a still camera, minutes
	// of work. Ctrl-C after a few seconds must leave a complete trajectory of the frames done.
	TempDir d("sigint_slam");
	const std::string folder = stillDeskSequence(d / "seq");
	ASSERT_FALSE(folder.empty());

	// Ctrl-C after 5 s of work.
	const std::string out = d / "run";
	const auto start = std::chrono::steady_clock::now();
	const auto r = interruptWhen("yesslam", {"--input", folder, "--out", out, "--detector", "none", "--quiet"},
								 [&] { return std::chrono::steady_clock::now() - start > std::chrono::seconds(5); });
	EXPECT_EQ(r.exitCode, 130) << "-1: killed by a signal";
	// Said at once, before the saving (issue 30 item 3).
	EXPECT_NE(
		r.err.find(
			"yesslam: stopping: finishing the map and saving the results (Ctrl-C again skips what is not yet written)"),
		std::string::npos)
		<< r.err;
	const long reported = r.frames();
	ASSERT_GE(reported, 0) << r.out;
	EXPECT_GT(reported, 0);
	EXPECT_LT(reported, 3000);
	// Every output is in place and the trajectory has a pose per frame done, all at the start.
	const auto traj = mrpt_yesslam::readTumTrajectory(out + "/trajectory.txt");
	EXPECT_EQ(static_cast<long>(traj.size()), reported);
	for (const auto& t : traj) EXPECT_LT(std::hypot(t.tx - traj[0].tx, t.ty - traj[0].ty, t.tz - traj[0].tz), 0.01);
	for (const char* name : {"keyframes.txt", "map.3Dscene", "stats.json", "config_used.ini"})
		EXPECT_TRUE(fs::exists(out + "/" + name)) << name;
	// stats.json says the run was cut short (issue 18 item 4).
	std::ifstream js(out + "/stats.json");
	const std::string stats((std::istreambuf_iterator<char>(js)), std::istreambuf_iterator<char>());
	EXPECT_NE(stats.find("\"complete\": false"), std::string::npos) << stats;
	EXPECT_NE(stats.find("\"stop_reason\": \"interrupted after " + std::to_string(reported) + " frames\""),
			  std::string::npos)
		<< stats;
	for (const auto& e : fs::directory_iterator(out))
		EXPECT_EQ(e.path().string().find(".tmp."), std::string::npos) << "left behind: " << e.path();
}

TEST(Interrupt, ASecondCtrlCWhileSavingKeepsWhatIsWrittenAndSaysWhatIsNot)
{
	// Issue 30 item 3: the second Ctrl-C killed the process during the saving, leaving only the
	// trajectories. Now the first says at once that the run is stopping and saving; the second
	// stops the saving after the file being written: the small files are always there, stats.json
	// names what was skipped, nothing half-written is left, and the exit code is Ctrl-C's.
	TempDir d("sigint_twice");
	const std::string folder = stillDeskSequence(d / "seq");
	ASSERT_FALSE(folder.empty());
	const std::string out = d / "run";
	const auto start = std::chrono::steady_clock::now();
	const auto r = interruptWhen(
		"yesslam", {"--input", folder, "--out", out, "--detector", "none", "--quiet", "--save-map", d / "map.ysm"},
		[&] { return std::chrono::steady_clock::now() - start > std::chrono::seconds(4); }, SIGINT, 5);
	EXPECT_EQ(r.exitCode, 130) << "-1: killed by a signal\n" << r.err;
	EXPECT_NE(r.err.find("yesslam: stopping: finishing the map and saving the results"), std::string::npos) << r.err;
	EXPECT_NE(r.err.find("yesslam: second Ctrl-C"), std::string::npos) << r.err;
	const long reported = r.frames();
	ASSERT_GT(reported, 0) << r.out;
	EXPECT_EQ(static_cast<long>(mrpt_yesslam::readTumTrajectory(out + "/trajectory.txt").size()), reported);
	for (const char* name : {"trajectory_online.txt", "keyframes.txt", "frames.csv", "config_used.ini", "stats.json"})
		EXPECT_TRUE(fs::exists(out + "/" + name)) << name;
	const std::string stats = readText(out + "/stats.json");
	EXPECT_NE(stats.find("\"complete\": false"), std::string::npos) << stats;
	// What the second Ctrl-C skipped depends on how far the saving had gone: each output is either
	// written whole or named as skipped, in stats.json and on stderr; at least the scene, written
	// last, is skipped this soon after.
	const auto reason = stats.find("saving aborted by a second Ctrl-C: not written: ");
	ASSERT_NE(reason, std::string::npos) << stats;
	const std::string skipped = stats.substr(reason, stats.find('\n', reason) - reason);
	EXPECT_NE(skipped.find("map.3Dscene"), std::string::npos) << skipped;
	const std::pair<const char*, std::string> outputs[] = {{"the dense map", out + "/dense_cloud.ply"},
														   {"the map file", d / "map.ysm"},
														   {"map.3Dscene", out + "/map.3Dscene"}};
	for (const auto& [name, file] : outputs)
	{
		const bool named = skipped.find(name) != std::string::npos;
		EXPECT_NE(fs::exists(file), named) << name << ": " << skipped;
		EXPECT_EQ(r.err.find(std::string("not written (second Ctrl-C): ") + name) != std::string::npos, named) << r.err;
	}
	for (const auto& e : fs::directory_iterator(out))
		EXPECT_EQ(e.path().string().find(".tmp."), std::string::npos) << "left behind: " << e.path();
}

// Issue 42 item 4: a second Ctrl-C during the final mapping said "the file being written is
// finished" when no file was being written. The run tells its phases; in each, the line a second
// Ctrl-C prints says what it does then. Real frames: ../shared/data/tum_fr1_desk_9frames (TUM RGB-D,
// CC BY 4.0, see its SOURCE.md).
TEST(Interrupt, ASecondCtrlCSaysWhatItDoesInThePhaseItComesIn)
{
	TempDir d("phases");
	mrpt_yesslam::TSlamJobOptions o;
	o.input = sharedFile("data/tum_fr1_desk_9frames");
	o.outDir = d / "run";
	o.slam.detector.backend = "none";
	o.slam.input.camera = "fr1";
	std::vector<std::pair<mrpt_yesslam::ESlamJobPhase, bool>> seen;  // phase, trajectory.txt there yet
	o.onPhase = [&](mrpt_yesslam::ESlamJobPhase p) { seen.emplace_back(p, fs::exists(d / "run/trajectory.txt")); };
	mrpt_yesslam::runSlamJob(o);
	using P = mrpt_yesslam::ESlamJobPhase;
	ASSERT_EQ(seen.size(), 3u);
	EXPECT_EQ(seen[0], std::make_pair(P::Frames, false));
	EXPECT_EQ(seen[1], std::make_pair(P::FinalMapping, false));
	EXPECT_EQ(seen[2], std::make_pair(P::Saving, false));
	EXPECT_TRUE(fs::exists(d / "run/trajectory.txt"));
	const std::string mapping = mrpt_yesslam::secondInterruptNote(P::FinalMapping),
					  saving = mrpt_yesslam::secondInterruptNote(P::Saving);
	EXPECT_EQ(mapping.find("file being written"), std::string::npos) << mapping;
	EXPECT_NE(mapping.find("final mapping runs to its end"), std::string::npos) << mapping;
	EXPECT_NE(saving.find("the file being written is finished"), std::string::npos) << saving;
}

TEST(Interrupt, SigtermEndsTheRunCleanlyWithExitCode143)
{
	// A service manager stops a run with SIGTERM: the outputs are saved as for Ctrl-C, and the exit
	// code says which signal it was (128 + 15), as a shell reports it.
	TempDir d("sigterm_slam");
	const std::string folder = stillDeskSequence(d / "seq");
	ASSERT_FALSE(folder.empty());
	const std::string out = d / "run";
	const auto start = std::chrono::steady_clock::now();
	const auto r = interruptWhen(
		"yesslam", {"--input", folder, "--out", out, "--detector", "none", "--quiet"},
		[&] { return std::chrono::steady_clock::now() - start > std::chrono::seconds(3); }, SIGTERM);
	EXPECT_EQ(r.exitCode, 143) << "-1: killed by the signal";
	EXPECT_GT(r.frames(), 0);
	EXPECT_EQ(static_cast<long>(mrpt_yesslam::readTumTrajectory(out + "/trajectory.txt").size()), r.frames());
}

TEST(Interrupt, ALiveRunStoppedWithCtrlCKeepsItsRecordingAndOutputs)
{
	// A recording played as a 30 fps camera (--realtime) with --record: Ctrl-C after 4 s leaves
	// the recording complete and readable (every captured frame), and the usual outputs.
	TempDir d("sigint_live");
	const std::string folder = stillDeskSequence(d / "seq");
	ASSERT_FALSE(folder.empty());
	const std::string out = d / "run", rec = d / "live.rawlog";
	const auto start = std::chrono::steady_clock::now();
	const auto r = interruptWhen(
		"yesslam",
		{"--input", folder, "--out", out, "--realtime", "--record", rec, "--detector", "none", "--no-dense-map"},
		[&] { return std::chrono::steady_clock::now() - start > std::chrono::seconds(4); });
	EXPECT_EQ(r.exitCode, 130) << "-1: killed by a signal";
	ASSERT_GT(r.frames(), 0) << r.out;
	const auto p = r.out.find("recorded:");
	ASSERT_NE(p, std::string::npos) << r.out;
	const long recorded = std::stol(r.out.substr(p + 9));
	EXPECT_GE(recorded, r.frames());
	EXPECT_LT(recorded, 3000) << "a 100 s recording stopped after about 4 s";
	mrpt_yesslam::CRawlogSource src(rec);
	long n = 0;
	while (src.next()) n++;
	EXPECT_EQ(n, recorded);
	EXPECT_EQ(static_cast<long>(mrpt_yesslam::readTumTrajectory(out + "/trajectory.txt").size()), r.frames());
	for (const auto& e : fs::directory_iterator(d.path()))
		EXPECT_EQ(e.path().string().find(".tmp."), std::string::npos) << "left behind: " << e.path();
}

TEST(Interrupt, CtrlCOnAnOniPlaybackKeepsTheOutputsAndTheRecording)
{
	// The walking recording played through OpenNI2 at a fifth of its rate (10 s): Ctrl-C after
	// 3 s leaves complete outputs of the frames done and the frames captured so far recorded.
	TempDir d("sigint_oni");
	const std::string oni = walkingOniRecording(d.path());
	const std::string out = d / "run", rec = d / "slow.rawlog";
	const auto start = std::chrono::steady_clock::now();
	const auto r = interruptWhen(
		"yesslam", {"--input", "openni2:" + oni, "--out", out, "--speed", "0.2", "--no-dense-map", "--record", rec},
		[&] { return std::chrono::steady_clock::now() - start > std::chrono::seconds(3); });
	EXPECT_EQ(r.exitCode, 130) << "-1: killed by a signal";
	ASSERT_GT(r.frames(), 0) << r.out;
	EXPECT_LT(r.frames(), 60);
	EXPECT_NE(readText(out + "/stats.json").find("\"complete\": false"), std::string::npos);
	EXPECT_EQ(static_cast<long>(mrpt_yesslam::readTumTrajectory(out + "/trajectory.txt").size()), r.frames());
	mrpt_yesslam::CRawlogSource src(rec);
	long n = 0;
	while (src.next()) n++;
	EXPECT_GE(n, r.frames());
}

TEST(Interrupt, AKilledRunKeepsItsJournalOfPosesAndFrames)
{
	// Issue 68 item 1: kill -9 (a power cut, the out-of-memory killer) used to leave an empty
	// output folder. The journal keeps every frame's online pose and frames.csv row as the run
	// goes, in whole lines, and stats.json says the run did not end; what an earlier run left
	// there is gone. Real Kinect frames (tum_fr1_rpy_dev), sequential: the journaled poses are the
	// ones a whole run reports for the same frames, in the map's frame.
	const std::string seq = sharedFile("data/tum_fr1_rpy_dev");
	ASSERT_TRUE(fs::exists(seq + "/rgb.txt")) << seq;
	TempDir d("sigkill_journal");
	const std::vector<std::string> common{"--input",      seq,      "--detector", "none", "--no-dense-map",
										  "--sequential", "--quiet"};
	auto with = [&](std::vector<std::string> extra)
	{
		std::vector<std::string> a = common;
		a.insert(a.end(), extra.begin(), extra.end());
		return a;
	};
	const std::string whole = d / "whole";
	const auto w = runTool("yesslam", with({"--out", whole, "--max-frames", "80"}));
	ASSERT_EQ(w.exitCode, 0) << w.err;

	const std::string out = d / "killed";
	fs::create_directories(out);
	writeText(out + "/trajectory.txt", "# an earlier run's\n");
	writeText(out + "/map.3Dscene", "an earlier run's");
	const auto poseLines = [&] { return journaledPoses(out); };
	const auto r = interruptWhen(
		"yesslam", with({"--out", out}), [&] { return poseLines() >= 40; }, SIGKILL);
	ASSERT_TRUE(r.ready) << "no 40 journaled poses within 60 s: " << r.err;
	EXPECT_EQ(r.exitCode, -1) << "killed by the signal";

	// Whole lines: a kill can only cut the last line of a write that spans two pages of the file,
	// which then lacks its newline (the journal's promise: a line with its newline is whole).
	const auto wholeLines = [](const std::string& text) { return text.substr(0, text.rfind('\n') + 1); };
	const auto journal = mrpt_yesslam::parseTumTrajectory(wholeLines(readText(out + "/trajectory_online.txt")),
														  "trajectory_online.txt");  // throws on a malformed line
	ASSERT_GE(journal.size(), 40u);
	EXPECT_LT(journal.size(), 300u) << "killed before the end";
	EXPECT_FALSE(fs::exists(out + "/trajectory.txt"));
	EXPECT_FALSE(fs::exists(out + "/map.3Dscene"));
	const std::string stats = readText(out + "/stats.json");
	EXPECT_NE(stats.find("\"complete\": false"), std::string::npos) << stats;
	EXPECT_NE(stats.find("still running, or it was killed"), std::string::npos) << stats;

	// frames.csv: the header, then one whole row per frame in order, at least one per pose.
	std::istringstream csv(wholeLines(readText(out + "/frames.csv")));
	std::string line;
	ASSERT_TRUE(std::getline(csv, line));
	const auto fields = [](const std::string& l) { return std::count(l.begin(), l.end(), ',') + 1; };
	const auto columns = fields(line);
	std::size_t rows = 0;
	while (std::getline(csv, line))
	{
		ASSERT_EQ(fields(line), columns) << line;
		EXPECT_EQ(std::stoul(line.substr(0, line.find(','))), rows) << line;
		rows++;
	}
	EXPECT_GE(rows, journal.size());
	EXPECT_TRUE(csv.eof());

	// The whole run's online poses, in its world frame: the journal's carried into it.
	const auto finished = mrpt_yesslam::readTumTrajectory(whole + "/trajectory_online.txt");
	const auto worldFromMap = mrpt_yesslam::readWorldFromMap(whole + "/trajectory_online.txt");
	ASSERT_TRUE(worldFromMap);
	const std::size_t n = std::min(journal.size(), finished.size());
	ASSERT_GE(n, 40u);
	for (std::size_t i = 0; i < n; i++)
	{
		const auto p = *worldFromMap + journal[i].asPose();
		const auto q = finished[i].asPose();
		EXPECT_DOUBLE_EQ(journal[i].t, finished[i].t);
		EXPECT_LT(std::hypot(p.x() - q.x(), p.y() - q.y(), p.z() - q.z()), 1e-6) << "frame " << i;
	}
}

TEST(Interrupt, AKilledRunKeepsItsLastMapCheckpointAndALaterRunLocalisesInItAndExtendsIt)
{
	// Issue 68 item 2: with --save-map the map went to its file only at the end, so kill -9 lost
	// it. Now it is saved every [System] checkpointSeconds in the background, atomically: a killed
	// run leaves a whole map (its semantic OctoMap with it) that a later run loads, is placed in by
	// relocalisation where the killed run was, and extends with keyframes of its own. Real Kinect
	// frames (tum_fr1_rpy_dev), sequential.
	const std::string seq = sharedFile("data/tum_fr1_rpy_dev");
	ASSERT_TRUE(fs::exists(seq + "/rgb.txt")) << seq;
	TempDir d("sigkill_checkpoint");
	const std::string cfg = d / "checkpoints.ini", map = d / "office.ysm", out = d / "killed";
	writeText(cfg, "[System]\ncheckpointSeconds = 0.5\n");
	const auto poseLines = [&] { return journaledPoses(out); };
	const auto r = interruptWhen(
		"yesslam",
		{"--input", seq, "--detector", "none", "--sequential", "--quiet", "--config", cfg, "--save-map", map, "--out",
		 out},
		[&] { return poseLines() >= 60 && fs::exists(map); }, SIGKILL);
	ASSERT_TRUE(r.ready) << "no checkpoint after 60 journaled poses within 60 s: " << r.err;
	EXPECT_EQ(r.exitCode, -1) << "killed by the signal";
	const auto journal = mrpt_yesslam::parseTumTrajectory(
		[&](std::string t) { return t.substr(0, t.rfind('\n') + 1); }(readText(out + "/trajectory_online.txt")),
		"trajectory_online.txt");
	ASSERT_LT(journal.size(), 300u) << "killed before the end";

	// A whole map file (the checksum holds), with keyframes and the semantic OctoMap.
	mrpt_yesslam::CSparseMap saved;
	std::unique_ptr<mrpt_yesslam::CSemanticOcTree> octree;
	mrpt_yesslam::TMapFileInfo info;
	ASSERT_NO_THROW(info = mrpt_yesslam::loadMapFile(map, saved, 0, &octree));
	const std::size_t keyFrames = saved.numKeyFrames();
	EXPECT_GE(keyFrames, 2u);
	ASSERT_TRUE(octree) << "the checkpoint holds the semantic OctoMap";
	EXPECT_GT(octree->size(), 1000u);

	// A later run on the same frames loads it, is placed in it and adds keyframes of its own
	// (frames beyond the checkpoint's); its poses are where the killed run had them.
	const std::string resumed = d / "resumed";
	const auto res = runTool("yesslam", {"--input", seq, "--detector", "none", "--sequential", "--quiet",
										 "--no-dense-map", "--max-frames", "150", "--load-map", map, "--out", resumed});
	ASSERT_EQ(res.exitCode, 0) << res.err;
	const std::string stats = readText(resumed + "/stats.json");
	const auto number = [&](const std::string& key)
	{
		const auto p = stats.find("\"" + key + "\": ");
		return p == std::string::npos ? -1.0 : std::stod(stats.substr(p + key.size() + 4));
	};
	EXPECT_GE(number("tracked_frames"), 140) << stats;
	EXPECT_GT(number("keyframes_in_map"), static_cast<double>(keyFrames)) << "the map was extended\n" << stats;
	const auto again = mrpt_yesslam::readTumTrajectory(resumed + "/trajectory_online.txt");
	const auto worldFromMap = mrpt_yesslam::readWorldFromMap(resumed + "/trajectory_online.txt");
	ASSERT_TRUE(worldFromMap);
	std::map<double, mrpt::poses::CPose3D> resumedAt;
	for (const auto& s : again) resumedAt[s.t] = s.asPose();
	std::size_t compared = 0;
	for (const auto& s : journal)
		if (const auto it = resumedAt.find(s.t); it != resumedAt.end())
		{
			const auto p = *worldFromMap + s.asPose();
			const auto& q = it->second;
			EXPECT_LT(std::hypot(p.x() - q.x(), p.y() - q.y(), p.z() - q.z()), 0.03) << "frame at " << s.t;
			compared++;
		}
	EXPECT_GE(compared, 50u);
}
