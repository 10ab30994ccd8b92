// How much of the ORB features lie on people, relative to how much of the image they cover: the
// statistic that decides how badly an unfiltered tracker is pulled by walking people. Run on real
// TUM frames (with a detector's boxes) and on yesslam-sim sequences (with their detections.txt) to
// check that the simulator's texture is like a real office's (issue 3: "tune towards real office
// statistics"). Boxes, not exact silhouettes, on both sides so that the two are comparable.
//
// usage: bench_feature_share [--core] (IMAGE DETECTIONS.txt | SIM_FOLDER) ...
// --core: count only the middle of each box (mostly the person) for the inputs after it.
#include <cstdio>
#include <filesystem>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "mrpt_yesslam/detection/CObjectDetector.h"
#include "mrpt_yesslam/feature/COrbExtractor.h"
#include "mrpt_yesslam/io/CTumFolderSource.h"

using namespace mrpt_yesslam;

int main(int argc, char** argv)
{
	if (argc < 2)
	{
		std::fprintf(stderr, "usage: bench_feature_share (IMAGE DETECTIONS.txt | SIM_FOLDER) ...\n");
		return 1;
	}
	std::printf("%-40s %7s %12s %14s %8s %14s\n", "input", "frames", "box pixels", "box keypoints", "ratio",
				"textured cells");
	COrbExtractor orb;
	bool core = false;
	for (int a = 1; a < argc; a++)
	{
		const std::string in = argv[a];
		if (in == "--core")
		{
			core = true;
			continue;
		}
		std::vector<std::pair<std::string, double>> frames;  // image, timestamp
		std::string detFile;
		if (std::filesystem::is_directory(in))
		{
			for (const auto& e : readTumFileList(in + "/rgb.txt")) frames.emplace_back(in + "/" + e.file, e.t);
			detFile = in + "/detections.txt";
		}
		else
		{
			if (a + 1 >= argc) return std::fprintf(stderr, "%s: needs a detections file after it\n", in.c_str()), 1;
			frames.emplace_back(in, 0.0);
			detFile = argv[++a];
		}
		CObjectDetector::TOptions dopt;
		dopt.backend = "file";
		dopt.file = detFile;
		auto det = createObjectDetector(dopt);
		double pix = 0, kp = 0, textured = 0;
		for (const auto& [file, t] : frames)
		{
			const cv::Mat rgb = cv::imread(file, cv::IMREAD_COLOR);
			cv::Mat inBox = cv::Mat::zeros(rgb.size(), CV_8U);
			for (const auto& d : det->detect(rgb, t))
				if (d.dynamic)
				{
					// The box core (middle 40% of the width, 10-90% of the height) is mostly the person
					// on real and simulated frames alike; whole boxes are half background.
					const cv::Rect2f c(d.box.x + 0.3f * d.box.width, d.box.y + 0.1f * d.box.height, 0.4f * d.box.width,
									   0.8f * d.box.height);
					inBox(cv::Rect(core ? c : d.box) & cv::Rect(0, 0, rgb.cols, rgb.rows)).setTo(255);
				}
			const auto f = orb.extract(rgb);
			// Texture statistics independent of the feature budget: the share of 32x32 cells outside the
			// boxes with a FAST corner of threshold 20 (a clear corner). Real offices have blank walls,
			// floor and ceiling; procedural clutter can make every cell textured.
			cv::Mat grey;
			cv::cvtColor(rgb, grey, cv::COLOR_BGR2GRAY);
			std::vector<cv::KeyPoint> fast;
			cv::FAST(grey, fast, 20, true);
			cv::Mat hit = cv::Mat::zeros(rgb.rows / 32, rgb.cols / 32, CV_8U);
			for (const auto& k : fast)
			{
				const int cx = static_cast<int>(k.pt.x) / 32, cy = static_cast<int>(k.pt.y) / 32;
				if (cx < hit.cols && cy < hit.rows) hit.at<uchar>(cy, cx) = 1;
			}
			std::size_t cells = 0, hits = 0;
			for (int cy = 0; cy < hit.rows; cy++)
				for (int cx = 0; cx < hit.cols; cx++)
				{
					if (cv::countNonZero(inBox(cv::Rect(cx * 32, cy * 32, 32, 32))) > 0) continue;
					cells++;
					hits += hit.at<uchar>(cy, cx);
				}
			textured += cells ? static_cast<double>(hits) / static_cast<double>(cells) : 0.0;
			std::size_t n = 0;
			for (const auto& k : f.keypoints)
				n += inBox.at<uchar>(std::min(static_cast<int>(k.pt.y), rgb.rows - 1),
									 std::min(static_cast<int>(k.pt.x), rgb.cols - 1)) != 0;
			pix += cv::countNonZero(inBox) / static_cast<double>(rgb.total());
			kp += f.keypoints.empty() ? 0.0 : static_cast<double>(n) / static_cast<double>(f.keypoints.size());
		}
		const double nf = static_cast<double>(frames.size());
		std::printf("%-40s %7zu %11.1f%% %13.1f%% %8.2f %13.1f%%\n",
					in.substr(in.size() > 40 ? in.size() - 40 : 0).c_str(), frames.size(), 100 * pix / nf,
					100 * kp / nf, pix > 0 ? kp / pix : 0.0, 100 * textured / nf);
	}
	return 0;
}
