// Dynamic-object masking measured against the simulator's ground truth (the paper's figure 3
// claim): for each yesslam-sim folder given, with its simulated detections (detections.txt), the
// person mask of each method (whole box, plain depth flood fill, edge-enhanced flood fill) is
// compared with the true person pixels (labels/class == person), and ORB keypoints are classified
// (eq. 3) against the keypoints that truly lie on people.
// usage: bench_masking [--frames N] [--dilate PX] [--tolerance M] [--gain G] [--blur SIGMA] [--dump DIR] SIM_FOLDER...
// Options apply to the folders after them. --gain and --blur set laplacianGain and blurSigma of
// the edge-enhanced fill, for sweeping the paper's enhancement.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "mrpt_yesslam/detection/CObjectDetector.h"
#include "mrpt_yesslam/dynamic/CDynamicObjectMasker.h"
#include "mrpt_yesslam/feature/COrbExtractor.h"
#include "SimFrame.h"
#include "mrpt_yesslam/io/CTumFolderSource.h"

using namespace mrpt_yesslam;

int main(int argc, char** argv)
{
	if (argc < 2)
	{
		std::fprintf(stderr,
					 "usage: bench_masking [--frames N] [--dilate PX] [--tolerance M] [--gain G] [--blur SIGMA] "
					 "[--dump DIR] SIM_FOLDER [SIM_FOLDER...]\n");
		return 1;
	}
	std::size_t maxFrames = 0;  // 0 = all
	double tolerance = CDynamicObjectMasker::TOptions().loDiff;
	std::string dumpDir;  // --dump: per-frame pictures of where each method errs
	int dilate = CDynamicObjectMasker::TOptions().dilatePixels;
	double gain = CDynamicObjectMasker::TOptions().laplacianGain, blur = CDynamicObjectMasker::TOptions().blurSigma;
	std::printf("%-22s %-10s %8s %8s %10s %10s %10s %10s %9s\n", "sequence", "method", "mask IoU", "IoU box", "kp prec",
				"kp recall", "rec. box", "static kept", "ms/frame");
	for (int a = 1; a < argc; a++)
	{
		const std::string dir = argv[a];
		if ((dir == "--frames" || dir == "--dilate" || dir == "--dump" || dir == "--tolerance" || dir == "--gain" ||
			 dir == "--blur") &&
			a + 1 < argc)
		{
			if (dir == "--gain")
				gain = std::stod(argv[++a]);
			else if (dir == "--blur")
				blur = std::stod(argv[++a]);
			else if (dir == "--tolerance")
				tolerance = std::stod(argv[++a]);
			else if (dir == "--dump")
				dumpDir = argv[++a];
			else if (dir == "--frames")
				maxFrames = std::stoul(argv[++a]);
			else
				dilate = std::stoi(argv[++a]);
			continue;
		}
		auto list = readTumFileList(dir + "/rgb.txt");
		const yesslam_bench::CSimFolder folder(dir);
		if (maxFrames && list.size() > maxFrames) list.resize(maxFrames);
		CObjectDetector::TOptions dopt;
		dopt.backend = "file";
		dopt.file = dir + "/detections.txt";
		auto det = createObjectDetector(dopt);
		COrbExtractor orb;
		for (const char* method : {"box", "fill", "edge_fill"})
		{
			CDynamicObjectMasker::TOptions mo;
			mo.method = method;
			mo.dilatePixels = dilate;
			mo.loDiff = mo.upDiff = tolerance;
			mo.laplacianGain = gain;
			mo.blurSigma = blur;
			CDynamicObjectMasker masker(mo);
			// "box" figures count only true person pixels / keypoints inside a detected dynamic box:
			// what the masker can reach, apart from the detector's misses.
			double inter = 0, uni = 0, interB = 0, uniB = 0, ms = 0;
			std::size_t tp = 0, fp = 0, fn = 0, tpB = 0, fnB = 0, staticTotal = 0, staticKept = 0;
			for (const auto& e : list)
			{
				const std::string name = e.file.substr(e.file.find('/') + 1);
				const auto [rgb, depth, cls] = folder.read(name);
				const auto dets = det->detect(rgb, e.t);
				const auto t0 = std::chrono::steady_clock::now();
				const auto m = masker.compute(depth, dets);
				ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
				const cv::Mat truth = cls == 1;  // COCO person + 1
				inter += cv::countNonZero(truth & m.mask);
				uni += cv::countNonZero(truth | m.mask);
				cv::Mat inBox = cv::Mat::zeros(truth.size(), CV_8U);
				for (const auto& d : dets)
					if (d.dynamic) inBox(cv::Rect(d.box) & cv::Rect(0, 0, inBox.cols, inBox.rows)).setTo(255);
				interB += cv::countNonZero(truth & m.mask & inBox);
				uniB += cv::countNonZero((truth & inBox) | m.mask);
				const auto f = orb.extract(rgb, depth, m.mask);
				if (!dumpDir.empty())
				{
					// Green: person masked; red: person missed; blue: background masked; boxes in yellow.
					cv::Mat v = rgb / 3;
					v.setTo(cv::Scalar(0, 200, 0), truth & m.mask);
					v.setTo(cv::Scalar(0, 0, 255), truth & ~m.mask);
					v.setTo(cv::Scalar(255, 0, 0), ~truth & m.mask);
					for (const auto& d : dets)
						if (d.dynamic) cv::rectangle(v, cv::Rect(d.box), cv::Scalar(0, 255, 255), 1);
					std::filesystem::create_directories(dumpDir);
					cv::imwrite(dumpDir + "/" + method + "_" + name, v);
				}
				for (std::size_t i = 0; i < f.keypoints.size(); i++)
				{
					const cv::Point p(static_cast<int>(std::lround(f.keypoints[i].pt.x)),
									  static_cast<int>(std::lround(f.keypoints[i].pt.y)));
					const bool onPerson =
						truth.at<uchar>(std::min(p.y, truth.rows - 1), std::min(p.x, truth.cols - 1)) != 0;
					tp += onPerson && f.dynamic[i];
					fp += !onPerson && f.dynamic[i];
					fn += onPerson && !f.dynamic[i];
					const bool boxed =
						inBox.at<uchar>(std::min(p.y, truth.rows - 1), std::min(p.x, truth.cols - 1)) != 0;
					tpB += onPerson && boxed && f.dynamic[i];
					fnB += onPerson && boxed && !f.dynamic[i];
					if (!onPerson)
					{
						staticTotal++;
						staticKept += !f.dynamic[i];
					}
				}
			}
			const std::string seq = dir.substr(dir.find_last_of('/') + 1);
			std::printf("%-22s %-10s %8.3f %8.3f %10.3f %10.3f %10.3f %10.3f %9.2f\n", seq.c_str(), method,
						uni > 0 ? inter / uni : 0.0, uniB > 0 ? interB / uniB : 0.0,
						tp + fp ? static_cast<double>(tp) / static_cast<double>(tp + fp) : 0.0,
						tp + fn ? static_cast<double>(tp) / static_cast<double>(tp + fn) : 0.0,
						tpB + fnB ? static_cast<double>(tpB) / static_cast<double>(tpB + fnB) : 0.0,
						staticTotal ? static_cast<double>(staticKept) / static_cast<double>(staticTotal) : 0.0,
						ms / static_cast<double>(list.size()));
		}
	}
	return 0;
}
