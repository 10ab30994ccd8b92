// Hours in one place, in a minute (issue 68 item 4): the real Bonn dev slice played three times in
// a row, as a robot revisits its room; the run's peak memory stays near one pass's.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "TestUtils.h"

using namespace yesslam_test;
namespace fs = std::filesystem;

namespace
{
// Runs yesslam with `args` (output to /dev/null) and returns its exit code and peak resident
// memory in MB (wait4's rusage: this child's own).
std::pair<int, double> runForPeakMb(const std::vector<std::string>& args)
{
	const std::string path = std::string(YESSLAM_TOOLS_DIR) + "/yesslam";
	std::vector<char*> argv{const_cast<char*>(path.c_str())};
	for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
	argv.push_back(nullptr);
	const pid_t pid = fork();
	if (pid < 0) return {-1, 0.0};
	if (pid == 0)
	{
		const int fd = ::open("/dev/null", O_WRONLY);
		dup2(fd, 1);
		dup2(fd, 2);
		execv(path.c_str(), argv.data());
		_exit(127);
	}
	int status = 0;
	rusage u{};
	if (wait4(pid, &status, 0, &u) != pid) return {-1, 0.0};
	return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, u.ru_maxrss / 1024.0};
}

// `src`'s rgb.txt and depth.txt listed `passes` times into `dst`, each pass one frame interval after
// the last (the camera jumps back to the start), with its images and calibration linked.
void loopFolder(const std::string& src, const std::string& dst, int passes)
{
	fs::create_directories(dst);
	for (const char* d : {"rgb", "depth"}) fs::create_directory_symlink(src + "/" + d, dst + "/" + d);
	fs::copy_file(src + "/calibration.txt", dst + "/calibration.txt");
	struct TEntry
	{
		double t;
		std::string file;
	};
	std::vector<TEntry> rgb, depth;
	const auto read = [](const std::string& path, std::vector<TEntry>& out)
	{
		std::ifstream f(path);
		std::string line;
		while (std::getline(f, line))
		{
			if (line.empty() || line[0] == '#') continue;
			std::istringstream l(line);
			TEntry e;
			if (l >> e.t >> e.file) out.push_back(e);
		}
	};
	read(src + "/rgb.txt", rgb);
	read(src + "/depth.txt", depth);
	ASSERT_GE(rgb.size(), 100u) << src;
	const double span = rgb.back().t - rgb.front().t + (rgb[1].t - rgb[0].t);
	for (const auto& [name, list] : {std::pair{"/rgb.txt", &rgb}, std::pair{"/depth.txt", &depth}})
	{
		std::ostringstream o;
		o.precision(6);
		o << std::fixed;
		for (int p = 0; p < passes; p++)
			for (const auto& e : *list) o << e.t + p * span << " " << e.file << "\n";
		writeText(dst + name, o.str());
	}
}
}  // namespace

TEST(Soak, ThreePassesOfOneRoomPeakNearOnePass)
{
	// Before issue 68 four passes of the crowd sequence peaked at 1.55x one pass's memory; here the
	// map finds itself again at each start and the stores stay bounded (the culled keyframes' clouds,
	// [DenseMapping] culledCloudsMB). Measured 1.03-1.07x over four passes on both real slices
	// (docs/benchmarks.md); the limit leaves room for the parallel runs' spread.
	const std::string slice = sharedFile("data/bonn_crowd_dev");
	ASSERT_TRUE(fs::exists(slice + "/rgb.txt")) << slice;
	TempDir d("soak");
	const std::string looped = d / "bonn_crowd_dev_soak";
	loopFolder(slice, looped, 3);
	const auto [onceExit, onePass] = runForPeakMb({"--input", slice, "--out", d / "once", "--quiet"});
	ASSERT_EQ(onceExit, 0);
	const auto [thriceExit, threePasses] = runForPeakMb({"--input", looped, "--out", d / "thrice", "--quiet"});
	ASSERT_EQ(thriceExit, 0);
	std::printf("peak resident memory: one pass %.1f MB, three passes %.1f MB\n", onePass, threePasses);
	EXPECT_NE(readText(d / "thrice" + "/stats.json").find("\"frames\": 750"), std::string::npos);
	EXPECT_LE(threePasses, 1.2 * onePass) << "one pass " << onePass << " MB, three " << threePasses << " MB";
}
