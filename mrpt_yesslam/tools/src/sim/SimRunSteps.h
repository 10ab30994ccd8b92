#pragma once
// Helpers of runSimulation (private to the simulator's files): what an object would cover unoccluded,
// the stage clock, the stamps' text.
#include <mrpt/poses/CPose3D.h>
#include <opencv2/core.hpp>

#include <chrono>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "mrpt_yesslam/io/RgbdCamera.h"
#include "mrpt_yesslam/sim/CSimWorld.h"

namespace mrpt_yesslam::sim_detail
{
/** Pixels covered by object `idx`'s boxes if nothing occluded them (its faces rasterised into `scratch`). */
std::size_t unoccludedPixels(const CSimWorld& world, int idx, const mrpt::poses::CPose3D& Twc, const TRgbdCamera& cam,
							 cv::Mat& scratch);

// Wall time per stage, summed over the run, in first-seen order (yesslam-sim prints it, the
// benchmark reads it): tells whether rendering, our own per-pixel work or encoding is the limit.
class TStageClock
{
   public:
	explicit TStageClock(std::vector<std::pair<std::string, double>>& out) : out_(out) {}
	/** Charges the time since the previous lap to `stage`. */
	void lap(const std::string& stage)
	{
		const auto now = std::chrono::steady_clock::now();
		add(stage, std::chrono::duration<double>(now - last_).count());
		last_ = now;
	}
	void add(const std::string& stage, double sec)
	{
		for (auto& [n, v] : out_)
			if (n == stage)
			{
				v += sec;
				return;
			}
		out_.emplace_back(stage, sec);
	}

   private:
	std::vector<std::pair<std::string, double>>& out_;
	std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

inline std::string stampText(double t)
{
	char b[64];
	std::snprintf(b, sizeof(b), "%.6f", t);
	return b;
}
}  // namespace mrpt_yesslam::sim_detail
