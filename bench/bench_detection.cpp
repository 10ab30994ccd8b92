// Per-frame time of every detector model in ../shared/models on a real 640x480 frame with two
// people, and of the dynamic-object masker (edge_fill, fill, box) for those two boxes on its real
// depth-like input. Prints medians of N runs; run through bench/bench_detection.sh.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>
#include <vector>

#include "mrpt_yesslam/detection/CObjectDetector.h"
#include "mrpt_yesslam/dynamic/CDynamicObjectMasker.h"

using namespace mrpt_yesslam;

namespace
{
double medianMs(const std::vector<double>& v0)
{
	auto v = v0;
	std::sort(v.begin(), v.end());
	return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

template <typename F>
std::vector<double> timeRuns(int n, F&& f)
{
	std::vector<double> ms;
	for (int i = 0; i < n; i++)
	{
		const auto t0 = std::chrono::steady_clock::now();
		f();
		ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
	}
	return ms;
}
}  // namespace

int main(int argc, char** argv)
{
	if (argc < 2)
	{
		std::fprintf(stderr, "usage: bench_detection SHARED_DIR [RUNS]\n");
		return 1;
	}
	const std::string S = argv[1];
	const int runs = argc > 2 ? std::max(1, std::atoi(argv[2])) : 15;
	const cv::Mat img = cv::imread(S + "/data/tum_sample_frames/fr3_walking/fr3_walking_xyz_rgb_1341846313.553992.png");
	if (img.empty())
	{
		std::fprintf(stderr, "bench_detection: error: test frame not found under %s\n", S.c_str());
		return 1;
	}
	std::printf("threads: %d, runs per figure: %d (median, after one warm-up run)\n", cv::getNumThreads(), runs);
	struct M
	{
		const char *label, *model, *weights, *names;
	};
	const std::vector<M> models = {
		{"Yolo-Fastest 1.1 (darknet 320)", "yolo_fastest_darknet/yolo-fastest-1.1.cfg",
		 "yolo_fastest_darknet/yolo-fastest-1.1.weights", "yolo_fastest_darknet/coco.names"},
		{"Yolo-Fastest 1.1 XL (darknet 320)", "yolo_fastest_darknet/yolo-fastest-1.1-xl.cfg",
		 "yolo_fastest_darknet/yolo-fastest-1.1-xl.weights", "yolo_fastest_darknet/coco.names"},
		{"FastestDet (onnx)", "fastestdet_onnx/FastestDet.onnx", "", "fastestdet_onnx/coco.names"},
		{"NanoDet-m 320 (onnx)", "nanodet_m_onnx/nanodet_m_320.onnx", "", "nanodet_m_onnx/coco.names"},
		{"NanoDet-m 416 (onnx)", "nanodet_m_onnx/nanodet_m_416.onnx", "", "nanodet_m_onnx/coco.names"},
		{"YOLOX-Nano (onnx, 416)", "yolox_nano_onnx/yolox_nano.onnx", "", "yolox_nano_onnx/coco_classes.txt"},
	};
	std::vector<TDetection> people;
	for (const auto& m : models)
	{
		CObjectDetector::TOptions o;
		o.model = S + "/models/" + m.model;
		if (*m.weights) o.weights = S + "/models/" + m.weights;
		o.names = S + "/models/" + m.names;
		o.confThreshold = 0.5;
		if (std::string(m.model).find("yolox") != std::string::npos) o.inputSize = 416;
		auto det = createObjectDetector(o);
		std::vector<TDetection> d = det->detect(img, 0);
		const auto ms = timeRuns(runs, [&] { d = det->detect(img, 0); });
		int n = 0;
		for (const auto& x : d) n += x.dynamic;
		if (people.empty() && n == 2)
			for (const auto& x : d)
				if (x.dynamic) people.push_back(x);
		std::printf("detector %-36s %7.1f ms/frame  (%d people found) [%s]\n", m.label, medianMs(ms), n,
					det->description().c_str());
	}

	// Masker: the two people boxes on a 640x480 depth image with a person-like foreground at 1.2 m
	// inside each box and a wall at 3 m, with Kinect-like noise.
	cv::Mat depth(480, 640, CV_32F);
	std::mt19937 rng(1);
	std::normal_distribution<float> n(0, 1);
	for (int y = 0; y < 480; y++)
		for (int x = 0; x < 640; x++)
		{
			bool fg = false;
			for (const auto& p : people)
				fg |= x > p.box.x + 0.2f * p.box.width && x < p.box.br().x - 0.2f * p.box.width &&
					  y > p.box.y + 0.05f * p.box.height;
			const float z = fg ? 1.2f : 3.0f;
			depth.at<float>(y, x) = z + 0.0015f * z * z * n(rng);
		}
	for (const char* method : {"edge_fill", "fill", "box"})
	{
		CDynamicObjectMasker::TOptions o;
		o.method = method;
		CDynamicObjectMasker masker(o);
		masker.compute(depth, people);
		const auto ms = timeRuns(runs * 10, [&] { masker.compute(depth, people); });
		std::printf("masker   %-36s %7.2f ms/frame  (%zu boxes, 640x480)\n", method, medianMs(ms), people.size());
	}
	return 0;
}
