// Which keypoints tracking used, scored against yesslam-sim's labels (issue 14, item 4): runs a
// SLAM job exactly as `yesslam --sequential --detector auto [--config CFG]` does (same outputs in
// OUT) and prints, over all tracked frames,
//   person_share: inlier keypoints on a person / all inlier keypoints (what could drag the camera)
//   static_kept:  keypoints with depth off every person that are not masked dynamic / all of them
//                 (what the mask leaves to track with; a whole-box mask throws more away)
// then the usual ate_rmse.
//
// usage: bench_keypoint_use --input SIM_FOLDER --out OUT [--config CFG]
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "mrpt_yesslam/jobs/SlamJob.h"
#include "mrpt_yesslam/util/CommandLine.h"
#include "mrpt_yesslam/util/Error.h"

using namespace mrpt_yesslam;

int main(int argc, char** argv)
{
	return runTool("bench_keypoint_use",
				   [&]
				   {
					   std::string config;
					   TSlamJobOptions o;
					   CommandLine cl(
						   "bench_keypoint_use", "bench_keypoint_use --input SIM_FOLDER --out OUT [--config CFG]",
						   "Runs yesslam (sequential, detector auto) on a yesslam-sim sequence and scores the "
						   "keypoints tracking used "
						   "against its labels/class PNGs: person_share and static_kept.",
						   {"bench_keypoint_use --input bench_out/dynamic/undetected_600f_s21 --out /tmp/run"});
					   cl.text("input", "DIR", "a yesslam-sim folder (with labels/class)", &o.input, true);
					   cl.text("out", "DIR", "output folder (as yesslam's)", &o.outDir, true);
					   cl.text("config", "CFG", "config file (INI or YAML)", &config);
					   if (!cl.parse(argc, argv)) return 0;
					   if (!config.empty()) o.slam.loadFromFile(config);
					   o.slam.detector.backend = "auto";
					   o.slam.system.parallel = false;
					   std::size_t personInliers = 0, inliers = 0, staticKept = 0, staticAll = 0;
					   o.onFrame = [&](const TFrame& f)
					   {
						   char name[64];
						   std::snprintf(name, sizeof(name), "/labels/class/%.6f.png", f.timestamp);
						   const cv::Mat cls = cv::imread(o.input + name, cv::IMREAD_UNCHANGED);
						   if (cls.empty())
							   throw InputError(o.input + name, "missing label image (a yesslam-sim folder is needed)");
						   for (std::size_t i = 0; i < f.size(); i++)
						   {
							   const auto& p = f.features.keypoints[i].pt;
							   const int u = std::min(cls.cols - 1, std::max(0, cvRound(p.x))),
										 v = std::min(cls.rows - 1, std::max(0, cvRound(p.y)));
							   const bool person = cls.at<uint16_t>(v, u) == 1;  // COCO person (0) + 1
							   if (f.tracked && i < f.mapPoints.size() && f.mapPoints[i] >= 0)
							   {
								   inliers++;
								   personInliers += person;
							   }
							   if (!person && f.features.depth[i] > 0)
							   {
								   staticAll++;
								   staticKept += !f.features.dynamic[i];
							   }
						   }
					   };
					   const TSlamJobSummary s = runSlamJob(o);
					   std::printf("person_share: %.4f\n",
								   inliers ? static_cast<double>(personInliers) / static_cast<double>(inliers) : 0.0);
					   std::printf("static_kept: %.4f\n",
								   staticAll ? static_cast<double>(staticKept) / static_cast<double>(staticAll) : 0.0);
					   if (s.evaluated) std::printf("ate_rmse: %.9f\n", s.eval.ate.stats.rmse);
					   return 0;
				   });
}
