#pragma once
// The work behind rawlog_tools/yesslam-detect: detection (and, where there is depth, dynamic
// masking) over an image, a TUM folder or a rawlog, written as detections.txt, masks and overlays.
#include <functional>
#include <string>

#include "mrpt_yesslam/detection/CObjectDetector.h"
#include "mrpt_yesslam/dynamic/CDynamicObjectMasker.h"
#include "mrpt_yesslam/io/CInputSource.h"

namespace mrpt_yesslam
{
/** Inputs and outputs of a detection run. */
struct TDetectJobOptions
{
	std::string input;          //!< image file (.png/.jpg/...), TUM folder or .rawlog
	std::string outDir;         //!< created if missing
	bool overlay = false;       //!< also write overlays/<stamp>.png
	std::size_t maxFrames = 0;  //!< 0 = all
	CObjectDetector::TOptions detector;
	CDynamicObjectMasker::TOptions masker;
	CInputSource::TOptions source;
};

/** What a run did. */
struct TDetectJobSummary
{
	std::size_t frames = 0, detections = 0, dynamicDetections = 0, masks = 0;
	double detectMsMedian = 0, maskMsMedian = 0;  //!< per frame
	std::string detectionsFile;
	bool interrupted = false;
};

/** Runs detection over the input; `progress(done,total)` after each frame, `cancel()` stops early
 * (what was done is written). Throws InputError for bad inputs or models. */
TDetectJobSummary runDetectionJob(const TDetectJobOptions& opts,
								  const std::function<void(std::size_t, std::size_t)>& progress = {},
								  const std::function<bool()>& cancel = {});

/** Draws boxes with class names and scores, and tints the mask red, on a copy of `bgr`. */
cv::Mat drawDetectionOverlay(const cv::Mat& bgr, const std::vector<TDetection>& dets, const CObjectDetector& detector,
							 const cv::Mat& mask = {});
}  // namespace mrpt_yesslam
