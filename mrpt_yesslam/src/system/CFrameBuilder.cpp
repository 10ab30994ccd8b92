#include "mrpt_yesslam/system/CFrameBuilder.h"

#include <algorithm>
#include <chrono>

#include "mrpt_yesslam/util/Stopwatch.h"
#include "mrpt_yesslam/geometry/CPinholeCamera.h"

namespace mrpt_yesslam
{
namespace
{
}  // namespace

CFrameBuilder::CFrameBuilder(std::unique_ptr<CObjectDetector> detector, const CDynamicObjectMasker::TOptions& masker,
							 const COrbExtractor::TOptions& orb, bool dynamicFilter, bool asyncDetection,
							 const CGeometricDynamicCheck::TOptions& check)
	: masker_(masker), extractor_(orb), check_(check), dynamicFilter_(dynamicFilter)
{
	// Overlapping needs features extracted without the mask, which excludeMasked forbids.
	if (detector && asyncDetection && !orb.excludeMasked)
		async_ = std::make_unique<CAsyncDetector>(std::move(detector));
	else
		detector_ = std::move(detector);
}

void CFrameBuilder::detectAhead(const cv::Mat& bgr, double timestamp, std::size_t id)
{
	if (async_ && !async_->submitted(id, timestamp)) async_->submit(bgr, timestamp, id);
}

const CObjectDetector* CFrameBuilder::detector() const
{
	return async_ ? &async_->detector() : detector_.get();
}

void CFrameBuilder::releaseDetectorModel()
{
	if (async_)
		async_->releaseModel();
	else if (detector_)
		detector_->releaseModel();
}

std::shared_ptr<TFrame> CFrameBuilder::build(const cv::Mat& bgr, const cv::Mat& depth, double timestamp,
											 const mrpt::img::TCamera& camera, std::size_t id,
											 std::map<std::string, double>* stageMs)
{
	std::map<std::string, double> ms;
	auto f = std::make_shared<TFrame>();
	f->id = id;
	f->timestamp = timestamp;
	f->camera = camera;
	f->camera.ncols = static_cast<uint32_t>(bgr.cols);
	f->camera.nrows = static_cast<uint32_t>(bgr.rows);

	auto t0 = SteadyClock::now();
	cv::Mat mask;
	auto computeMask = [&]
	{
		const auto tm = SteadyClock::now();
		if (dynamicFilter_)
		{
			// Also without a dynamic detection in this frame: the masker holds objects the detector
			// has just missed ([DynamicMask] holdFrames).
			mask = masker_.compute(depth, f->detections).mask;
			f->numDynamicMasked = static_cast<std::size_t>(cv::countNonZero(mask));
			if (f->numDynamicMasked == 0) mask.release();
		}
		ms["mask"] = msSince(tm);
	};
	if (async_)
	{
		// Detection on the worker while ORB runs here: "detect" is the detector's own time (on its
		// thread), "detect_wait" what this frame still waited for it after ORB.
		if (!async_->submitted(id, timestamp)) async_->submit(bgr, timestamp, id);  // else detectAhead() did
		const TStageClock orb;
		f->features = extractor_.extract(bgr, depth);
		orb.addTo(ms, "orb");
		t0 = SteadyClock::now();
		double detectMs = 0;
		f->detections = async_->get(id, &detectMs);
		ms["detect_wait"] = msSince(t0);
		ms["detect"] = detectMs;
		computeMask();
		COrbExtractor::flagDynamic(f->features, mask);
	}
	else
	{
		if (detector_) f->detections = detector_->detect(bgr, timestamp);
		ms["detect"] = msSince(t0);
		ms["detect_wait"] = ms["detect"];  // in this thread: the frame waits all of it
		computeMask();
		const TStageClock orb;
		f->features = extractor_.extract(bgr, depth, mask);
		orb.addTo(ms, "orb");
	}
	const TStageClock rest;                                                       // counted in "orb"
	if (dynamicFilter_) check_.classify(f->features, f->detections, bgr.size());  // at the raw keypoints, as the mask
	// Colours (and, in the extractor, depth and mask) are looked up at the raw keypoint, in the
	// image as it is; only then are keypoints undistorted: tracking works in undistorted pixels.
	f->colors.reserve(f->size());
	for (const auto& k : f->features.keypoints)
	{
		const cv::Point p(std::clamp(cvRound(k.pt.x), 0, bgr.cols - 1), std::clamp(cvRound(k.pt.y), 0, bgr.rows - 1));
		f->colors.push_back(bgr.at<cv::Vec3b>(p));
	}
	const CPinholeCamera K(f->camera);
	if (K.distorted())
	{
		std::vector<cv::Point2f> pts;
		pts.reserve(f->size());
		for (const auto& k : f->features.keypoints) pts.push_back(k.pt);
		K.undistort(pts);
		for (std::size_t i = 0; i < pts.size(); i++) f->features.keypoints[i].pt = pts[i];
	}
	f->mapPoints.assign(f->size(), -1);
	if (keepImages_)
	{
		// Copies: the caller's buffers (an observation's image) may be reused after this call.
		auto im = std::make_shared<TFrameImages>();
		im->bgr = bgr.clone();
		im->depth = depth.clone();
		im->dynamicMask = mask;  // made for this frame
		f->images = std::move(im);
	}
	rest.addTo(ms, "orb");
	if (stageMs)
		for (const auto& [k, v] : ms) (*stageMs)[k] = v;
	return f;
}
}  // namespace mrpt_yesslam
