// Ctrl-C on a long run: the tool stops cleanly, and what it wrote is complete and readable.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <thread>

#include "TestUtils.h"
#include "mrpt_yesslam/io/CRawlogSource.h"
#include "mrpt_yesslam/io/Trajectory.h"

#include <cmath>

using namespace yesslam_test;
namespace fs = std::filesystem;

TEST(Interrupt, Tum2RawlogSavesCompleteFramesOnSigint)
{
	TempDir d("sigint");
	// One real-sized frame listed 3000 times: a conversion of minutes, from two files on disk.
	const auto frames = makeSyntheticFrames(1, 640, 480);
	const std::string folder = d / "seq";
	writeTumFolder(folder, frames);
	std::ostringstream rgb, depth;
	char buf[128];
	for (int k = 0; k < 3000; k++)
	{
		std::snprintf(buf, sizeof(buf), "%.6f rgb/1000.000000.png\n", 1000.0 + k / 30.0);
		rgb << buf;
		std::snprintf(buf, sizeof(buf), "%.6f depth/1000.004000.png\n", 1000.004 + k / 30.0);
		depth << buf;
	}
	writeText(folder + "/rgb.txt", rgb.str());
	writeText(folder + "/depth.txt", depth.str());

	const std::string out = d / "seq.rawlog", log = d / "stdout.txt";
	const std::string tool = std::string(YESSLAM_TOOLS_DIR) + "/tum2rawlog";
	const pid_t pid = fork();
	ASSERT_GE(pid, 0);
	if (pid == 0)
	{
		const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
		dup2(fd, 1);
		execl(tool.c_str(), tool.c_str(), "--input", folder.c_str(), "--output", out.c_str(), "--quiet", nullptr);
		_exit(127);
	}
	// Wait until the temporary rawlog has real content, then press Ctrl-C.
	const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
	bool started = false;
	while (std::chrono::steady_clock::now() < deadline && !started)
	{
		for (const auto& e : fs::directory_iterator(d.path()))
			if (e.path().string().find("seq.rawlog.tmp.") != std::string::npos && fs::file_size(e.path()) > 2'000'000)
				started = true;
		std::this_thread::sleep_for(std::chrono::milliseconds(50));
	}
	ASSERT_TRUE(started) << "conversion did not start";
	ASSERT_EQ(kill(pid, SIGINT), 0);
	int status = 0;
	ASSERT_EQ(waitpid(pid, &status, 0), pid);
	ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
	EXPECT_EQ(WEXITSTATUS(status), 130);

	// The rawlog is in place, every frame in it is complete, and the count matches the summary.
	ASSERT_TRUE(fs::exists(out));
	std::ifstream f(log);
	std::string summary((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
	const auto p = summary.find("frames:");
	ASSERT_NE(p, std::string::npos) << summary;
	const long reported = std::stol(summary.substr(p + 7));
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
	const std::string src = sharedFile("data/tum_fr1_desk_9frames");
	const std::string folder = d / "seq";
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
	ASSERT_FALSE(rgbFile.empty());
	fs::copy_file(src + "/" + rgbFile, folder + "/rgb/0.png");
	fs::copy_file(src + "/" + depthFile, folder + "/depth/0.png");
	fs::copy_file(src + "/calibration.txt", folder + "/calibration.txt");
	std::ostringstream rgb, depth;
	char buf[128];
	for (int k = 0; k < 3000; k++)
	{
		std::snprintf(buf, sizeof(buf), "%.6f rgb/0.png\n", 1000.0 + k / 30.0);
		rgb << buf;
		std::snprintf(buf, sizeof(buf), "%.6f depth/0.png\n", 1000.001 + k / 30.0);
		depth << buf;
	}
	writeText(folder + "/rgb.txt", rgb.str());
	writeText(folder + "/depth.txt", depth.str());

	const std::string out = d / "run", log = d / "stdout.txt";
	const std::string tool = std::string(YESSLAM_TOOLS_DIR) + "/yesslam";
	const pid_t pid = fork();
	ASSERT_GE(pid, 0);
	if (pid == 0)
	{
		const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
		dup2(fd, 1);
		execl(tool.c_str(), tool.c_str(), "--input", folder.c_str(), "--out", out.c_str(), "--detector", "none", "--quiet", nullptr);
		_exit(127);
	}
	std::this_thread::sleep_for(std::chrono::seconds(5));
	ASSERT_EQ(kill(pid, SIGINT), 0);
	int status = 0;
	ASSERT_EQ(waitpid(pid, &status, 0), pid);
	ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
	EXPECT_EQ(WEXITSTATUS(status), 130);
	std::ifstream f(log);
	const std::string summary((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
	const auto p = summary.find("frames:");
	ASSERT_NE(p, std::string::npos) << summary;
	const long reported = std::stol(summary.substr(p + 7));
	EXPECT_GT(reported, 0);
	EXPECT_LT(reported, 3000);
	// Every output is in place and the trajectory has a pose per frame done, all at the start.
	const auto traj = mrpt_yesslam::readTumTrajectory(out + "/trajectory.txt");
	EXPECT_EQ(static_cast<long>(traj.size()), reported);
	for (const auto& t : traj) EXPECT_LT(std::hypot(t.tx, t.ty, t.tz), 0.01);
	for (const char* name : {"keyframes.txt", "map.3Dscene", "stats.json", "config_used.ini"}) EXPECT_TRUE(fs::exists(out + "/" + name)) << name;
	for (const auto& e : fs::directory_iterator(out))
		EXPECT_EQ(e.path().string().find(".tmp."), std::string::npos) << "left behind: " << e.path();
}
