#pragma once
// Builds a TFrame from an RGB-D image pair: detection, the dynamic mask (paper eq. 2-5), ORB
// features with depth and dynamic flags (eq. 3), undistortion of the keypoints and their colours.
// With an asynchronous detector, detection runs on its own thread while ORB features are extracted
// (the dynamic flags are set once the mask is known), as stella_vslam overlaps its front end.
#include <map>
#include <memory>
#include <string>

#include "mrpt_yesslam/data/TFrame.h"
#include "mrpt_yesslam/detection/CAsyncDetector.h"
#include "mrpt_yesslam/dynamic/CDynamicObjectMasker.h"
#include "mrpt_yesslam/dynamic/CGeometricDynamicCheck.h"
#include "mrpt_yesslam/feature/COrbExtractor.h"

namespace mrpt_yesslam
{
/** The front end of a frame, before tracking. */
class CFrameBuilder
{
   public:
	/** `detector` may be null (no detection). `dynamicFilter` false: no mask, every feature static.
	 * `asyncDetection`: detect on a worker thread while ORB runs (same frames as without). */
	CFrameBuilder(std::unique_ptr<CObjectDetector> detector, const CDynamicObjectMasker::TOptions& masker,
				  const COrbExtractor::TOptions& orb, bool dynamicFilter, bool asyncDetection,
				  const CGeometricDynamicCheck::TOptions& check = CGeometricDynamicCheck::TOptions());

	/** A frame with id `id`: features (undistorted keypoints, depth, dynamic flags), colours at the
	 * raw keypoints, detections. `stageMs` (may be null) gets the time of detect, mask and orb. */
	std::shared_ptr<TFrame> build(const cv::Mat& bgr, const cv::Mat& depthMetres, double timestamp,
								  const mrpt::img::TCamera& camera, std::size_t id,
								  std::map<std::string, double>* stageMs = nullptr);

	/** Starts detecting frame `id` before build() gets it (recorded input, where it is already read),
	 * so that its detection overlaps the tracking of the frame before; the image must stay unchanged
	 * until then. Without an asynchronous detector, or for a frame already submitted, nothing. */
	void detectAhead(const cv::Mat& bgr, double timestamp, std::size_t id);
	/** Whether detectAhead() can do anything (an asynchronous detector). */
	bool detectsAhead() const { return async_ != nullptr; }

	/** Keep each frame's colour, depth and dynamic mask in TFrame::images (for dense mapping). */
	void setKeepImages(bool keep) { keepImages_ = keep; }

	/** The detector (null without one). */
	const CObjectDetector* detector() const;
	/** The detector lets go of its model once no more frames will be built (after pending detections). */
	void releaseDetectorModel();
	const COrbExtractor& extractor() const { return extractor_; }

   private:
	std::unique_ptr<CObjectDetector> detector_;  //!< synchronous use
	std::unique_ptr<CAsyncDetector> async_;      //!< or asynchronous use (owns the detector)
	CDynamicObjectMasker masker_;
	COrbExtractor extractor_;
	CGeometricDynamicCheck check_;
	bool dynamicFilter_;
	bool keepImages_ = false;
};
}  // namespace mrpt_yesslam
