// Decoding a dataset's PNG frames (issue 41: a sixth of a replay's CPU was libpng's inflate):
// readImageFile (libdeflate for the kinds datasets hold) against cv::imread, file by file, both
// on one thread and interleaved; prints each one's median per frame (colour + depth) and their
// ratio, and fails if any image decodes to different pixels.
//
// usage: bench_png FOLDER [frames] [repeats]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "TumList.h"
#include "mrpt_yesslam/io/PngDecoder.h"

using namespace mrpt_yesslam;

namespace
{
double msSince(std::chrono::steady_clock::time_point t0)
{
	return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

int main(int argc, char** argv)
{
	if (argc < 2)
	{
		std::fprintf(stderr, "usage: bench_png FOLDER [frames] [repeats]\n");
		return 1;
	}
	const std::string folder = argv[1];
	const int frames = argc > 2 ? std::atoi(argv[2]) : 100, repeats = std::max(1, argc > 3 ? std::atoi(argv[3]) : 3);
	std::vector<std::string> rgb, depth;
	if (!yesslam_bench::listFolderImages("bench_png", folder, rgb, depth)) return 1;
	const std::size_t n = std::min({static_cast<std::size_t>(std::max(frames, 1)), rgb.size(), depth.size()});
	if (n == 0)
	{
		std::fprintf(stderr, "bench_png: error: %s has no rgb.txt / depth.txt images\n", folder.c_str());
		return 1;
	}
	cv::setNumThreads(1);
	std::vector<double> ours, opencv;
	try
	{
		for (int r = 0; r < repeats; r++)
			for (std::size_t i = 0; i < n; i++)
			{
				auto t0 = std::chrono::steady_clock::now();
				const cv::Mat a = readImageFile(rgb[i], cv::IMREAD_COLOR, "image"),
							  ad = readImageFile(depth[i], cv::IMREAD_UNCHANGED, "depth image");
				ours.push_back(msSince(t0));
				t0 = std::chrono::steady_clock::now();
				const cv::Mat b = cv::imread(rgb[i], cv::IMREAD_COLOR), bd = cv::imread(depth[i], cv::IMREAD_UNCHANGED);
				opencv.push_back(msSince(t0));
				if (r == 0 && (a.type() != b.type() || ad.type() != bd.type() || cv::norm(a, b, cv::NORM_INF) != 0 ||
							   cv::norm(ad, bd, cv::NORM_INF) != 0))
				{
					std::fprintf(stderr,
								 "bench_png: error: %s or its depth image decodes differently from cv::imread\n",
								 rgb[i].c_str());
					return 1;
				}
			}
	}
	catch (const std::exception& e)
	{
		std::fprintf(stderr, "bench_png: error: %s\n", e.what());
		return 1;
	}
	const auto median = [](std::vector<double> v)
	{
		std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
		return v[v.size() / 2];
	};
	const double mo = median(ours), mc = median(opencv);
	std::printf(
		"%zu frames x %d (colour + depth): readImageFile median %.2f ms, cv::imread %.2f ms, ratio %.2f; same pixels\n",
		n, repeats, mo, mc, mc / mo);
	return 0;
}
