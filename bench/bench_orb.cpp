// ORB extraction alone (issue 41 item 2: <= 6 ms median on 640x480 with 1000 features): times
// COrbExtractor::extract on the frames of a TUM-layout folder (colour from rgb.txt, depth from
// depth.txt by order, 16-bit at 5000 per metre), every frame `repeats` times on one thread, and
// prints the median and p95 per frame and a checksum of everything extract() returned (keypoints,
// angles, levels, descriptors, depths), so that a faster build can be shown to give the same features.
//
// usage: bench_orb FOLDER [frames] [repeats]
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "TumList.h"
#include "mrpt_yesslam/feature/COrbExtractor.h"

using namespace mrpt_yesslam;

namespace
{
// FNV-1a over raw bytes: a fingerprint of the features, not a security hash.
void mix(std::uint64_t& h, const void* p, std::size_t n)
{
	const auto* b = static_cast<const unsigned char*>(p);
	for (std::size_t i = 0; i < n; i++) h = (h ^ b[i]) * 1099511628211ULL;
}
}  // namespace

int main(int argc, char** argv)
{
	if (argc < 2)
	{
		std::fprintf(stderr, "usage: bench_orb FOLDER [frames] [repeats]\n");
		return 1;
	}
	const std::string folder = argv[1];
	const int frames = argc > 2 ? std::atoi(argv[2]) : 50, repeats = argc > 3 ? std::atoi(argv[3]) : 5;
	std::vector<std::string> rgb, depth;
	if (!yesslam_bench::listFolderImages("bench_orb", folder, rgb, depth)) return 1;
	std::vector<cv::Mat> images, depths;
	for (int i = 0; i < frames && i < static_cast<int>(rgb.size()); i++)
	{
		images.push_back(cv::imread(rgb[static_cast<std::size_t>(i)], cv::IMREAD_COLOR));
		cv::Mat d;
		if (i < static_cast<int>(depth.size()))
			cv::imread(depth[static_cast<std::size_t>(i)], cv::IMREAD_ANYDEPTH).convertTo(d, CV_32F, 1.0 / 5000);
		depths.push_back(d);
		if (images.back().empty())
		{
			std::fprintf(stderr, "bench_orb: error: %s cannot be read\n", rgb[static_cast<std::size_t>(i)].c_str());
			return 1;
		}
	}
	const COrbExtractor orb;
	std::vector<double> ms;
	std::uint64_t h = 1469598103934665603ULL;
	std::size_t keypoints = 0;
	for (int r = 0; r < repeats; r++)
		for (std::size_t i = 0; i < images.size(); i++)
		{
			const auto t0 = std::chrono::steady_clock::now();
			const TFeatures f = orb.extract(images[i], depths[i]);
			ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
			if (r > 0) continue;
			keypoints += f.keypoints.size();
			for (std::size_t k = 0; k < f.keypoints.size(); k++)
			{
				const auto& kp = f.keypoints[k];
				mix(h, &kp.pt, sizeof kp.pt);
				mix(h, &kp.angle, sizeof kp.angle);
				mix(h, &kp.octave, sizeof kp.octave);
				mix(h, &f.depth[k], sizeof(float));
			}
			if (!f.descriptors.empty()) mix(h, f.descriptors.data, f.descriptors.total() * f.descriptors.elemSize());
		}
	std::sort(ms.begin(), ms.end());
	std::printf("%zu frames x %d: extract median %.2f ms, p95 %.2f ms; %zu keypoints; checksum %016llx\n",
				images.size(), repeats, ms[ms.size() / 2], ms[ms.size() * 95 / 100], keypoints,
				static_cast<unsigned long long>(h));
	return 0;
}
