// Map reuse figures (issue 17, item 6), two modes used by bench/bench_map.sh:
//   bench_map io MAP.ysm RUNS
//     median load and save time of a saved map over RUNS repetitions, its size, and both per 1000
//     stored keyframes (erased ones included: they are in the file).
//   bench_map localisation FIRST_GT SECOND_GT TRAJECTORY FRAMES_CSV
//     a second pass's trajectory against its ground truth in the saved map's frame, without any
//     alignment (the map's origin is the first pass's first camera pose; both ground truths are in
//     the simulated room's frame): RMSE, and the first frame with a pose and the time to it.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "mrpt_yesslam/data/CSparseMap.h"
#include "mrpt_yesslam/mapio/MapFile.h"
#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/io/WorldFrame.h"
#include "mrpt_yesslam/util/CommandLine.h"
#include "mrpt_yesslam/util/Error.h"

using namespace mrpt_yesslam;

namespace
{
double median(std::vector<double> v)
{
	std::sort(v.begin(), v.end());
	return v.empty() ? 0 : (v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]));
}

int io(const std::string& path, int runs)
{
	using Clock = std::chrono::steady_clock;
	std::vector<double> load, save;
	CSparseMap m;
	TMapFileInfo info;
	const std::string tmp = path + ".bench_copy.ysm";
	for (int r = 0; r < runs; r++)
	{
		auto t0 = Clock::now();
		CSparseMap fresh;
		info = loadMapFile(path, fresh, 0);
		load.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
		t0 = Clock::now();
		saveMapFile(tmp, fresh, info.vocabularyFingerprint);
		save.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
		if (r == 0) loadMapFile(path, m, 0);
	}
	std::filesystem::remove(tmp);
	const auto poses = m.keyFramePoses();
	const double per = 1000.0 / static_cast<double>(std::max<std::size_t>(1, poses.size()));
	std::printf("keyframes: %zu stored (%zu in the map)\npoints: %zu\nbytes: %llu\nload_ms: %.1f\nsave_ms: %.1f\n",
				poses.size(), m.numKeyFrames(), m.numPoints(), static_cast<unsigned long long>(info.bytes),
				median(load), median(save));
	std::printf("per_1000_keyframes: %.1f MB, load %.0f ms, save %.0f ms\n", info.bytes / 1e6 * per, median(load) * per,
				median(save) * per);
	return 0;
}

int localisation(const std::string& gt1Path, const std::string& gt2Path, const std::string& trajPath,
				 const std::string& csvPath)
{
	const auto gt1 = readTumTrajectory(gt1Path), gt2 = readTumTrajectory(gt2Path), est = readTumTrajectory(trajPath);
	if (gt1.empty()) throw InputError(gt1Path, "empty ground truth");
	const auto origin = gt1.front().asPose();
	// The run's export frame (z-up by default; kept from the loaded map) as its header states it.
	const mrpt::poses::CPose3D worldFromMap = readWorldFromMap(trajPath).value_or(mrpt::poses::CPose3D());
	// frames.csv: which frames were tracked, and their times.
	std::ifstream csv(csvPath);
	if (!csv) throw InputError(csvPath, "cannot open");
	std::string line;
	std::getline(csv, line);
	std::vector<bool> tracked;
	std::vector<double> frameMs;
	while (std::getline(csv, line))
	{
		std::vector<std::string> c;
		std::stringstream ls(line);
		for (std::string x; std::getline(ls, x, ',');) c.push_back(x);
		if (c.size() < 16) throw InputError(csvPath, "not a frames.csv");
		tracked.push_back(c[2] == "1");
		double ms = 0;
		for (int k = 11; k <= 15; k++) ms += std::stod(c[k]);
		frameMs.push_back(ms);
	}
	double sum = 0;
	std::size_t used = 0;
	for (std::size_t i = 0; i < est.size() && i < tracked.size(); i++)
	{
		if (!tracked[i]) continue;
		for (const auto& g : gt2)
			if (std::abs(g.t - est[i].t) < 1e-4)
			{
				const auto expected = worldFromMap + (g.asPose() - origin);
				const auto got = est[i].asPose();
				sum += std::pow(got.x() - expected.x(), 2) + std::pow(got.y() - expected.y(), 2) +
					   std::pow(got.z() - expected.z(), 2);
				used++;
				break;
			}
	}
	int first = -1;
	double toFirst = 0;
	for (std::size_t i = 0; i < tracked.size(); i++)
	{
		toFirst += frameMs[i];
		if (tracked[i])
		{
			first = static_cast<int>(i);
			break;
		}
	}
	std::printf(
		"first_pose_frame: %d\ntime_to_first_pose_ms: %.1f\nrmse_in_map_frame_mm: %.1f\ntracked_frames: %zu of %zu\n",
		first, first >= 0 ? toFirst : 0.0, used ? 1000 * std::sqrt(sum / static_cast<double>(used)) : 0.0,
		static_cast<std::size_t>(std::count(tracked.begin(), tracked.end(), true)), tracked.size());
	return 0;
}
}  // namespace

int main(int argc, char** argv)
{
	return runTool(
		"bench_map",
		[&]() -> int
		{
			const std::vector<std::string> a(argv + 1, argv + argc);
			if (a.size() == 3 && a[0] == "io") return io(a[1], std::max(1, std::stoi(a[2])));
			if (a.size() == 5 && a[0] == "localisation") return localisation(a[1], a[2], a[3], a[4]);
			std::fprintf(
				stderr,
				"usage: bench_map io MAP.ysm RUNS | bench_map localisation FIRST_GT SECOND_GT TRAJECTORY FRAMES_CSV\n");
			return 2;
		});
}
