// Static-object labels of the dense map measured per pixel against the simulator's ground truth:
// for each yesslam-sim folder, every `step`-th frame, the static detections of detections.txt are
// labelled by each [DenseMapping] labelMethod (CDenseSemanticMapper::labelPixels) and compared with
// labels/class. Per class: recall (true pixels of the class inside one of its detection boxes that
// get its label: what labelling can reach, apart from detector misses), precision (labelled pixels
// that truly are the class) and the share of the class's boxed pixels left without evidence.
// usage: bench_labels [--step K] [--dump DIR] SIM_FOLDER...
// --dump writes, per frame looked at, the labels of each method beside the true ones (label
// colours as the dense map's, boxes drawn; black: no evidence).
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <filesystem>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "mrpt_yesslam/dense/CDenseSemanticMapper.h"
#include "mrpt_yesslam/detection/CObjectDetector.h"
#include "SimFrame.h"
#include "mrpt_yesslam/io/CTumFolderSource.h"

using namespace mrpt_yesslam;

int main(int argc, char** argv)
{
	int step = 10;
	std::string dump;
	std::vector<std::string> dirs;
	for (int a = 1; a < argc; a++)
	{
		const std::string s = argv[a];
		if (s == "--step" && a + 1 < argc)
			step = std::max(1, std::stoi(argv[++a]));
		else if (s == "--dump" && a + 1 < argc)
			dump = argv[++a];
		else
			dirs.push_back(s);
	}
	if (dirs.empty())
	{
		std::fprintf(stderr, "usage: bench_labels [--step K] SIM_FOLDER...\n");
		return 1;
	}
	std::printf("%-24s %-9s %6s %-14s %9s %9s %9s %9s\n", "sequence", "method", "class", "name", "pixels", "recall",
				"precision", "no evid.");
	for (const auto& dir : dirs)
	{
		const auto list = readTumFileList(dir + "/rgb.txt");
		const yesslam_bench::CSimFolder folder(dir);
		CObjectDetector::TOptions dopt;
		dopt.backend = "file";
		dopt.file = dir + "/detections.txt";
		auto det = createObjectDetector(dopt);
		mrpt::img::TCamera cam;
		cam.ncols = 640, cam.nrows = 480;
		cam.fx(535.4), cam.fy(539.2), cam.cx(320.1), cam.cy(247.6);  // yesslam-sim's (calibration.txt)
		for (const char* method : {"fill", "segments"})
		{
			CDenseSemanticMapper::TOptions o;
			o.labelMethod = method;
			const CDenseSemanticMapper mapper(o, CDynamicObjectMasker::TOptions(), 80);
			struct TCount
			{
				double truth = 0, hit = 0, labelled = 0, correct = 0, unknown = 0;
			};
			std::map<int, TCount> per;  // by label (class + 1)
			std::vector<double> times;  // ms per frame
			for (std::size_t i = 0; i < list.size(); i += static_cast<std::size_t>(step))
			{
				const auto& e = list[i];
				const std::string name = e.file.substr(e.file.find('/') + 1);
				const auto [rgb, depth, cls] = folder.read(name);
				std::vector<TDetection> objects;
				for (const auto& d : det->detect(rgb, e.t))
					if (!d.dynamic) objects.push_back(d);
				std::stable_sort(objects.begin(), objects.end(),
								 [](const TDetection& a, const TDetection& b) { return a.box.area() > b.box.area(); });
				const auto t0 = std::chrono::steady_clock::now();
				const TObjectLabels lab = mapper.labelPixels(depth, cam, objects);
				times.push_back(
					std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
				if (!dump.empty())
				{
					cv::Mat got = rgb / 3, truth = rgb / 3;
					for (int v = 0; v < depth.rows; v++)
						for (int u = 0; u < depth.cols; u++)
						{
							const int inst = lab.instance.at<std::uint16_t>(v, u) - 1;
							if (inst >= 0)
								got.at<cv::Vec3b>(v, u) = labelColour(
									static_cast<TSemLabel>(objects[static_cast<std::size_t>(inst)].classId + 1));
							if (lab.unknown.at<uchar>(v, u)) got.at<cv::Vec3b>(v, u) = cv::Vec3b(0, 0, 0);
							const int t =
								cls.type() == CV_16U ? cls.at<std::uint16_t>(v, u) : cls.at<std::uint8_t>(v, u);
							if (t > 1) truth.at<cv::Vec3b>(v, u) = labelColour(static_cast<TSemLabel>(t));
						}
					for (const auto& d : objects)
						cv::rectangle(got, cv::Rect(d.box), labelColour(static_cast<TSemLabel>(d.classId + 1)), 1);
					cv::Mat both;
					cv::hconcat(got, truth, both);
					std::filesystem::create_directories(dump);
					cv::imwrite(dump + "/" + method + "_" + name, both);
				}
				// Pixels inside a box of each class (what labelling can reach).
				std::map<int, cv::Mat> boxed;
				for (const auto& d : objects)
				{
					cv::Mat& m = boxed[d.classId + 1];
					if (m.empty()) m = cv::Mat::zeros(depth.size(), CV_8U);
					m(cv::Rect(d.box) & cv::Rect(0, 0, m.cols, m.rows)).setTo(255);
				}
				for (int v = 0; v < depth.rows; v += 2)
					for (int u = 0; u < depth.cols; u += 2)
					{
						const float z = depth.at<float>(v, u);
						if (!(z > 0.3f && z < 4.0f)) continue;
						const int truth =
							cls.type() == CV_16U ? cls.at<std::uint16_t>(v, u) : cls.at<std::uint8_t>(v, u);
						if (truth == 1) continue;  // people are never labelled (left out of the map)
						const int inst = lab.instance.at<std::uint16_t>(v, u) - 1;
						const int got = inst >= 0 ? objects[static_cast<std::size_t>(inst)].classId + 1 : 0;
						if (got > 0)
						{
							per[got].labelled++;
							per[got].correct += got == truth;
						}
						if (truth > 0 && boxed.count(truth) && boxed[truth].at<uchar>(v, u))
						{
							per[truth].truth++;
							per[truth].hit += got == truth;
							per[truth].unknown += lab.unknown.at<uchar>(v, u) != 0;
						}
					}
			}
			const std::string seq = dir.substr(dir.find_last_of('/') + 1);
			std::sort(times.begin(), times.end());
			std::printf("%-24s %-9s median %.2f ms per frame\n", seq.c_str(), method,
						times.empty() ? 0.0 : times[times.size() / 2]);
			for (const auto& [l, c] : per)
			{
				if (c.truth < 200) continue;
				std::printf("%-24s %-9s %6d %-14s %9.0f %9.3f %9.3f %9.3f\n", seq.c_str(), method, l,
							det->className(l - 1).c_str(), c.truth, c.truth > 0 ? c.hit / c.truth : 0.0,
							c.labelled > 0 ? c.correct / c.labelled : 0.0, c.truth > 0 ? c.unknown / c.truth : 0.0);
			}
		}
	}
	return 0;
}
