#pragma once
// OpenCV's built-in HOG + linear SVM people detector (Dalal-Triggs): needs no model file, so it is
// the zero-download fallback for live cameras. Much weaker than YOLO (upright, whole people only).
#include <opencv2/objdetect.hpp>

#include "mrpt_yesslam/detection/CObjectDetector.h"

namespace mrpt_yesslam
{
/** The "hog" backend: class 0 = "person". */
class CHogPeopleDetector : public CObjectDetector
{
   public:
	explicit CHogPeopleDetector(const TOptions& opts);
	std::string description() const override { return "hog (OpenCV default people detector)"; }

   protected:
	/** SVM margins are mapped to [0,1] with a logistic curve, so the common confThreshold applies
	 * (0.6 keeps margins above 0.4). */
	std::vector<TDetection> detectImpl(const cv::Mat& bgr, double timestamp) override;

   private:
	cv::HOGDescriptor hog_;
};
}  // namespace mrpt_yesslam
