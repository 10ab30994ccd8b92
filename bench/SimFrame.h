#pragma once
// One frame of a yesslam-sim folder as the benches read it: colour, depth in metres and the
// simulator's per-pixel class labels (labels/class, COCO class + 1).
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <fstream>
#include <sstream>
#include <string>

namespace yesslam_bench
{
/** A simulator frame. */
struct TSimFrame
{
	cv::Mat rgb;  //!< CV_8UC3 BGR
	cv::Mat depth;	//!< CV_32F metres (depth_scale 5000, as every yesslam-sim folder)
	cv::Mat cls;  //!< labels/class as stored (8 or 16 bit)
};

/** The depth image associations.txt pairs with colour image `name` (a sequence whose depth images
 * were taken at other moments, --depth-offset, names them by their own stamps); `name` itself
 * when the list does not say. */
inline std::string simDepthName(const std::string& dir, const std::string& name)
{
	std::ifstream in(dir + "/associations.txt");
	for (std::string line; std::getline(in, line);)
	{
		std::istringstream row(line);
		std::string t0, rgb, t1, depth;
		if (row >> t0 >> rgb >> t1 >> depth && rgb == "rgb/" + name) return depth.substr(depth.find('/') + 1);
	}
	return name;
}

/** Reads frame `name` (the file name in rgb/ and labels/class/) of folder `dir`. */
inline TSimFrame readSimFrame(const std::string& dir, const std::string& name)
{
	TSimFrame f;
	f.rgb = cv::imread(dir + "/rgb/" + name, cv::IMREAD_COLOR);
	cv::imread(dir + "/depth/" + simDepthName(dir, name), cv::IMREAD_UNCHANGED).convertTo(f.depth, CV_32F, 1.0 / 5000);
	f.cls = cv::imread(dir + "/labels/class/" + name, cv::IMREAD_UNCHANGED);
	return f;
}
}  // namespace yesslam_bench
