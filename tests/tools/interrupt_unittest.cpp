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
