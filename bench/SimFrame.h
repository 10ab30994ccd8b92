#pragma once
// One frame of a yesslam-sim folder as the benches read it: colour, depth in metres and the
// simulator's per-pixel class labels (labels/class, COCO class + 1).
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>

namespace yesslam_bench
{
/** A simulator frame. */
struct TSimFrame
{
	cv::Mat rgb;    //!< CV_8UC3 BGR
	cv::Mat depth;  //!< CV_32F metres (depth_scale 5000, as every yesslam-sim folder)
	cv::Mat cls;    //!< labels/class as stored (8 or 16 bit)
};

/** A yesslam-sim folder as the benches read it: associations.txt read once, which pairs each
 * colour image with its depth image (a sequence whose depth images were taken at other moments,
 * --depth-offset, names them by their own stamps). */
class CSimFolder
{
   public:
	explicit CSimFolder(std::string dir) : dir_(std::move(dir))
	{
		std::ifstream in(dir_ + "/associations.txt");
		for (std::string line; std::getline(in, line);)
		{
			std::istringstream row(line);
			std::string t0, rgb, t1, depth;
			if (row >> t0 >> rgb >> t1 >> depth)
				depthOf_[rgb.substr(rgb.find('/') + 1)] = depth.substr(depth.find('/') + 1);
		}
	}
	/** Frame `name` (the file name in rgb/ and labels/class/); its depth image is the one the list
	 * pairs with it, or the same name where the list does not say. */
	TSimFrame read(const std::string& name) const
	{
		const auto it = depthOf_.find(name);
		TSimFrame f;
		f.rgb = cv::imread(dir_ + "/rgb/" + name, cv::IMREAD_COLOR);
		cv::imread(dir_ + "/depth/" + (it == depthOf_.end() ? name : it->second), cv::IMREAD_UNCHANGED)
			.convertTo(f.depth, CV_32F, 1.0 / 5000);
		f.cls = cv::imread(dir_ + "/labels/class/" + name, cv::IMREAD_UNCHANGED);
		return f;
	}

   private:
	std::string dir_;
	std::map<std::string, std::string> depthOf_;  //!< colour file name -> depth file name
};
}  // namespace yesslam_bench
