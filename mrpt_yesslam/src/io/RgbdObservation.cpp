#include "mrpt_yesslam/io/RgbdObservation.h"

#include <mrpt/core/Clock.h>
#include <mrpt/img/CImage.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
mrpt::obs::CObservation3DRangeScan::Ptr makeRgbdObservation(double timestamp, const cv::Mat& bgr,
															const cv::Mat& depth16, const TRgbdCamera& camera,
															const std::string& sensorLabel)
{
	auto obs = mrpt::obs::CObservation3DRangeScan::Create();
	obs->timestamp = mrpt::Clock::fromDouble(timestamp);
	obs->sensorLabel = sensorLabel;
	obs->hasIntensityImage = true;
	obs->intensityImage = mrpt::img::CImage(bgr, mrpt::img::DEEP_COPY);
	obs->hasRangeImage = true;
	obs->range_is_depth = true;
	obs->rangeImage_setSize(depth16.rows, depth16.cols);
	for (int r = 0; r < depth16.rows; r++)
	{
		const uint16_t* src = depth16.ptr<uint16_t>(r);
		for (int c = 0; c < depth16.cols; c++) obs->rangeImage(r, c) = src[c];
	}
	obs->rangeUnits = static_cast<float>(1.0 / camera.depthScale);
	obs->cameraParams = camera.intrinsics;
	obs->cameraParamsIntensity = camera.intrinsics;
	// Registered depth: the colour camera sits where the depth camera is. MRPT's depth frame has
	// +X forward, its camera frame +Z forward; this rotation is MRPT's own convention for that.
	obs->relativePoseIntensityWRTDepth = mrpt::poses::CPose3D(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
	obs->maxRange = 10.0f;
	return obs;
}

void validateRgbdObservation(const mrpt::obs::CObservation3DRangeScan& obs, const std::string& where)
{
	if (!obs.hasIntensityImage) throw InputError(where, "frame has no colour image");
	if (!obs.hasRangeImage) throw InputError(where, "frame has no depth image");
	const auto w = obs.intensityImage.getWidth(), h = obs.intensityImage.getHeight();
	if (w == 0 || h == 0) throw InputError(where, "colour image is empty");
	if (obs.rangeImage.cols() == 0 || obs.rangeImage.rows() == 0) throw InputError(where, "depth image is empty");
	if (static_cast<size_t>(obs.rangeImage.cols()) != w || static_cast<size_t>(obs.rangeImage.rows()) != h)
		throw InputError(where, "depth image is " + std::to_string(obs.rangeImage.cols()) + "x" +
									std::to_string(obs.rangeImage.rows()) + " but colour image is " +
									std::to_string(w) + "x" + std::to_string(h) +
									" (registered depth of the same size is required)");
	if (!std::isfinite(obs.rangeUnits) || obs.rangeUnits <= 0)
		throw InputError(where,
						 "depth units (rangeUnits) must be a positive number, got " + std::to_string(obs.rangeUnits));
	const auto& K = obs.cameraParamsIntensity;
	if (!(K.fx() > 0) || !(K.fy() > 0) || !std::isfinite(K.cx()) || !std::isfinite(K.cy()))
		throw InputError(where, "camera intrinsics are not valid (fx, fy must be positive)");
}

double medianDepth(const mrpt::obs::CObservation3DRangeScan& obs, int step)
{
	step = std::max(step, 1);
	std::vector<std::uint16_t> raw;
	raw.reserve(static_cast<std::size_t>(obs.rangeImage.rows() / step + 1) *
				static_cast<std::size_t>(obs.rangeImage.cols() / step + 1));
	for (int r = 0; r < obs.rangeImage.rows(); r += step)
		for (int c = 0; c < obs.rangeImage.cols(); c += step)
			if (obs.rangeImage(r, c) > 0) raw.push_back(obs.rangeImage(r, c));
	if (raw.empty()) return 0;
	auto mid = raw.begin() + static_cast<std::ptrdiff_t>(raw.size() / 2);
	std::nth_element(raw.begin(), mid, raw.end());
	return *mid * static_cast<double>(obs.rangeUnits);
}

std::string implausibleDepthReason(double d)
{
	// Structured-light and time-of-flight RGB-D cameras (Kinect, Xtion, RealSense, Azure Kinect)
	// measure from about 0.3-0.5 m to 5-10 m, noisy beyond 4-5 m; indoors their median depth is 1-4 m. A depth scale
	// off by 5x (1000 for TUM's 5000, or the reverse) moves the median out of that range.
	char b[300];
	if (d <= 0) return "no frame has any depth (all depth pixels are 0)";
	if (d < 0.35)
		std::snprintf(b, sizeof(b),
					  "the median depth is %.2f m, nearer than RGB-D cameras measure (about 0.4-4.5 m): is the depth "
					  "scale right (TUM: 5000, OpenNI: 1000 units a metre)?",
					  d);
	else if (d > 4.5)
		std::snprintf(b, sizeof(b),
					  "the median depth is %.1f m, farther than RGB-D cameras measure well (about 0.4-4.5 m): is the "
					  "depth scale right (TUM: 5000, OpenNI: 1000 units a metre)?",
					  d);
	else
		return {};
	return b;
}

cv::Mat depthInMetres(const mrpt::obs::CObservation3DRangeScan& obs)
{
	cv::Mat d(static_cast<int>(obs.rangeImage.rows()), static_cast<int>(obs.rangeImage.cols()), CV_32F);
	const float u = obs.rangeUnits;
	for (int r = 0; r < d.rows; r++)
	{
		float* dst = d.ptr<float>(r);
		for (int c = 0; c < d.cols; c++) dst[c] = obs.rangeImage(r, c) * u;
	}
	return d;
}

double observationTime(const mrpt::obs::CObservation& obs)
{
	return mrpt::Clock::toDouble(obs.timestamp);
}
}  // namespace mrpt_yesslam
