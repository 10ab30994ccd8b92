#pragma once
// Small value types shared by every stage.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace mrpt_yesslam
{
/** One detected object (paper eq. 1: class, confidence, box) in image pixels. */
struct TDetection
{
	int classId = -1;      //!< index into the detector's class names
	float score = 0;       //!< confidence in [0,1]
	cv::Rect2f box;        //!< x, y (top-left), width, height in pixels of the input image
	int instanceId = -1;   //!< from a detections file that has one (simulator ground truth); else -1
	bool dynamic = false;  //!< its class is in the configured set of dynamic classes
};

/** The pixels covering `box` grown by `margin` x its size on every side, at 1/`scale` of the
 * image side (rounded outwards), clipped to `image` (in those pixels). */
cv::Rect coveringRect(const cv::Rect2f& box, double margin, int scale, const cv::Rect& image);

/** Intersection over union of two boxes (0 when either is empty). */
double boxIoU(const cv::Rect2f& a, const cv::Rect2f& b);
}  // namespace mrpt_yesslam
